//! Typed messages carried in frames. All integers and floats little-endian;
//! floats travel as their IEEE-754 bits, so a round trip is bit-exact.
//!
//! | kind | direction | name      | payload                                                         |
//! |------|-----------|-----------|-----------------------------------------------------------------|
//! | 0x01 | host → fw | `Hello`   | —                                                               |
//! | 0x02 | host → fw | `Pulse`   | `ticks: u32`                                                    |
//! | 0x03 | host → fw | `Inputs`  | `v_m: f32, t_u: f32`                                            |
//! | 0x04 | host → fw | `Exit`    | —                                                               |
//! | 0x05 | host → fw | `Configure` | `ivt_ctrl::Config` in declaration order, [`CONFIG_LEN`] bytes (see [`Request::Configure`]) |
//! | 0x81 | fw → host | `Hello`   | `version: u16, ppr: u32`                                        |
//! | 0x82 | fw → host | `Output`  | `omega, omega_a, omega_t, r_ol, r_d, r: f32, stepper_target: i32, flags: u8 (bit0 saturated, bit1 ready, bit2 inputs_clamped), fault: u8, ol_region: u8` |
//! | 0x83 | fw → host | `Ack`     | —                                                               |
//! | 0x8F | fw → host | `Error`   | `code: u8` (see [`ErrorCode`])                                  |
//! | 0x06 | host → fw | `Commission` | `selection: u8` + `ivt_ctrl::Plan` (see [`crate::commission`]), [`crate::commission::PLAN_LEN`] + 1 bytes |
//! | 0x84 | fw → host | `Sequenced` | as `Output` + `stage: u32, flags: u8` (bit0 stage started, bit1 pulse log, bit2 done) |
//!
//! Telemetry frames (0x90–0x93) are in [`crate::telemetry`].

use crate::commission::{get_plan, put_plan, PLAN_LEN};
pub use crate::config::CONFIG_LEN;
use crate::config::{get_config, put_config};
use crate::fields::{expect_len, Get, Put};
use crate::frame::{encode, WireError};
use ivt_ctrl::{Config, ControlOutput, Fault, OlRegion, Plan, Selection};

/// Protocol version reported by `Hello`; bump on any incompatible change.
pub const VERSION: u16 = 2;

const K_HELLO: u8 = 0x01;
const K_PULSE: u8 = 0x02;
const K_INPUTS: u8 = 0x03;
const K_EXIT: u8 = 0x04;
const K_CONFIGURE: u8 = 0x05;
const K_R_HELLO: u8 = 0x81;
const K_R_OUTPUT: u8 = 0x82;
const K_R_ACK: u8 = 0x83;
const K_R_ERROR: u8 = 0x8F;
const K_COMMISSION: u8 = 0x06;
const K_R_SEQUENCED: u8 = 0x84;

/// Host → firmware.
// `Configure` is ~200 bytes; boxing it is not an option without a heap, and a
// request lives only between decoding and handling.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Request {
    /// Asks for the protocol version and the controller's PPR.
    Hello,
    /// One encoder pulse with its timer timestamp.
    Pulse {
        /// Timer ticks of the pulse edge.
        ticks: u32,
    },
    /// Slow readings: motor voltage \[V\] and load torque \[N·m\].
    Inputs {
        /// Motor voltage V_m \[V\].
        v_m: f32,
        /// Load torque T_U [N·m].
        t_u: f32,
    },
    /// Ends the session (the QEMU image exits with status 0).
    Exit,
    /// Replaces the controller by `Controller::new(config)` (a fresh state).
    /// Every field travels, in declaration order; enums as `u8`, bools as 0/1.
    Configure(Config),
    /// Starts the commissioning sequences `selection` of `plan` on the next
    /// pulse (`ivt_ctrl::commission`); pulses are answered with
    /// [`Reply::Sequenced`] until the next `Configure`.
    Commission {
        /// The sequences to run.
        selection: Selection,
        /// Their parameters.
        plan: Plan,
    },
}

/// Why the firmware rejected a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum ErrorCode {
    /// The request frame failed its CRC.
    BadCrc = 1,
    /// Unknown request kind.
    UnknownKind = 2,
    /// Known kind, wrong payload length.
    BadLength = 3,
    /// A field that is not a valid enum value.
    BadValue = 4,
}

