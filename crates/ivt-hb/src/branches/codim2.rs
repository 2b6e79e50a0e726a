//! Two-parameter continuation of the folds of frequency-response curves
//! (issue 27, item 1): how a fold moves with a second parameter `p` of a model
//! family `family(p)`, and where two folds meet (the cusp below which the jump
//! disappears).
//!
//! A fold of the FRC in ω is a point where the Galerkin Jacobian `Φ_q`
//! (Eq. 56) of the HB residual `R(q, ω; p)` (Eq. 61) is singular. The standard
//! extended system (Keller; the fold systems of AUTO and MATCONT)
//!
//! `R(q, ω; p) = 0`,  `Φ_q(q, ω; p) v = 0`,  `(vᵀv − 1)/2 = 0`
//!
//! (a unit null vector: a fixed normalisation `cᵀv = 1` lets `v` grow without
//! bound where it turns away from `c`, as it does through a cusp) has the unknowns `{q, v, ω}` and `p`; it is
//! followed by the engine's pseudo-arclength continuation
//! ([`ivt_path::continuation::Stepper`], Eq. 68–77) with `p` as the path
//! parameter, the extended system given by its residual
//! ([`ivt_path::ResidualBranch`]). Its events are located as the points
//! arrive ([`ivt_path::events::observe_residual`]): a cusp is a turning point
//! of the curve in `p` (there the two folds of the FRC merge), the engine's
//! [`Fold`] of the extended system; the fold at each requested `p` is the
//! [`Crossing`] of that value, solved at fixed `p` by Newton from the
//! interpolation of the two path points around it.
//!
//! Here the excitation may depend on `p` (a force amplitude): the residual is
//! planned anew when `p` changes. `family(p)` returns a `Result`, so a family
//! built from user callbacks can fail cleanly.
//!
//! Period-doubling and Neimark–Sacker curves are in [`multiplier_curve`]
//! ([`bifurcation_curve`]), folds of limit cycles in [`cycle_fold`]; the
//! legs, events and result all curves share are here.

pub mod cycle_fold;
mod fold_system;
pub mod multiplier_curve;
pub use cycle_fold::{cycle_fold_curve, CycleFoldCurve, CycleFoldPoint};
pub use multiplier_curve::{bifurcation_curve, BifurcationCurve, CurvePoint, CurveStart};

use crate::branches::events::{name_family_failures, Unlocated};
use crate::error::HbError;
use crate::orbit::ihb::HbOptions;
use crate::problem::BoxedFamily;
use fold_system::FoldSystem;
use ivt_num::vector::norm2;
use ivt_path::continuation::{ContinuationOptions, Path, PathPoint, Termination};
use ivt_path::events::{
    observe_residual, Bifurcation, Crossing, Detector, Event, EventObserver, Fold, LocateOptions,
};
use ivt_path::{Branch, PathError};

/// One fold on the curve.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldPoint {
    /// Excitation frequency ω_f of the fold.
    pub omega: f64,
    /// The second parameter.
    pub p: f64,
    /// Fourier coefficients of the orbit at the fold.
    pub coeffs: Vec<f64>,
    /// The unit null vector of `Φ_q`.
    pub null_vector: Vec<f64>,
}

/// A curve of folds: of the FRC in (ω, p) ([`FoldCurve`]) or of limit
/// cycles in (μ, ν) ([`CycleFoldCurve`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Curve<T> {
    /// Points in path order.
    pub points: Vec<T>,
    /// The fold at each requested value of the path parameter, each time the
    /// curve crosses it, in path order.
    pub at: Vec<T>,
    /// Cusps: turning points of the curve in its path parameter.
    pub cusps: Vec<T>,
    /// The `at` points and cusps the path passed but whose location failed,
    /// in path order.
    pub unlocated: Vec<Unlocated<T>>,
    /// Why tracing stopped.
    pub termination: Termination,
}

/// A fold curve in (ω, p).
pub type FoldCurve = Curve<FoldPoint>;

/// The extended system of a two-parameter curve: `n − 1` equations in the
/// path vector `x` of `n` entries (the path parameter last), followed as a
/// [`ivt_path::ResidualBranch`] by the one stepper.
pub(crate) trait CurveSystem {
    /// What a point of the curve reports.
    type Point;

