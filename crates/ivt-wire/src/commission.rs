//! The commissioning plan on the wire (`Request::Commission`): every field of
//! `ivt_ctrl::Plan` in declaration order, f32 as IEEE-754 bits, so the
//! firmware runs exactly the plan the host chose.

use crate::fields::{Get, Put};
use ivt_ctrl::commission::{DrivePlan, HoldPlan, StepPlan, SweepPlan, DRIVE_STAGES};
use ivt_ctrl::Plan;

/// Payload bytes of a [`Plan`]: 34 f32 (sweep 5, hold 4, step 7, drive 18)
/// and the step test's `points: u8`.
pub const PLAN_LEN: usize = 4 * (5 + 4 + 7 + 3 * DRIVE_STAGES) + 1;

pub(crate) fn put_plan<const N: usize>(p: &mut Put<N>, plan: &Plan) {
    // Exhaustive destructuring: a field added to a plan fails to compile
    // here until the wire carries it.
    let Plan {
        sweep:
            SweepPlan {
                to_deg,
                step_deg,
                hold_s,
                inputs: sweep_inputs,
            },
        hold:
            HoldPlan {
                theta_ct_deg,
                hold_s: hold_hold_s,
                inputs: hold_inputs,
            },
        step:
            StepPlan {
                range_deg,
                points,
                hold_s: step_hold_s,
                law_s,
                inputs: step_inputs,
                t_u_step,
            },
        drive: DrivePlan { stages },
    } = *plan;
    p.f32s(&[to_deg, step_deg, hold_s]);
    p.f32s(&sweep_inputs);
    p.f32s(&[theta_ct_deg, hold_hold_s]);
    p.f32s(&hold_inputs);
    p.f32s(&range_deg);
    p.bytes(&[points]);
    p.f32s(&[step_hold_s, law_s]);
    p.f32s(&step_inputs);
    p.f32(t_u_step);
    for s in &stages {
        p.f32s(s);
    }
}

pub(crate) fn get_plan(g: &mut Get<'_>) -> Plan {
    Plan {
        sweep: SweepPlan {
            to_deg: g.f32(),
            step_deg: g.f32(),
            hold_s: g.f32(),
            inputs: g.f32s(),
        },
        hold: HoldPlan {
            theta_ct_deg: g.f32(),
            hold_s: g.f32(),
            inputs: g.f32s(),
        },
        step: StepPlan {
            range_deg: g.f32s(),
            points: g.u8(),
            hold_s: g.f32(),
            law_s: g.f32(),
            inputs: g.f32s(),
            t_u_step: g.f32(),
        },
        drive: DrivePlan {
            stages: core::array::from_fn(|_| g.f32s()),
        },
    }
}