impl From<WireError> for ErrorCode {
    fn from(e: WireError) -> Self {
        match e {
            WireError::BadCrc => ErrorCode::BadCrc,
            WireError::UnknownKind(_) => ErrorCode::UnknownKind,
            WireError::BadValue => ErrorCode::BadValue,
            _ => ErrorCode::BadLength,
        }
    }
}

/// Firmware → host.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reply {
    /// Protocol version and the PPR the firmware was built with.
    Hello {
        /// [`VERSION`] of the firmware.
        version: u16,
        /// Pulses per revolution of θ (the controller's const generic).
        ppr: u32,
    },
    /// Answer to a pulse: the whole `ControlOutput`, bit-exact.
    Output(ControlOutput),
    /// `Inputs`, `Configure` or `Exit` accepted.
    Ack,
    /// A request was rejected (the raw error code, see [`ErrorCode`]).
    Error(u8),
    /// Answer to a pulse while a commissioning sequence runs.
    Sequenced {
        /// The controller's output.
        out: ControlOutput,
        /// Global index of the current stage.
        stage: u32,
        /// A stage started at this pulse.
        started: bool,
        /// Every edge is logged in this stage.
        pulse_log: bool,
        /// The last stage has ended.
        done: bool,
    },
}

const OUTPUT_LEN: usize = 6 * 4 + 4 + 3;

impl Request {
    /// Encodes the request as a frame into `out`; returns the frame length.
    ///
    /// # Errors
    /// [`WireError::BufferTooSmall`].
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, WireError> {
        let mut p = Put::<CONFIG_LEN>::new();
        let kind = match *self {
            Request::Hello => K_HELLO,
            Request::Pulse { ticks } => {
                p.u32(ticks);
                K_PULSE
            }
            Request::Inputs { v_m, t_u } => {
                p.f32(v_m);
                p.f32(t_u);
                K_INPUTS
            }
            Request::Exit => K_EXIT,
            Request::Configure(ref c) => {
                put_config(&mut p, c);
                K_CONFIGURE
            }
            Request::Commission {
                selection,
                ref plan,
            } => {
                p.bytes(&[selection.0]);
                put_plan(&mut p, plan);
                K_COMMISSION
            }
        };
        encode(kind, p.done(), out)
    }

    /// Decodes a request from a frame's kind and payload.
    ///
    /// # Errors
    /// [`WireError::UnknownKind`] or [`WireError::BadLength`].
    pub fn decode(kind: u8, payload: &[u8]) -> Result<Self, WireError> {
        Ok(match kind {
            K_HELLO => {
                expect_len(kind, payload, 0)?;
                Request::Hello
            }
            K_PULSE => Request::Pulse {
                ticks: expect_len(kind, payload, 4)?.u32(),
            },
            K_INPUTS => {
                let mut g = expect_len(kind, payload, 8)?;
                Request::Inputs {
                    v_m: g.f32(),
                    t_u: g.f32(),
                }
            }
            K_EXIT => {
                expect_len(kind, payload, 0)?;
                Request::Exit
            }
            K_CONFIGURE => {
                Request::Configure(get_config(&mut expect_len(kind, payload, CONFIG_LEN)?)?)
            }
            K_COMMISSION => {
                let mut g = expect_len(kind, payload, PLAN_LEN + 1)?;
                let selection = Selection(g.u8());
                if selection.0 & !Selection::ALL.0 != 0 {
                    return Err(WireError::BadValue);
                }
                Request::Commission {
                    selection,
                    plan: get_plan(&mut g),
                }
            }
            other => return Err(WireError::UnknownKind(other)),
        })
    }
}

/// `ControlOutput` on the wire: every field is written; [`get_output`]
/// builds the struct with all of them named, so a new field fails to compile.
fn put_output<const N: usize>(p: &mut Put<N>, o: &ControlOutput) {
    p.f32s(&[o.omega, o.omega_a, o.omega_t, o.r_ol, o.r_d, o.r]);
    p.bytes(&o.stepper_target.to_le_bytes());
    p.flags(&[o.saturated, o.ready, o.inputs_clamped]);
    p.bytes(&[o.fault.code(), o.ol_region.code()]);
}

fn get_output(g: &mut Get<'_>) -> Result<ControlOutput, WireError> {
    let [omega, omega_a, omega_t, r_ol, r_d, r] = g.f32s();
    let stepper_target = g.i32();
    let [saturated, ready, inputs_clamped] = g.flags();
    Ok(ControlOutput {
        omega,
        omega_a,
        omega_t,
        r_ol,
        r_d,
        r,
        stepper_target,
        saturated,
        ready,
        inputs_clamped,
        fault: Fault::from_code(g.u8()).ok_or(WireError::BadValue)?,
        ol_region: OlRegion::from_code(g.u8()).ok_or(WireError::BadValue)?,
    })
}

