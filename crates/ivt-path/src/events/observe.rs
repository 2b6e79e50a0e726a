//! A branch of a [`Family`] followed by pseudo-arclength continuation (Eq. 68–77)
//! and watched by an [`EventObserver`]: each accepted point gets its Floquet
//! multipliers (Hsu, Eq. 80) as it arrives, every [`Detector`] evaluates its
//! test function there, and an event whose test changed sign is located at
//! once by its extended system.

use super::branch_point::BranchPoint;
use super::detector::{
    BifurcationError, Detector, Event, LocateOptions, Observer, PathSoFar, Start, TracedPoint,
};
use super::fold::FamilyFold;
use super::multipliers::{Multipliers, PointMultipliers};
use super::neimark_sacker::NeimarkSacker;
use super::period_doubling::PeriodDoubling;
use crate::branch::Branch;
use crate::continuation::{ContinuationOptions, Path, PathPoint, Stepper, Traced};
use crate::family::{Family, FamilyBranch};
use crate::ihb::HbError;
use crate::stability::{AdaptiveHsu, HsuSteps};

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

/// The observer of a path on a branch `B`: the multipliers of each point
/// (optional: [`EventObserver::new`] and [`EventObserver::with_detectors`]
/// on a [`Family`] branch), then its detectors — on a [`Family`] branch by
/// default fold, period doubling, Neimark–Sacker and branch point; on any
/// [`Branch`] the [`Fold`](super::Fold) ([`EventObserver::without_multipliers`]).
pub struct EventObserver<B> {
    multipliers: Option<Box<dyn PointMultipliers<B>>>,
    detectors: Vec<Box<dyn Detector<B>>>,
    /// Each detector's test at the newest point.
    tests: Vec<f64>,
    /// Brackets waiting for the point after their start: (detector, start).
    pending: Vec<(usize, usize)>,
    /// Each detector's last bracketed start (one event per start and kind).
    last_start: Vec<Option<usize>>,
    path: PathSoFar,
    opts: LocateOptions,
}

impl<F: Family> EventObserver<FamilyBranch<F>> {
    /// The observer of a path of `branch` from `lambda0`: multipliers with
    /// `stability`, every event located with `opts`.
    ///
    /// # Errors
    /// As [`AdaptiveHsu::new`].
    pub fn new(
        branch: &FamilyBranch<F>,
        lambda0: f64,
        stability: HsuSteps,
        opts: &LocateOptions,
    ) -> Result<Self, HbError> {
        let detectors: Vec<Box<dyn Detector<FamilyBranch<F>>>> = vec![
            Box::new(FamilyFold),
            Box::new(PeriodDoubling),
            Box::new(NeimarkSacker),
            Box::new(BranchPoint::new(opts)),
        ];
        Self::with_detectors(branch, lambda0, stability, opts, detectors)
    }

    /// The observer of [`EventObserver::new`] running `detectors` only (e.g.
    /// the frequency response's [`Fold`](super::Fold)).
    ///
    /// # Errors
    /// As [`AdaptiveHsu::new`].
    pub fn with_detectors(
        branch: &FamilyBranch<F>,
        lambda0: f64,
        stability: HsuSteps,
        opts: &LocateOptions,
        detectors: Vec<Box<dyn Detector<FamilyBranch<F>>>>,
    ) -> Result<Self, HbError> {
        let multipliers = Multipliers::new(AdaptiveHsu::new(
            &branch.family().at(lambda0).0,
            branch.options().harmonics,
            stability,
        )?);
        let mut observer = Self::without_multipliers(opts, detectors);
        observer.multipliers = Some(Box::new(multipliers));
        Ok(observer)
    }
}

impl<B: Branch> EventObserver<B> {
    /// The observer of a path on any branch running `detectors` (e.g. the
    /// [`Fold`](super::Fold)) without multipliers, every event located with `opts`.
    pub fn without_multipliers(opts: &LocateOptions, detectors: Vec<Box<dyn Detector<B>>>) -> Self {
        let n = detectors.len();
        Self {
            multipliers: None,
            detectors,
            tests: vec![f64::NAN; n],
            pending: Vec::new(),
            last_start: vec![None; n],
            path: PathSoFar::default(),
            opts: opts.clone(),
        }
    }

