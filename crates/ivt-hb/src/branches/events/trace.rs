//! A branch of a [`Family`] followed by pseudo-arclength continuation (Eq. 68–77)
//! and watched by the path engine's [`EventObserver`]: each accepted point
//! gets its Floquet multipliers (Hsu, Eq. 80, [`Multipliers`]) as it arrives,
//! every [`Detector`] evaluates its test function there, and an event whose
//! test changed sign is located at once by its extended system.

use super::branch_point::BranchPoint;
use super::fold::FamilyFold;
use super::multipliers::Multipliers;
use super::neimark_sacker::NeimarkSacker;
use super::period_doubling::PeriodDoubling;
use super::{BifurcationError, Event};
use crate::branches::family::{Family, FamilyBranch};
use crate::orbit::ihb::HbError;
use crate::stability::{AdaptiveHsu, HsuSteps};
use ivt_path::continuation::{ContinuationOptions, Traced};
use ivt_path::events::{observe, Detector, EventObserver, LocateOptions, TracedPoint};
use ivt_path::Branch;

/// The options of a path whose points get their Floquet multipliers, shared
/// by the sweep that locates folds only ([`crate::FrcOptions`]) and the one
/// that locates every event ([`TraceOptions`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PathOptions {
    /// Path following (its λ bounds are set from the interval; its
    /// corrector [`crate::Corrector::Broyden`] by default).
    pub continuation: ContinuationOptions,
    /// Hsu sub-intervals of the path points' multipliers (by default chosen
    /// per point for multipliers to 1e-6, [`HsuSteps::Tolerance`]).
    pub stability: HsuSteps,
}

/// Options of [`trace`].
#[derive(Debug, Clone, PartialEq)]
pub struct TraceOptions {
    /// End of the parameter interval (the path stops once it leaves
    /// `[min(λ₀, lambda_to), max(λ₀, lambda_to)]`).
    pub lambda_to: f64,
    /// The path and its multipliers (λ bounds set from λ₀ and `lambda_to`).
    pub path: PathOptions,
    /// Options of the located events.
    pub locate: LocateOptions,
}

impl Default for TraceOptions {
    fn default() -> Self {
        Self {
            lambda_to: 1.0,
            path: PathOptions::default(),
            locate: LocateOptions::default(),
        }
    }
}

/// A traced branch: its points with their multipliers and every detected
/// event, each with its location or why locating it failed, in path order
/// (by start point, then kind).
pub type Trace = Traced<TracedPoint, Event>;

/// The observer of a path of `branch` from `lambda0`: multipliers with
/// `stability` (Hsu steps chosen per point, [`AdaptiveHsu`]), then
/// `detectors` (by default — [`trace`] — fold, period doubling,
/// Neimark–Sacker and branch point; the frequency response runs the fold
/// alone), every event located with `opts`.
///
/// # Errors
/// As [`AdaptiveHsu::new`].
pub fn observer<F: Family, E: From<HbError> + 'static>(
    branch: &FamilyBranch<F>,
    lambda0: f64,
    stability: HsuSteps,
    opts: &LocateOptions,
    detectors: Vec<Box<dyn Detector<FamilyBranch<F>, E>>>,
) -> Result<EventObserver<FamilyBranch<F>, E>, HbError> {
    let multipliers = Multipliers::new(AdaptiveHsu::new(
        &branch.family().at(lambda0).0,
        branch.options().harmonics,
        stability,
    )?);
    Ok(EventObserver::new(opts, detectors).with_multipliers(Box::new(multipliers)))
}

/// The four events of a [`Family`] branch: fold (with its multipliers),
/// period doubling, Neimark–Sacker and branch point.
pub fn every_event<F: Family>(
    opts: &LocateOptions,
) -> Vec<Box<dyn Detector<FamilyBranch<F>, BifurcationError>>> {
    vec![
        Box::new(FamilyFold),
        Box::new(PeriodDoubling),
        Box::new(NeimarkSacker),
        Box::new(BranchPoint::new(opts)),
    ]
}