const SEQUENCED_LEN: usize = OUTPUT_LEN + 5;

impl Reply {
    /// Encodes the reply as a frame into `out`; returns the frame length.
    ///
    /// # Errors
    /// [`WireError::BufferTooSmall`].
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, WireError> {
        let mut p = Put::<SEQUENCED_LEN>::new();
        let kind = match *self {
            Reply::Hello { version, ppr } => {
                p.bytes(&version.to_le_bytes());
                p.u32(ppr);
                K_R_HELLO
            }
            Reply::Output(o) => {
                put_output(&mut p, &o);
                K_R_OUTPUT
            }
            Reply::Ack => K_R_ACK,
            Reply::Error(code) => {
                p.bytes(&[code]);
                K_R_ERROR
            }
            Reply::Sequenced {
                out,
                stage,
                started,
                pulse_log,
                done,
            } => {
                put_output(&mut p, &out);
                p.u32(stage);
                p.flags(&[started, pulse_log, done]);
                K_R_SEQUENCED
            }
        };
        encode(kind, p.done(), out)
    }

    /// Decodes a reply from a frame's kind and payload.
    ///
    /// # Errors
    /// [`WireError::UnknownKind`], [`WireError::BadLength`] or
    /// [`WireError::BadValue`].
    pub fn decode(kind: u8, payload: &[u8]) -> Result<Self, WireError> {
        Ok(match kind {
            K_R_HELLO => {
                let mut g = expect_len(kind, payload, 6)?;
                Reply::Hello {
                    version: g.u16(),
                    ppr: g.u32(),
                }
            }
            K_R_OUTPUT => Reply::Output(get_output(&mut expect_len(kind, payload, OUTPUT_LEN)?)?),
            K_R_ACK => {
                expect_len(kind, payload, 0)?;
                Reply::Ack
            }
            K_R_ERROR => Reply::Error(expect_len(kind, payload, 1)?.u8()),
            K_R_SEQUENCED => {
                let mut g = expect_len(kind, payload, SEQUENCED_LEN)?;
                let out = get_output(&mut g)?;
                let stage = g.u32();
                let flags: [bool; 3] = g.flags();
                Reply::Sequenced {
                    out,
                    stage,
                    started: flags[0],
                    pulse_log: flags[1],
                    done: flags[2],
                }
            }
            other => return Err(WireError::UnknownKind(other)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Decoder, MAX_FRAME};
    use ivt_ctrl::{ActuatorMap, Gains, LawKind, StepperLimits};

    fn one_frame(bytes: &[u8]) -> (u8, [u8; MAX_FRAME], usize) {
        let mut dec = Decoder::new();
        for &b in bytes {
            if let Some(r) = dec.push(b) {
                let f = r.unwrap();
                let mut p = [0u8; MAX_FRAME];
                p[..f.payload.len()].copy_from_slice(f.payload);
                return (f.kind, p, f.payload.len());
            }
        }
        panic!("no frame");
    }

    #[test]
    fn requests_round_trip() {
        let mut buf = [0u8; MAX_FRAME];
        for req in [
            Request::Hello,
            Request::Pulse { ticks: 0xFFFF_FFF0 },
            // A NaN with payload bits must survive unchanged (bits, not value).
            Request::Inputs {
                v_m: f32::from_bits(0x7FC0_1234),
                t_u: -0.0,
            },
            Request::Exit,
        ] {
            let n = req.encode(&mut buf).unwrap();
            let (k, p, len) = one_frame(&buf[..n]);
            let back = Request::decode(k, &p[..len]).unwrap();
            match (req, back) {
                (Request::Inputs { v_m, t_u }, Request::Inputs { v_m: v2, t_u: t2 }) => {
                    assert_eq!(v_m.to_bits(), v2.to_bits());
                    assert_eq!(t_u.to_bits(), t2.to_bits());
                }
                _ => assert_eq!(req, back),
            }
        }
    }

    #[test]
    fn replies_round_trip() {
        let mut buf = [0u8; MAX_FRAME];
        let out = ControlOutput {
            omega: 10.471_975,
            omega_a: 10.5,
            omega_t: f32::INFINITY,
            r_ol: 0.0067,
            r_d: -1e-6,
            r: 0.012,
            stepper_target: -123_456,
            saturated: true,
            fault: Fault::InputInvalid,
            ready: false,
            inputs_clamped: true,
            ol_region: OlRegion::UnderDrive,
        };
        for rep in [
            Reply::Hello {
                version: VERSION,
                ppr: 1200,
            },
            Reply::Output(out),
            Reply::Ack,
            Reply::Error(ErrorCode::BadLength as u8),
        ] {
            let n = rep.encode(&mut buf).unwrap();
            let (k, p, len) = one_frame(&buf[..n]);
            assert_eq!(Reply::decode(k, &p[..len]).unwrap(), rep);
        }
        assert_eq!(Reply::Output(out).encode(&mut buf).unwrap(), 31 + 5);
    }

    #[test]
    fn commission_and_sequenced_round_trip() {
        let mut buf = [0u8; MAX_FRAME];
        let mut plan = Plan::default();
        plan.step.points = 9;
        plan.drive.stages[5] = [1.5, 2.5, 3.5];
        plan.hold.theta_ct_deg = 1234.5;
        let req = Request::Commission {
            selection: Selection(0b0110),
            plan,
        };
        let n = req.encode(&mut buf).unwrap();
        assert_eq!(n, crate::commission::PLAN_LEN + 1 + 5);
        let (k, p, len) = one_frame(&buf[..n]);
        assert_eq!(Request::decode(k, &p[..len]).unwrap(), req);
        let mut bad = p;
        bad[0] = 0x10; // a sequence bit that does not exist
        assert_eq!(Request::decode(k, &bad[..len]), Err(WireError::BadValue));
        let rep = Reply::Sequenced {
            out: ControlOutput {
                r: 0.005,
                ..ControlOutput::IDLE
            },
            stage: 70_000,
            started: true,
            pulse_log: false,
            done: true,
        };
        let n = rep.encode(&mut buf).unwrap();
        assert_eq!(n, SEQUENCED_LEN + 5);
        let (k, p, len) = one_frame(&buf[..n]);
        assert_eq!(Reply::decode(k, &p[..len]).unwrap(), rep);
    }

    #[test]
    fn config_round_trip_is_exact() {
        // Every field distinct so a swapped pair shows up.
        let mut c = Config::default();
        let mut x = 1.0f32;
        let mut next = || {
            x += 0.125;
            x
        };
        c.f_timer_hz = next();
        c.omega0 = next();
        c.decimation = 7;
        c.law = LawKind::Prop;
        c.gains = Gains {
            k: next(),
            k2: next(),
            k_prop: next(),
            prop_period_s: next(),
        };
        for row in c.open_loop.poly.iter_mut() {
            for v in row.iter_mut() {
                *v = next();
            }
        }
        c.open_loop.boundary = [next(), next(), next()];
        c.open_loop.r_max = next();
        c.open_loop.v_m_range = [next(), next()];
        c.open_loop.t_u_range = [next(), next()];
        c.feedforward = false;
        c.actuator = ActuatorMap {
            steps_per_metre: next(),
            offset_steps: -9,
        };
        c.stepper = StepperLimits {
            max_speed: next(),
            accel: next(),
        };
        c.stall_timeout_s = next();
        c.omega_max = next();
        c.safe_r = next();
        c.v_m_valid = [next(), next()];
        c.t_u_valid = [next(), next()];
        c.initial_inputs = [next(), next()];
        let mut buf = [0u8; MAX_FRAME];
        let n = Request::Configure(c).encode(&mut buf).unwrap();
        assert_eq!(n, CONFIG_LEN + 5);
        let (k, p, len) = one_frame(&buf[..n]);
        assert_eq!(
            Request::decode(k, &p[..len]).unwrap(),
            Request::Configure(c)
        );
    }

    #[test]
    fn wrong_lengths_and_kinds_are_errors() {
        assert_eq!(
            Request::decode(K_PULSE, &[1, 2, 3]),
            Err(WireError::BadLength {
                kind: K_PULSE,
                len: 3
            })
        );
        assert_eq!(
            Request::decode(0x55, &[]),
            Err(WireError::UnknownKind(0x55))
        );
        assert!(Reply::decode(K_R_OUTPUT, &[0; 30]).is_err());
        // A fault code the controller does not define.
        let mut bad = [0u8; OUTPUT_LEN];
        bad[OUTPUT_LEN - 2] = 99;
        assert_eq!(Reply::decode(K_R_OUTPUT, &bad), Err(WireError::BadValue));
    }
}
