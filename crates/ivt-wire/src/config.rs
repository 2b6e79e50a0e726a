//! `ivt_ctrl::Config` on the wire (`Request::Configure`): every field in
//! declaration order, enums as `u8`, bools as 0/1, f32 as IEEE-754 bits.

use crate::fields::{Get, Put};
use crate::frame::WireError;
use ivt_ctrl::{ActuatorMap, Config, Gains, LawKind, OpenLoopCoeffs, StepperLimits};

fn law_code(law: LawKind) -> u8 {
    match law {
        LawKind::Delay => 0,
        LawKind::NoDelay => 1,
        LawKind::Prop => 2,
        LawKind::Open => 3,
    }
}

fn law_from(code: u8) -> Result<LawKind, WireError> {
    Ok(match code {
        0 => LawKind::Delay,
        1 => LawKind::NoDelay,
        2 => LawKind::Prop,
        3 => LawKind::Open,
        _ => return Err(WireError::BadValue),
    })
}

/// Payload length of `Configure` (see `put_config`): 27 four-byte scalars,
/// the u16 decimation, two u8 (law, feedforward) and the open-loop polynomial.
pub const CONFIG_LEN: usize =
    4 * 27 + 2 + 2 + 4 * ivt_ctrl::open_loop::POLY_V_TERMS * ivt_ctrl::open_loop::POLY_T_TERMS;

pub(crate) fn put_config(p: &mut Put<CONFIG_LEN>, c: &Config) {
    // Exhaustive destructuring: a field added to Config fails to compile here
    // until the wire format carries it.
    let Config {
        f_timer_hz,
        omega0,
        decimation,
        law,
        gains:
            Gains {
                k,
                k2,
                k_prop,
                prop_period_s,
            },
        open_loop:
            OpenLoopCoeffs {
                poly,
                boundary,
                r_max,
                v_m_range,
                t_u_range,
            },
        feedforward,
        actuator: ActuatorMap {
            steps_per_metre,
            offset_steps,
        },
        stepper: StepperLimits { max_speed, accel },
        stall_timeout_s,
        omega_max,
        safe_r,
        v_m_valid,
        t_u_valid,
        initial_inputs,
    } = *c;
    p.f32s(&[f_timer_hz, omega0]);
    p.bytes(&decimation.to_le_bytes());
    p.bytes(&[law_code(law)]);
    p.f32s(&[k, k2, k_prop, prop_period_s]);
    for row in &poly {
        p.f32s(row);
    }
    p.f32s(&boundary);
    p.f32(r_max);
    p.f32s(&v_m_range);
    p.f32s(&t_u_range);
    p.bytes(&[feedforward as u8]);
    p.f32(steps_per_metre);
    p.bytes(&offset_steps.to_le_bytes());
    p.f32s(&[max_speed, accel, stall_timeout_s, omega_max, safe_r]);
    p.f32s(&v_m_valid);
    p.f32s(&t_u_valid);
    p.f32s(&initial_inputs);
}

pub(crate) fn get_config(g: &mut Get<'_>) -> Result<Config, WireError> {
    let f_timer_hz = g.f32();
    let omega0 = g.f32();
    let decimation = u16::from_le_bytes(g.take());
    let law = law_from(g.u8())?;
    let gains = Gains {
        k: g.f32(),
        k2: g.f32(),
        k_prop: g.f32(),
        prop_period_s: g.f32(),
    };
    let poly = core::array::from_fn(|_| g.f32s());
    let open_loop = OpenLoopCoeffs {
        poly,
        boundary: g.f32s(),
        r_max: g.f32(),
        v_m_range: g.f32s(),
        t_u_range: g.f32s(),
    };
    let feedforward = match g.u8() {
        0 => false,
        1 => true,
        _ => return Err(WireError::BadValue),
    };
    let actuator = ActuatorMap {
        steps_per_metre: g.f32(),
        offset_steps: g.i32(),
    };
    Ok(Config {
        f_timer_hz,
        omega0,
        decimation,
        law,
        gains,
        open_loop,
        feedforward,
        actuator,
        stepper: StepperLimits {
            max_speed: g.f32(),
            accel: g.f32(),
        },
        stall_timeout_s: g.f32(),
        omega_max: g.f32(),
        safe_r: g.f32(),
        v_m_valid: g.f32s(),
        t_u_valid: g.f32s(),
        initial_inputs: g.f32s(),
    })
}
