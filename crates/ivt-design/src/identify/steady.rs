//! The rig tests of §4.4 from a recording's holds: the average speed ratio
//! against the stepper angle (Fig. 47, Eq. 185), the motor speed against the
//! stepper angle with its slope K₂T_out and the gain K = 1/(K₂T_out) of the
//! proportional law (Fig. 50, Eq. 187–190), and the phase-averaged speed
//! over θ_in of a long hold (Fig. 48's 75-period averaging).

use super::regression::{fit_line, Line};
use super::windows::integrals;
use super::{IdentifyError, Recording, Stage};
use core::f64::consts::TAU;

/// rad/s → rpm.
const RPM_PER_RAD_S: f64 = 60.0 / TAU;

/// One hold of the stepper-angle sweep at steady state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoldPoint {
    /// Stepper angle θ_CT \[deg\].
    pub theta_ct_deg: f64,
    /// Eccentricity r \[m\].
    pub r: f64,
    /// θ-mean of V_m \[V\].
    pub v_m: f64,
    /// θ-mean of T_U \[N·m\].
    pub t_u: f64,
    /// Mean speed over whole revolutions, ω_m = 2πN/Δt \[rad/s\] (the motor
    /// and the driven gear turn once each per revolution of θ).
    pub omega_m: f64,
    /// Average speed ratio T_in/T_out, T_in the θ-mean of the identified
    /// motor torque (k_t/R_a) f V_m − (k_t k_e/R_a) f² ω (Eq. 186 with
    /// T_in = R_avg T_out); None at T_U = 0.
    pub r_avg: Option<f64>,
    /// Whole revolutions averaged.
    pub revolutions: usize,
}

/// The steady-state part of the identification: Fig. 47 and Fig. 50.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepAnalysis {
    /// The holds, in sweep order.
    pub holds: Vec<HoldPoint>,
    /// R_avg against θ_CT \[1/deg\] (Fig. 47; Eq. 185: 7/27492 for r_OG = 1.5″).
    pub r_avg_line: Line,
    /// ω_m \[rpm\] against θ_CT \[deg\] (Fig. 50, Eq. 187): slope −K₂T_out.
    pub omega_line: Line,
    /// K₂T_out \[rpm/deg\] = −slope of `omega_line` (thesis: 0.0128).
    pub k2_t_out: f64,
    /// K = 1/(K₂T_out) \[deg/rpm\] (thesis: 78, Eq. 190 with |1 − K₂T_out K| = 0).
    pub k: f64,
}

/// The steady state at the end of `stage` (its last half, whole
/// revolutions at one r): None if the stage holds less than one revolution.
fn hold_point(rec: &Recording, stage: &Stage, end_t: f64, motor: Motor) -> Option<HoldPoint> {
    let t = &rec.pulse_t;
    let from = stage.t + 0.5 * (end_t - stage.t);
    let last = t.partition_point(|&x| x <= end_t).checked_sub(1)?;
    let first_allowed = t.partition_point(|&x| x < from);
    let revs = last.checked_sub(first_allowed)? / rec.ppr;
    if revs == 0 {
        return None;
    }
    let first = last - revs * rec.ppr;
    let (t0, t1) = (*t.get(first)?, *t.get(last)?);
    let r = rec.eccentricity_at(t0)?;
    if rec.eccentricity_changes_in(t0, t1) {
        return None;
    }
    let i = integrals(rec, first, last, r, motor.lag_s)?;
    let span = TAU * revs as f64;
    let t_u = i.torque / span;
    let t_in = (motor.gain * i.volt - motor.damping * i.damp) / span;
    let mut v_sum = 0.0;
    for k in first..last {
        v_sum += rec.inputs_at(0.5 * (t.get(k)? + t.get(k + 1)?))?.0;
    }
    Some(HoldPoint {
        theta_ct_deg: stage.theta_ct_deg,
        r,
        v_m: v_sum / (last - first) as f64,
        t_u,
        omega_m: span / (t1 - t0),
        r_avg: (t_u != 0.0).then(|| t_in / t_u),
        revolutions: revs,
    })
}