/// Follows `branch` from the orbit `q0` at `lambda0` (corrected first) towards
/// `opts.lambda_to`, with multipliers at every point, and locates its events
/// as the points arrive ([`EventObserver`]).
///
/// # Errors
/// [`BifurcationError::Hb`] if the start cannot be used or a point's
/// multipliers fail; events that cannot be located carry their error in
/// [`Event::location`].
pub fn trace<F: Family>(
    branch: &mut FamilyBranch<F>,
    q0: &[f64],
    lambda0: f64,
    opts: &TraceOptions,
) -> Result<Trace, BifurcationError> {
    let m = branch.len();
    if q0.len() != m || !opts.lambda_to.is_finite() || opts.lambda_to == lambda0 {
        return Err(HbError::InvalidInput(format!(
            "start must have {m} entries and lambda_to be finite and differ from λ₀"
        ))
        .into());
    }
    let mut x0 = q0.to_vec();
    x0.push(lambda0);
    let mut copts = opts.path.continuation.clone();
    copts.lambda_min = lambda0.min(opts.lambda_to);
    copts.lambda_max = lambda0.max(opts.lambda_to);
    let mut observer = observer(
        branch,
        lambda0,
        opts.path.stability,
        &opts.locate,
        every_event(&opts.locate),
    )?;
    // The one continuation driver: the observer sees each point as it is
    // reached, and its error ends the path.
    let mut stepper = branch.stepper(&x0, 0, opts.lambda_to - lambda0, &copts)?;
    let (path, events) = observe(&mut stepper, &mut observer, |_, _| true)?;
    Ok(Trace {
        points: observer.into_points(),
        events,
        termination: path.termination,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::branches::family::Frequency;
    use crate::branches::frc::FrcOptions;
    use crate::orbit::ihb::HbOptions;
    use crate::Corrector;
    use crate::{BifurcationKind, Duffing, ModifiedIhb};
    use ivt_path::continuation::Termination;
    use ivt_path::events::Observer;

    #[test]
    fn folds_are_located_as_the_points_arrive_not_after_the_path() {
        // Fig. 29 (Duffing, ξ = 0.02, F = 0.1) followed by the exact
        // corrector, which hands each point over as it is reached: each fold
        // is returned by the observer at most two points after its start
        // (the point nearest the turn), long before the path ends, at the
        // shooting values 1.6548121 and 1.1687244 (tests/frc.rs).
        let hb = HbOptions::new(20, 64).with_tol(1e-10);
        let d = Duffing::new(0.02, 1.0, 1.0, 0.1);
        let start = ModifiedIhb::new(&d, hb.clone())
            .unwrap()
            .solve(0.2, None)
            .unwrap();
        let mut branch = FamilyBranch::new(Frequency(&d), &hb, 0.2).unwrap();
        let opts = LocateOptions::default();
        let mut observer =
            observer(&branch, 0.2, HsuSteps::default(), &opts, every_event(&opts)).unwrap();
        let mut copts = FrcOptions::default().path.continuation;
        (copts.lambda_min, copts.lambda_max) = (0.2, 3.0);
        copts.corrector = Corrector::Newton;
        let mut x0 = start.coeffs.clone();
        x0.push(0.2);
        let mut arrived = Vec::new();
        let mut count = 0;
        let path = branch.stepper(&x0, 0, 1.0, &copts).unwrap().run(|b, p| {
            let found = observer.on_point(b, p).unwrap();
            arrived.extend(found.into_iter().map(|e| (count, e)));
            count += 1;
            true
        });
        assert_eq!(path.termination, Termination::LeftInterval);
        let n = path.points.len();
        assert_eq!(arrived.len(), 2, "{arrived:?}");
        for ((at, e), want) in arrived.iter().zip([1.6548121, 1.1687244]) {
            assert_eq!(e.kind, BifurcationKind::Fold);
            assert!(e.index < *at && *at <= e.index + 2, "{at} {e:?}");
            assert!(*at + 10 < n, "{at} of {n}");
            let lambda = e.location.as_ref().unwrap().lambda;
            assert!((lambda - want).abs() < 1e-7, "{lambda} vs {want}");
        }
    }

    #[test]
    fn a_turn_at_the_paths_last_point_is_located_from_it() {
        // Fig. 29 (Duffing, ξ = 0.02, F = 0.1) cut (`max_points`) at the
        // first point past a turn, for step caps until that point is the
        // one nearest the turn: the fold's start is then the path's last
        // point, with no point after it. The observer's `finish` locates it
        // from there, at the shooting values 1.6548121 and 1.1687244
        // (tests/frc.rs); on babcee2 it stayed unlocated (`located = false`).
        let hb = HbOptions::new(20, 64).with_tol(1e-10);
        let d = Duffing::new(0.02, 1.0, 1.0, 0.1);
        let mut reached = 0;
        for k in 0..10 {
            let mut opts = FrcOptions::default();
            opts.path.continuation.corrector = Corrector::Newton;
            opts.path.continuation.ds_max = 0.12 - 0.008 * f64::from(k);
            let full = crate::frequency_response(&d, &hb, &opts).unwrap();
            let omega: Vec<f64> = full.points.iter().map(|p| p.omega_f).collect();
            let rising = |j: usize| omega[j] > omega[j - 1];
            let turns = (2..omega.len()).filter(|&j| rising(j) != rising(j - 1));
            for (j, want) in turns.zip([1.6548121, 1.1687244]) {
                // The tangents turn at the highest point `j − 1` or after it.
                for last in [j - 1, j] {
                    opts.path.continuation.max_points = last + 1;
                    let cut = crate::frequency_response(&d, &hb, &opts).unwrap();
                    assert_eq!(cut.points.len(), last + 1);
                    let Some(fold) = cut.events.last().filter(|f| f.index == last) else {
                        continue;
                    };
                    reached += 1;
                    assert_eq!(cut.termination, Termination::MaxPoints);
                    assert!(fold.located, "{fold:?}");
                    assert!((fold.omega_f - want).abs() < 1e-7, "{fold:?}");
                }
            }
        }
        assert!(reached > 0, "no step cap put a turn at the last point");
    }
}