    /// The residual at `x` into `r` (`n − 1` entries); `None` where it
    /// cannot be evaluated (sizes disagree or the family fails at that `p`).
    fn try_residual(&mut self, x: &[f64], r: &mut [f64]) -> Option<()>;

    /// The curve's point at the path vector `x` (`None` if `x` is short).
    fn point(&self, x: &[f64]) -> Option<Self::Point>;

    /// [`Self::try_residual`], NaN where it cannot be evaluated (a failed
    /// step to the path).
    fn residual(&mut self, x: &[f64], r: &mut [f64]) {
        if self.try_residual(x, r).is_none() {
            r.fill(f64::NAN);
        }
    }
}

/// The crossings of each value of `values` by component `index` of a
/// curve's path vector, located to the residual's `scale`
/// ([`Crossing::scaled`]).
pub(crate) fn crossings(index: usize, values: &[f64], scale: f64) -> Vec<Crossing> {
    (values.iter())
        .map(|&v| Crossing::scaled(index, v, scale))
        .collect()
}

/// One leg of a curve: its path and the events located on it as its points
/// arrived, in path order.
pub(crate) struct Leg {
    /// The path.
    pub path: Path,
    /// Its events: the crossings (detector `i` is crossing `i`), then the
    /// cusps (detector = the number of crossings).
    pub events: Vec<Event<PathError>>,
}

impl Leg {
    /// The leg's events split into the located (detector, location) and the
    /// failed (detector, the locator's start point, error), each in path
    /// order.
    #[allow(clippy::type_complexity)]
    fn split(&self) -> (Vec<(usize, Bifurcation)>, Vec<(usize, Vec<f64>, PathError)>) {
        let (mut located, mut failed) = (Vec::new(), Vec::new());
        for e in &self.events {
            match &e.location {
                Ok(b) => located.push((e.detector, b.clone())),
                Err(err) => {
                    let start = self.path.points.get(e.index).map(|p| p.x.clone());
                    failed.push((e.detector, start.unwrap_or_default(), err.clone()));
                }
            }
        }
        (located, failed)
    }
}

/// Follows `residual` from `x0` with the sign `direction` of the path
/// parameter's first change, to its end, the bounds of `opts` or the first
/// point `keep` refuses, locating each of `watch` and (if `cusps`) the
/// turning points in the path parameter ([`Fold`]) as the points arrive.
///
/// # Errors
/// The start's failures as [`ivt_path::follow_residual`]'s.
pub(crate) fn follow_leg(
    residual: impl FnMut(&[f64], &mut [f64]),
    x0: &[f64],
    direction: f64,
    opts: &ContinuationOptions,
    (watch, cusps): (&[Crossing], bool),
    keep: impl FnMut(&PathPoint) -> bool,
) -> Result<Leg, HbError> {
    let mut observer = EventObserver::new(&LocateOptions::default(), detectors(watch, cusps));
    let (path, events) = observe_residual(residual, x0, direction, opts, &mut observer, keep)?;
    Ok(Leg { path, events })
}

/// The detectors of a leg: `watch` in order, then the [`Fold`] if `cusps`.
fn detectors<B: Branch>(watch: &[Crossing], cusps: bool) -> Vec<Box<dyn Detector<B, PathError>>> {
    let mut found: Vec<Box<dyn Detector<B, PathError>>> = (watch.iter().cloned())
        .map(|c| Box::new(c) as Box<dyn Detector<B, PathError>>)
        .collect();
    if cusps {
        found.push(Box::new(Fold));
    }
    found
}

/// The path vector `[q, λ]` of a located event.
pub(crate) fn event_vector(b: &Bifurcation) -> Vec<f64> {
    let mut x = b.q.clone();
    x.push(b.lambda);
    x
}

/// The two legs of a curve through its start: the path from the start
/// towards one end of the interval, and — unless the start is the other end,
/// or the first leg was cut short (interrupted, or at `max_points`, e.g.
/// round a closed curve) — the path from the start the other way. A leg that
/// turns (a cusp) runs back on the other branch and leaves the interval at
/// the far end without passing the start's own branch there, so both legs
/// are followed.
pub(crate) struct Legs {
    /// From the start towards the first end.
    pub first: Leg,
    /// From the start the other way.
    pub second: Option<Leg>,
}

