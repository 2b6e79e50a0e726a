//! The driver of an observed path ([`observe`]: the one [`Stepper`] with each
//! point handed to an [`Observer`] as it arrives) and the observer that runs
//! [`Detector`]s on it ([`EventObserver`]): each accepted point optionally
//! gets its Floquet multipliers ([`PointMultipliers`]), every detector
//! evaluates its test function there, and an event whose test changed sign
//! is located at once by its extended system.

use super::detector::{Detector, Event, LocateOptions, Observer, PathSoFar, Start, TracedPoint};
use crate::branch::{Branch, ResidualBranch};
use crate::continuation::{BroydenCorrector, ContinuationOptions, Path, PathPoint, Stepper};
use crate::error::PathError;

/// What gives each arriving point of a branch `B` its Floquet multipliers:
/// the optional part of an [`EventObserver`] (a branch without them — the
/// STHB string, a condensed structure — runs its detectors without one);
/// `E` its error, which ends the observation.
pub trait PointMultipliers<B, E> {
    /// The arrived `point` with its multipliers.
    ///
    /// # Errors
    /// The monodromy's failure; an error for an empty point.
    fn at(&mut self, branch: &B, point: &PathPoint) -> Result<TracedPoint, E>;
}

/// The observer of a path on a branch `B` whose events carry the location
/// error `E`: the multipliers of each point (optional,
/// [`EventObserver::with_multipliers`]), then its detectors (e.g. the
/// [`Fold`](super::Fold) of any branch; ivt-hb's fold, period doubling,
/// Neimark–Sacker and branch point on its `FamilyBranch`).
pub struct EventObserver<B, E> {
    multipliers: Option<Box<dyn PointMultipliers<B, E>>>,
    detectors: Vec<Box<dyn Detector<B, E>>>,
    /// Each detector's test at the newest point.
    tests: Vec<f64>,
    /// Brackets waiting for the point after their start: (detector, start).
    pending: Vec<(usize, usize)>,
    /// Each detector's last bracketed start (one event per start and kind).
    last_start: Vec<Option<usize>>,
    path: PathSoFar,
    opts: LocateOptions,
}

impl<B: Branch, E> EventObserver<B, E> {
    /// The observer of a path on any branch running `detectors` (e.g. the
    /// [`Fold`](super::Fold)) without multipliers, every event located with `opts`.
    pub fn new(opts: &LocateOptions, detectors: Vec<Box<dyn Detector<B, E>>>) -> Self {
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

    /// The same observer giving each point its multipliers by `multipliers`
    /// before the detectors see it.
    pub fn with_multipliers(mut self, multipliers: Box<dyn PointMultipliers<B, E>>) -> Self {
        self.multipliers = Some(multipliers);
        self
    }

    /// The points observed, with their multipliers (none without them).
    pub fn into_points(self) -> Vec<TracedPoint> {
        self.path.traced
    }

    /// Locates the brackets of `which` (detector, start) on the path so far.
    fn locate(&mut self, branch: &mut B, which: Vec<(usize, usize)>) -> Vec<Event<E>> {
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
                detector: d,
                location: det.locate(at),
            });
        }
        events
    }
}

impl<B: Branch, E> Observer<B> for EventObserver<B, E> {
    type Error = E;

    fn on_point(&mut self, branch: &mut B, point: &PathPoint) -> Result<Vec<Event<E>>, E> {
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
    fn finish(&mut self, branch: &mut B) -> Result<Vec<Event<E>>, E> {
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
// The pair (path, events) is the result's shape, read at once by every caller.
#[allow(clippy::type_complexity)]
pub fn observe<B: Branch, O: Observer<B> + ?Sized>(
    stepper: &mut Stepper<'_, B>,
    observer: &mut O,
    mut on_point: impl FnMut(&mut B, &PathPoint) -> bool,
) -> Result<(Path, Vec<Event<O::Error>>), O::Error> {
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

/// The path of a system given by its residual alone (as
/// [`follow_residual`](crate::continuation::follow_residual): a
/// [`ResidualBranch`] on the one [`Stepper`] with the Broyden corrector, no
/// Jacobian estimate at the start) with each point handed to `observer` as
/// it arrives ([`observe`]): the path and the events located on it, in path
/// order.
///
/// # Errors
/// As `follow_residual` (converted into the observer's error); the
/// observer's error.
// The pair (path, events) is the result's shape, read at once by every caller.
#[allow(clippy::type_complexity)]
pub fn observe_residual<F, O>(
    residual: F,
    start: &[f64],
    direction: f64,
    opts: &ContinuationOptions,
    observer: &mut O,
    mut on_point: impl FnMut(&PathPoint) -> bool,
) -> Result<(Path, Vec<Event<O::Error>>), O::Error>
where
    F: FnMut(&[f64], &mut [f64]),
    O: Observer<ResidualBranch<F>> + ?Sized,
    O::Error: From<PathError>,
{
    let m = start.len().saturating_sub(1);
    let mut branch = ResidualBranch::new(m, residual);
    let corrector = Box::new(BroydenCorrector::new(m, &opts.broyden, None));
    let mut stepper = Stepper::new(&mut branch, corrector, start, 0, direction, opts)?;
    observe(&mut stepper, observer, |_, p| on_point(p))
}