    /// The points observed, with their multipliers (none without them).
    pub fn into_points(self) -> Vec<TracedPoint> {
        self.path.traced
    }

    /// Locates the brackets of `which` (detector, start) on the path so far.
    fn locate(&mut self, branch: &mut B, which: Vec<(usize, usize)>) -> Vec<Event> {
        let mut events = Vec::with_capacity(which.len());
        for (d, index) in which {
            let Some(det) = self.detectors.get_mut(d) else {
                continue;
            };
            let at = Start {
                branch: &mut *branch,
                path: &self.path,
                index,
                opts: &self.opts,
            };
            events.push(Event {
                kind: det.kind(),
                index,
                location: det.locate(at),
            });
        }
        events
    }
}

impl<B: Branch> Observer<B> for EventObserver<B> {
    fn on_point(&mut self, branch: &mut B, point: &PathPoint) -> Result<Vec<Event>, HbError> {
        if let Some(multipliers) = self.multipliers.as_mut() {
            self.path.traced.push(multipliers.at(branch, point)?);
        }
        self.path.points.push(point.clone());
        let Some(newest) = self.path.len().checked_sub(1).filter(|&k| k > 0) else {
            // The first point's tests may need the second (a secant).
            return Ok(Vec::new());
        };
        let path = &self.path;
        for (d, det) in self.detectors.iter_mut().enumerate() {
            if newest == 1 {
                if let Some(t) = self.tests.get_mut(d) {
                    *t = det.test(branch, path, 0);
                }
            }
            let value = det.test(branch, path, newest);
            let Some(before) = self.tests.get_mut(d).map(|t| std::mem::replace(t, value)) else {
                continue;
            };
            if before * value >= 0.0 || before.is_nan() || value.is_nan() {
                continue;
            }
            let start = det.start(path);
            let last = self.last_start.get_mut(d);
            if let (Some(start), Some(last)) = (start, last) {
                if *last != Some(start) {
                    *last = Some(start);
                    self.pending.push((d, start));
                }
            }
        }
        let len = path.len();
        let (ready, waiting): (Vec<_>, Vec<_>) = std::mem::take(&mut self.pending)
            .into_iter()
            .partition(|(_, start)| start + 1 < len);
        self.pending = waiting;
        Ok(self.locate(branch, ready))
    }

    /// The brackets whose start is the path's last point, located from it.
    fn finish(&mut self, branch: &mut B) -> Result<Vec<Event>, HbError> {
        let pending = std::mem::take(&mut self.pending);
        Ok(self.locate(branch, pending))
    }
}

/// An observed path: [`Stepper::run`] with each point, after `on_point`
/// (`false` stops the path), handed to `observer`, whose error ends the path;
/// when the stepper stops, the observer finishes its pending brackets
/// ([`Observer::finish`]). Returns the path and its events in path order (by
/// start point, then kind).
///
/// # Errors
/// The observer's error.
pub fn observe<B: Branch>(
    stepper: &mut Stepper<'_, B>,
    observer: &mut dyn Observer<B>,
    mut on_point: impl FnMut(&mut B, &PathPoint) -> bool,
) -> Result<(Path, Vec<Event>), HbError> {
    let (mut events, mut failure) = (Vec::new(), None);
    let path = stepper.run(|branch, p| {
        let go_on = on_point(branch, p);
        match observer.on_point(branch, p) {
            Ok(found) => {
                events.extend(found);
                go_on
            }
            Err(e) => {
                failure = Some(e);
                false
            }
        }
    });
    if let Some(e) = failure {
        return Err(e);
    }
    events.extend(observer.finish(stepper.branch())?);
    // An event is reported when the point after its start has arrived; a
    // fold's start may precede a bracket reported before it.
    events.sort_by_key(|e| (e.index, e.kind));
    Ok((path, events))
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
    let mut observer = EventObserver::new(branch, lambda0, opts.path.stability, &opts.locate)?;
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
    use crate::continuation::Termination;
    use crate::family::Frequency;
    use crate::frc::FrcOptions;
    use crate::ihb::HbOptions;
    use crate::Corrector;
    use crate::{BifurcationKind, Duffing, ModifiedIhb};

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
        let mut observer = EventObserver::new(&branch, 0.2, HsuSteps::default(), &opts).unwrap();
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