/// A curve's legs joined into one path from the first leg's end.
pub(crate) struct Joined {
    /// The points in path order.
    pub points: Vec<PathPoint>,
    /// The termination (see [`Legs::joined`]).
    pub termination: Termination,
    /// The located events in the same order: (detector, location).
    pub events: Vec<(usize, Bifurcation)>,
    /// The events that failed to locate, in the same order: (detector, the
    /// locator's start point, its error).
    pub failed: Vec<(usize, Vec<f64>, PathError)>,
}

impl Joined {
    /// The located events of detector `d`, in path order.
    pub(crate) fn of(&self, d: usize) -> impl Iterator<Item = &Bifurcation> + '_ {
        (self.events.iter())
            .filter(move |(detector, _)| *detector == d)
            .map(|(_, b)| b)
    }

    /// The curve of `point` (a curve system's point at a path vector) with
    /// the crossings of detectors `0..n_at` (value by value, each in path
    /// order) as its `at` points and the events of detector `n_at` as its
    /// cusps.
    pub(crate) fn curve<T>(
        self,
        watch: &[Crossing],
        point: impl Fn(&[f64]) -> Option<T>,
    ) -> Curve<T> {
        let n_at = watch.len();
        let at = (0..n_at)
            .flat_map(|d| self.of(d))
            .filter_map(|b| point(&event_vector(b)))
            .collect();
        let cusps = self
            .of(n_at)
            .filter_map(|b| point(&event_vector(b)))
            .collect();
        let unlocated = self.unlocated(&point, |d| match watch.get(d) {
            Some(c) => Some(("at", Some(c.value()))),
            None => Some(("cusp", None)),
        });
        Curve {
            points: self.points.iter().filter_map(|pt| point(&pt.x)).collect(),
            at,
            cusps,
            unlocated,
            termination: self.termination,
        }
    }

    /// The failed events as [`Unlocated`] points, `what(detector)` naming
    /// each (and giving its value, if any; `None` leaves it out).
    pub(crate) fn unlocated<T>(
        &self,
        point: impl Fn(&[f64]) -> Option<T>,
        what: impl Fn(usize) -> Option<(&'static str, Option<f64>)>,
    ) -> Vec<Unlocated<T>> {
        (self.failed.iter())
            .filter_map(|(d, start, e)| {
                let (what, value) = what(*d)?;
                Some(Unlocated {
                    what,
                    value,
                    near: point(start)?,
                    reason: e.to_string(),
                })
            })
            .collect()
    }
}

impl Legs {
    /// `trace(direction)` (the leg from the start with that sign of the
    /// path parameter's initial change) for the direction from `p_start`
    /// towards `p_from`, then for the other.
    ///
    /// # Errors
    /// `trace`'s.
    pub(crate) fn follow<E>(
        (p_start, p_from, p_to): (f64, f64, f64),
        mut trace: impl FnMut(f64) -> Result<Leg, E>,
    ) -> Result<Self, E> {
        let direction = if p_from < p_start { -1.0 } else { 1.0 };
        let first = trace(direction)?;
        let cut = matches!(
            first.path.termination,
            Termination::Interrupted | Termination::MaxPoints
        );
        let second = if cut || p_start == p_to {
            None
        } else {
            Some(trace(-direction)?)
        };
        Ok(Self { first, second })
    }

    /// One path: with two legs in order from the first leg's end (its points
    /// and events reversed, then the second leg's after the shared start),
    /// with one the first leg from the start. The termination is the last
    /// leg's, unless the first failed (`step_too_small`): a failure is not
    /// hidden by the other leg's normal end.
    pub(crate) fn joined(self) -> Joined {
        let Self { first, second } = self;
        let (mut events, mut failed) = first.split();
        match second {
            Some(second) => {
                events.reverse();
                failed.reverse();
                let (more, more_failed) = second.split();
                events.extend(more);
                failed.extend(more_failed);
                let mut points: Vec<PathPoint> = first.path.points.into_iter().rev().collect();
                points.extend(second.path.points.into_iter().skip(1));
                let termination = match first.path.termination {
                    failed @ Termination::StepTooSmall(_) => failed,
                    _ => second.path.termination,
                };
                Joined {
                    points,
                    termination,
                    events,
                    failed,
                }
            }
            None => Joined {
                points: first.path.points,
                termination: first.path.termination,
                events,
                failed,
            },
        }
    }
}

