//! Frequency-response curve (FRC) in ω_f by pseudo-arclength continuation
//! (Eq. 68–77) with Floquet multipliers (Hsu, Eq. 78) at every point. Without
//! events [`ivt_hb::frequency_response`] traces it and locates the folds on
//! their extended system; with events the start is solved by the modified
//! IHB and [`ivt_hb::trace`] locates every fold, period doubling,
//! Neimark–Sacker point and branch point as the path passes it.

use super::{check_finite, pairs, Array};
use ivt_hb::branches::events::{trace, BifurcationError, BifurcationKind, Event, TraceOptions};
use ivt_hb::branches::family::{Family, FamilyBranch, Frequency};
use ivt_hb::branches::frc::{
    frequency_response, AmplitudeProbe, Frc, FrcFold, FrcOptions, FrcPoint,
};
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::{AtFrequency, PeriodicProblem};
use ivt_hb::stability::HsuSteps;
use ivt_hb::stability::StabilityKind;
use ivt_hb::HbError;
use ivt_hb::ModifiedIhb;
use ivt_path::continuation::Termination;
use serde::Serialize;
use std::time::Instant;

/// The sweep (its interval: `from`, `to` finite, > 0 and distinct) and
/// whether to locate every event.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrcRequest {
    /// The sweep; by default Fig. 29's interval 0.2 → 3.0 and
    /// [`FrcOptions`]' path.
    pub options: FrcOptions,
    /// Locate period doublings, Neimark–Sacker and branch points too
    /// (otherwise folds only; the default).
    pub events: bool,
}

impl FrcRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] unless `from`, `to` are finite, > 0 and
    /// distinct.
    pub fn validate(&self) -> Result<(), HbError> {
        let (from, to) = (
            super::finite("from", self.options.from)?,
            super::finite("to", self.options.to)?,
        );
        if !(from > 0.0 && to > 0.0 && from != to) {
            return Err(HbError::InvalidInput(format!(
                "`from` = {from:?}, `to` = {to:?} must be > 0 and distinct"
            )));
        }
        Ok(())
    }
}

/// One point of the curve.
#[derive(Debug, Clone, Serialize)]
pub struct CurvePoint {
    /// ω_f.
    pub omega: f64,
    /// max |x_0| over the AFT samples (DOF 0).
    pub amplitude: f64,
    /// All multipliers inside the unit circle.
    pub stable: bool,
    /// The leading multiplier's class.
    pub stability: StabilityKind,
    /// Same as `stability` (the key of the first releases).
    pub kind: StabilityKind,
    /// Coefficients of the orbit.
    pub coeffs: Array<f64>,
    /// Floquet multipliers `[[re, im], ...]`.
    pub multipliers: Vec<[f64; 2]>,
    /// Richardson estimate of the multipliers' error (None when not estimated).
    pub multiplier_error: Option<f64>,
}

/// A fold located on the path.
#[derive(Debug, Clone, Serialize)]
pub struct FoldPoint {
    /// ω_f at the turn.
    pub omega: f64,
    /// Amplitude there.
    pub amplitude: f64,
    /// Orbit there.
    pub coeffs: Array<f64>,
    /// Converged on the extended system (else the parabola's estimate).
    pub located: bool,
    /// Path point before the turn.
    pub index: usize,
}

/// An event in path order. A failed location keeps the values of the path
/// point before it and the reason.
#[derive(Debug, Clone, Serialize)]
pub struct EventRecord {
    /// What it is.
    pub kind: BifurcationKind,
    /// Path point before it.
    pub index: usize,
    /// ω_f (located, else that of the point before).
    pub omega: Option<f64>,
    /// max |x_0| of its orbit over the AFT samples, the measure of the
    /// points' `amplitude` (located, else that of the point before).
    pub amplitude: Option<f64>,
    /// Converged on its extended system.
    pub located: bool,
    /// Multipliers there `[[re, im], ...]`.
    pub multipliers: Option<Vec<[f64; 2]>>,
    /// Orbit there.
    pub coeffs: Option<Array<f64>>,
    /// Why the location failed (None when located).
    pub error: Option<String>,
}