/// The motor as identified: what the input torque T_in of a hold needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motor {
    /// k_t/R_a \[N·m/V\].
    pub gain: f64,
    /// k_t k_e/R_a \[N·m·s/rad\].
    pub damping: f64,
    /// Electrical time constant L_a/R_a \[s\] (Eq. 137; 0: Eq. 138).
    pub lag_s: f64,
}

/// Fig. 47 and Fig. 50 from the stages named `sweep`, with the identified
/// motor. None if the recording has no sweep.
///
/// # Errors
/// A sweep with fewer than 4 usable holds, or all at one angle.
pub fn sweep_analysis(
    rec: &Recording,
    motor: Motor,
) -> Result<Option<SweepAnalysis>, IdentifyError> {
    let holds: Vec<HoldPoint> = stages_named(rec, "sweep")
        .filter_map(|(s, end)| hold_point(rec, s, end, motor))
        .collect();
    if holds.is_empty() {
        return Ok(None);
    }
    let ratio: Vec<_> = holds
        .iter()
        .filter_map(|h| h.r_avg.map(|r| (h.theta_ct_deg, r)))
        .collect();
    let r_avg_line = fit_line(&ratio, "the average speed ratio against θ_CT (Fig. 47)")?;
    let speed: Vec<_> = holds
        .iter()
        .map(|h| (h.theta_ct_deg, h.omega_m * RPM_PER_RAD_S))
        .collect();
    let omega_line = fit_line(&speed, "the motor speed against θ_CT (Fig. 50)")?;
    let k2_t_out = -omega_line.slope;
    Ok(Some(SweepAnalysis {
        holds,
        r_avg_line,
        omega_line,
        k2_t_out,
        k: 1.0 / k2_t_out,
    }))
}

/// The stages named `name` with the time each ends (the next stage's start,
/// or the last pulse).
fn stages_named<'a>(
    rec: &'a Recording,
    name: &'a str,
) -> impl Iterator<Item = (&'a Stage, f64)> + 'a {
    let end_of_data = rec.pulse_t.last().copied().unwrap_or(f64::NAN);
    rec.stages.iter().enumerate().filter_map(move |(k, s)| {
        let end = rec.stages.get(k + 1).map_or(end_of_data, |n| n.t);
        (s.name == name).then_some((s, end))
    })
}

/// The speed over one revolution of θ_in, averaged over every whole
/// revolution of the first stage named `hold` (the thesis averages 75):
/// `(θ_in [deg], ω/ω̄)` per pulse interval. None without such a stage.
pub fn phase_average(rec: &Recording) -> Option<Vec<(f64, f64)>> {
    let (stage, end) = stages_named(rec, "hold").next()?;
    let t = &rec.pulse_t;
    let first = t.partition_point(|&x| x < stage.t);
    let last = t.partition_point(|&x| x <= end).checked_sub(1)?;
    let revs = last.checked_sub(first)? / rec.ppr;
    if revs == 0 {
        return None;
    }
    let dtheta = rec.dtheta();
    let mut bins = vec![(0.0, 0usize); rec.ppr];
    for k in first..first + revs * rec.ppr {
        let dt = t.get(k + 1)? - t.get(k)?;
        let theta = (rec.theta_of(k) + 0.5 * dtheta).rem_euclid(TAU);
        let bin = ((theta / dtheta) as usize).min(rec.ppr - 1);
        let slot = bins.get_mut(bin)?;
        slot.0 += dtheta / dt;
        slot.1 += 1;
    }
    let means: Vec<(f64, f64)> = bins
        .iter()
        .enumerate()
        .filter(|(_, b)| b.1 > 0)
        .map(|(k, b)| ((k as f64 + 0.5) * dtheta, b.0 / b.1 as f64))
        .collect();
    let mean = means.iter().map(|p| p.1).sum::<f64>() / means.len().max(1) as f64;
    Some(
        means
            .into_iter()
            .map(|(th, w)| (th.to_degrees(), w / mean))
            .collect(),
    )
}