/// Follows the fold of the FRC of `family(p_start)` at `(start, omega)` (a
/// located fold: coefficients and ω_f) in `p`, first towards `p_from` until `p`
/// leaves `[min(p_from, p_to), max(p_from, p_to)]`, then from the start towards
/// `p_to` (`Legs`); points in path order from the first leg's end (from the
/// start when `p_to` is the start); the folds
/// at each `p` of `at` (every crossing of either leg) and the cusps are
/// located (see the module docs).
///
/// # Errors
/// [`HbError::InvalidInput`] for sizes or bounds (`p_start` must lie in the
/// interval); `family(p_start)`'s error; the start's failures as
/// [`ivt_path::follow_residual`]'s. Later, a `p` where `family` fails is a failed
/// step, and an `at` point or cusp whose location fails is reported in
/// [`Curve::unlocated`] with the reason (the curve is kept).
///
/// `family` is any `p ↦ problem` with its members boxed: `&boxed_family(f)`
/// ([`crate::problem::boxed_family`]), so this body is compiled once for
/// every model.
#[allow(clippy::too_many_arguments)]
pub fn fold_curve(
    family: &BoxedFamily<'_, '_>,
    hb: &HbOptions,
    start: &[f64],
    omega: f64,
    p_start: f64,
    p_from: f64,
    p_to: f64,
    at: &[f64],
    opts: &ContinuationOptions,
) -> Result<FoldCurve, HbError> {
    let (lo, hi) = path_interval("fold curve", omega, p_start, p_from, p_to)?;
    let mut sys = FoldSystem::new(&family, hb, p_start)?;
    let m = sys.m;
    if start.len() != m {
        return Err(HbError::InvalidInput(format!(
            "the start fold must have {m} coefficients"
        )));
    }
    let v0 = sys.null_vector(start, omega, p_start)?;
    let mut x0 = start.to_vec();
    x0.extend_from_slice(&v0);
    x0.extend([omega, p_start]);
    let copts = bounded(opts, (lo, hi));
    let watch = crossings(x0.len() - 1, at, norm2(start));
    let legs = Legs::follow((p_start, p_from, p_to), |direction| {
        let residual = |x: &[f64], r: &mut [f64]| sys.residual(x, r);
        follow_leg(residual, &x0, direction, &copts, (&watch, true), |_| true)
    })?;
    let mut curve = legs.joined().curve(&watch, |x| sys.point(x));
    name_family_failures(&mut curve.unlocated, |p, _| family(p).err());
    Ok(curve)
}

/// `opts` with the path parameter bounded to `[lo, hi]`.
fn bounded(opts: &ContinuationOptions, (lo, hi): (f64, f64)) -> ContinuationOptions {
    let mut copts = opts.clone();
    copts.lambda_min = lo;
    copts.lambda_max = hi;
    copts
}

/// The interval `[lo, hi]` of `p` of a curve of `what` from `(ω, p_start)`.
///
/// # Errors
/// [`HbError::InvalidInput`] unless all are finite, `p_from ≠ p_to`,
/// `p_start` lies between them and ω > 0.
pub(crate) fn path_interval(
    what: &str,
    omega: f64,
    p_start: f64,
    p_from: f64,
    p_to: f64,
) -> Result<(f64, f64), HbError> {
    let (lo, hi) = (p_from.min(p_to), p_from.max(p_to));
    let finite = [p_start, p_from, p_to, omega].iter().all(|v| v.is_finite());
    if finite && lo != hi && (lo..=hi).contains(&p_start) && omega > 0.0 {
        return Ok((lo, hi));
    }
    Err(HbError::InvalidInput(format!(
        "{what}: finite p_from ≠ p_to with the start's p between them, ω > 0"
    )))
}