/// A traced curve: the keys of `ivt hb duffing-frc --json` and the dicts of
/// `ivt.hb.duffing_frc` (`F = f64`: folds as ω_f) and `ivt.hb.frc`
/// (`F = FoldPoint`).
#[derive(Debug, Clone, Serialize)]
pub struct FrcCurve<F> {
    /// Points in path order.
    pub points: Vec<CurvePoint>,
    /// Folds in path order.
    pub folds: Vec<F>,
    /// Events in path order (without events: the folds).
    pub bifurcations: Vec<EventRecord>,
    /// Why the path stopped.
    pub termination: Termination,
    /// ω_f of every point (a column for plotting).
    pub omega: Array<f64>,
    /// Amplitude of every point.
    pub amplitude: Array<f64>,
    /// Verdict of every point.
    pub stable: Array<bool>,
    /// Wall time of the whole job.
    pub time_s: f64,
}

impl FrcCurve<FoldPoint> {
    /// The same curve with each fold given by its ω_f alone (the shape of the
    /// Duffing FRC, Fig. 29).
    pub fn with_fold_omegas(self) -> FrcCurve<f64> {
        FrcCurve {
            folds: self.folds.iter().map(|f| f.omega).collect(),
            points: self.points,
            bifurcations: self.bifurcations,
            termination: self.termination,
            omega: self.omega,
            amplitude: self.amplitude,
            stable: self.stable,
            time_s: self.time_s,
        }
    }
}

/// Trace the FRC of `problem` from `req.from` to `req.to`.
///
/// # Errors
/// [`FrcRequest::validate`]'s, the start's and the path's.
pub fn frc(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    req: &FrcRequest,
) -> Result<FrcCurve<FoldPoint>, HbError> {
    let problem = &problem;
    req.validate()?;
    let t0 = Instant::now();
    let opts = &req.options;
    if req.events {
        let at_start = AtFrequency::new(problem, opts.from);
        let start = ModifiedIhb::new(&at_start, hb.clone())?.solve(opts.from, None)?;
        let mut branch = FamilyBranch::new(Frequency(problem), hb, opts.from)?;
        return traced_curve(&mut branch, &start.coeffs, opts, t0);
    }
    let curve = frequency_response(problem, hb, opts)?;
    let events = curve.events.iter().map(|f| fold_event(f, &curve)).collect();
    assemble(curve, events, opts.path.stability, t0)
}

/// The curve of `branch` (a frequency family, planned with the options the
/// points' coefficients have) traced with events by [`ivt_hb::trace`] from
/// the orbit `start` at ω_f = `sweep.from` to `sweep.to` on `sweep.path`, as
/// [`frc`] returns it (also the new branch of [`super::switch()`]); `t0`
/// starts the job's wall time.
///
/// # Errors
/// The trace's ([`trace_error`]) and [`assemble`]'s.
pub(super) fn traced_curve<F: Family>(
    branch: &mut FamilyBranch<F>,
    start: &[f64],
    sweep: &FrcOptions,
    t0: Instant,
) -> Result<FrcCurve<FoldPoint>, HbError> {
    let opts = TraceOptions {
        lambda_to: sweep.to,
        path: sweep.path.clone(),
        ..TraceOptions::default()
    };
    let traced = trace(branch, start, sweep.from, &opts).map_err(trace_error)?;
    let curve = ivt_hb::branches::frc::from_trace(&traced, branch.options())?;
    let mut probe = AmplitudeProbe::new(branch.options())?;
    let events = traced
        .events
        .iter()
        .map(|e| event(e, &curve, &mut probe))
        .collect();
    assemble(curve, events, sweep.path.stability, t0)
}

/// A bifurcation error as the jobs report it: the [`HbError`] it carries, or
/// its message as an input error.
pub(super) fn trace_error(e: BifurcationError) -> HbError {
    match e {
        BifurcationError::Hb(h) => h,
        other => HbError::InvalidInput(other.to_string()),
    }
}

/// The job's result from a traced `curve` and its `events`: every point's
/// multipliers checked finite (a point whose stability is unknown makes the
/// curve an error, naming the cap of the Hsu sub-intervals `stability`, not
/// a point reported unstable).
fn assemble(
    curve: Frc,
    events: Vec<EventRecord>,
    stability: HsuSteps,
    t0: Instant,
) -> Result<FrcCurve<FoldPoint>, HbError> {
    let hsu_cap = match stability {
        HsuSteps::Tolerance { max, .. } => max,
        HsuSteps::Fixed(steps) => steps,
    };
    for p in &curve.points {
        check_finite(&p.multipliers, p.omega_f, hsu_cap)?;
    }
    Ok(FrcCurve {
        points: curve.points.iter().map(point).collect(),
        folds: curve.events.iter().map(fold).collect(),
        bifurcations: events,
        omega: curve.points.iter().map(|p| p.omega_f).collect(),
        amplitude: curve.points.iter().map(|p| p.amplitude).collect(),
        stable: curve.points.iter().map(FrcPoint::stable).collect(),
        termination: curve.termination,
        time_s: t0.elapsed().as_secs_f64(),
    })
}

pub(super) fn point(p: &FrcPoint) -> CurvePoint {
    CurvePoint {
        omega: p.omega_f,
        amplitude: p.amplitude,
        stable: p.stable(),
        stability: p.kind,
        kind: p.kind,
        coeffs: Array(p.coeffs.clone()),
        multipliers: pairs(&p.multipliers),
        multiplier_error: p.multiplier_error,
    }
}

fn fold(f: &FrcFold) -> FoldPoint {
    FoldPoint {
        omega: f.omega_f,
        amplitude: f.amplitude,
        coeffs: Array(f.coeffs.clone()),
        located: f.located,
        index: f.index,
    }
}

/// An event of the trace (its amplitude by `probe`); a failed location
/// takes the point before it.
pub(super) fn event(e: &Event, curve: &Frc, probe: &mut AmplitudeProbe) -> EventRecord {
    let near = curve.points.get(e.index);
    match &e.location {
        Ok(b) => EventRecord {
            kind: e.kind,
            index: e.index,
            omega: Some(b.lambda),
            amplitude: Some(probe.of(&b.q)),
            located: true,
            multipliers: Some(pairs(&b.multipliers)),
            coeffs: Some(Array(b.q.clone())),
            error: None,
        },
        Err(why) => EventRecord {
            kind: e.kind,
            index: e.index,
            omega: near.map(|p| p.omega_f),
            amplitude: near.map(|p| p.amplitude),
            located: false,
            multipliers: near.map(|p| pairs(&p.multipliers)),
            coeffs: near.map(|p| Array(p.coeffs.clone())),
            error: Some(why.to_string()),
        },
    }
}

/// A fold of the folds-only path as an event (multipliers: those of the path
/// point nearest the turn).
fn fold_event(f: &FrcFold, curve: &Frc) -> EventRecord {
    EventRecord {
        kind: BifurcationKind::Fold,
        index: f.index,
        omega: Some(f.omega_f),
        amplitude: Some(f.amplitude),
        located: f.located,
        multipliers: curve.points.get(f.index).map(|p| pairs(&p.multipliers)),
        coeffs: Some(Array(f.coeffs.clone())),
        error: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ivt_hb::Duffing;

    #[test]
    fn duffing_folds_with_and_without_events_are_the_shooting_folds() {
        // Fig. 29: two folds, located on their extended systems; the shooting
        // values 1.6548121 and 1.1687244 (tests/frc.rs checks them against an
        // independent shooting to 1e-8).
        let d = Duffing::new(0.02, 1.0, 1.0, 0.1);
        let hb = HbOptions::new(20, 64).with_tol(1e-10);
        for events in [false, true] {
            let req = FrcRequest {
                events,
                ..FrcRequest::default()
            };
            let c = frc(&d, &hb, &req).unwrap().with_fold_omegas();
            assert_eq!(c.folds.len(), 2, "events = {events}: {:?}", c.folds);
            for (f, want) in c.folds.iter().zip([1.6548121, 1.1687244]) {
                assert!((f - want).abs() < 1e-7, "events = {events}: {f} vs {want}");
            }
            let kinds: Vec<_> = c.bifurcations.iter().map(|b| b.kind).collect();
            assert_eq!(kinds, [BifurcationKind::Fold; 2], "events = {events}");
            assert_eq!(c.termination, Termination::LeftInterval);
            assert_eq!(c.omega.0.len(), c.points.len());
        }
    }

    #[test]
    fn bad_interval_is_an_input_error() {
        let req = FrcRequest {
            options: FrcOptions {
                from: 1.0,
                to: 1.0,
                ..FrcOptions::default()
            },
            ..FrcRequest::default()
        };
        assert_eq!(req.validate().unwrap_err().kind(), "input");
    }
}
