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
//! ([`ivt_path::continuation::Stepper`], Eq. 68–77) with `p` as the path parameter. A cusp is a
//! turning point of this curve in `p` (there the two folds of the FRC merge):
//! the path's fold detection brackets it and a second, short path with a
//! hundredth of the step through the bracket locates it (parabola through the
//! three points around the turn). The fold at each requested `p` is solved at
//! fixed `p` by Newton ([`ivt_num::newton()`]) from the bracketing points.
//!
//! Here the excitation may depend on `p` (a force amplitude): the residual is
//! planned anew when `p` changes. `family(p)` returns a `Result`, so a family
//! built from user callbacks can fail cleanly.
//!
//! Period-doubling and Neimark–Sacker curves are in [`multiplier_curve`]
//! ([`bifurcation_curve`]); the fixed-`p` solve all curves share is
//! `fixed.rs`.

pub mod cycle_fold;
mod fixed;
mod fold_system;
pub mod multiplier_curve;
pub use cycle_fold::{cycle_fold_curve, CycleFoldCurve, CycleFoldPoint};
pub use multiplier_curve::{bifurcation_curve, BifurcationCurve, CurvePoint, CurveStart};

use crate::error::HbError;
use crate::orbit::ihb::HbOptions;
use crate::problem::PeriodicProblem;
use fixed::{solve_crossings, CurveSystem};
use fold_system::FoldSystem;
use ivt_num::vector::norm2;
use ivt_path::continuation::{
    follow_residual, ContinuationOptions, Path, PathPoint, Termination, Turn,
};

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
    /// Why tracing stopped.
    pub termination: Termination,
}

/// A fold curve in (ω, p).
pub type FoldCurve = Curve<FoldPoint>;

/// The curve of `sys` along `path` (joined [`Legs`]) with the given `cusps`:
/// each path point mapped to its point and the points at each value of `at`
/// of the path parameter (the last component) solved at fixed value.
fn fold_curve_of<S: CurveSystem>(
    sys: &mut S,
    (path, termination): (Vec<PathPoint>, Termination),
    at: &[f64],
    cusps: Vec<S::Point>,
    scale: f64,
) -> Curve<S::Point> {
    let p_index = path.first().map_or(0, |pt| pt.x.len().saturating_sub(1));
    let located = solve_crossings(sys, &path, at, p_index, scale);
    let points = path.iter().filter_map(|pt| sys.point(&pt.x)).collect();
    Curve {
        points,
        at: located,
        cusps,
        termination,
    }
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
    pub first: Path,
    /// From the start the other way.
    pub second: Option<Path>,
}

impl Legs {
    /// `trace(direction)` (the path from the start with that sign of the
    /// path parameter's initial change) for the direction from `p_start`
    /// towards `p_from`, then for the other.
    ///
    /// # Errors
    /// `trace`'s.
    pub(crate) fn follow<E>(
        (p_start, p_from, p_to): (f64, f64, f64),
        mut trace: impl FnMut(f64) -> Result<Path, E>,
    ) -> Result<Self, E> {
        let direction = if p_from < p_start { -1.0 } else { 1.0 };
        let first = trace(direction)?;
        let cut = matches!(
            first.termination,
            Termination::Interrupted | Termination::MaxPoints
        );
        let second = if cut || p_start == p_to {
            None
        } else {
            Some(trace(-direction)?)
        };
        Ok(Self { first, second })
    }

    /// `locate(path, turn)` for each turn of each leg (a cusp) that it
    /// locates, in the order of [`Self::joined`].
    pub(crate) fn cusps<T>(&self, mut locate: impl FnMut(&Path, &Turn) -> Option<T>) -> Vec<T> {
        let mut found: Vec<T> = (self.first.events.iter())
            .filter_map(|turn| locate(&self.first, turn))
            .collect();
        if let Some(path) = &self.second {
            found.reverse();
            found.extend(path.events.iter().filter_map(|turn| locate(path, turn)));
        }
        found
    }

    /// One path: with two legs in order from the first leg's end (its points
    /// reversed, then the second leg's after the shared start), with one the
    /// first leg from the start. The termination is the last leg's, unless
    /// the first failed (`step_too_small`): a failure is not hidden by the
    /// other leg's normal end.
    pub(crate) fn joined(self) -> (Vec<PathPoint>, Termination) {
        let Self { first, second } = self;
        match second {
            Some(second) => {
                let mut points: Vec<PathPoint> = first.points.into_iter().rev().collect();
                points.extend(second.points.into_iter().skip(1));
                let termination = match first.termination {
                    failed @ Termination::StepTooSmall(_) => failed,
                    _ => second.termination,
                };
                (points, termination)
            }
            None => (first.points, first.termination),
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
/// [`follow_residual`]'s. Later, a `p` where `family` fails is a failed
/// step, and a failed location of an `at` point or cusp is left out (the
/// curve is kept).
#[allow(clippy::too_many_arguments)]
pub fn fold_curve<P, F>(
    family: F,
    hb: &HbOptions,
    start: &[f64],
    omega: f64,
    p_start: f64,
    p_from: f64,
    p_to: f64,
    at: &[f64],
    opts: &ContinuationOptions,
) -> Result<FoldCurve, HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError>,
{
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
    let legs = Legs::follow((p_start, p_from, p_to), |direction| {
        follow_curve(&mut sys, &x0, direction, &copts)
    })?;
    let cusps = legs.cusps(|path, turn| locate_cusp(&mut sys, path, turn.bracket, &copts));
    Ok(fold_curve_of(
        &mut sys,
        legs.joined(),
        at,
        cusps,
        norm2(start),
    ))
}

/// The turning point in `p` near `path.points[bracket..bracket + 3]`: a
/// short path through the bracket with 1/100 of its spacing, and the vertex of
/// the parabola through the three points around its own turn.
fn locate_cusp<P: PeriodicProblem, F: Fn(f64) -> Result<P, HbError>>(
    sys: &mut FoldSystem<'_, F>,
    path: &Path,
    bracket: usize,
    opts: &ContinuationOptions,
) -> Option<FoldPoint> {
    let (a, b) = (path.points.get(bracket)?, path.points.get(bracket + 2)?);
    let span: f64 =
        a.x.iter()
            .zip(&b.x)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt();
    let ds = span / 200.0;
    let mut fine = opts.clone();
    fine.ds = ds;
    fine.ds_max = ds;
    fine.ds_min = ds * 1e-3;
    fine.max_points = 500;
    let dir = if a.dlambda < 0.0 { -1.0 } else { 1.0 };
    let mut turned = false;
    let residual = |x: &[f64], r: &mut [f64]| sys.residual(x, r);
    let local = follow_residual(residual, &a.x, None, dir, &fine, |pt| {
        // Stop two points after the turn.
        let stop = turned;
        turned = turned || pt.dlambda * dir < 0.0;
        !stop
    })
    .ok()?;
    let fold = local.events.first()?;
    let mut x = local.points.get(fold.index)?.x.clone();
    if let Some(last) = x.last_mut() {
        *last = fold.lambda;
    }
    let mut point = sys.point(&x)?;
    point.p = fold.lambda;
    Some(point)
}

/// `opts` with the path parameter bounded to `[lo, hi]`.
fn bounded(opts: &ContinuationOptions, (lo, hi): (f64, f64)) -> ContinuationOptions {
    let mut copts = opts.clone();
    copts.lambda_min = lo;
    copts.lambda_max = hi;
    copts
}

/// The path of the curve of `sys` from `x0` (the path parameter last) with
/// the sign `direction` of the path parameter's first change, to its end or
/// the bounds of `opts`.
///
/// # Errors
/// The start's failures as [`follow_residual`]'s.
fn follow_curve<S: CurveSystem>(
    sys: &mut S,
    x0: &[f64],
    direction: f64,
    opts: &ContinuationOptions,
) -> Result<Path, HbError> {
    let residual = |x: &[f64], r: &mut [f64]| sys.residual(x, r);
    Ok(follow_residual(
        residual,
        x0,
        None,
        direction,
        opts,
        |_| true,
    )?)
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

/// Each pair of consecutive points of `path` whose component `index` brackets a
/// value of `values`, with that value: `(a, b, value)`, values in the order
/// given, pairs in path order.
pub(crate) fn crossings<'p>(
    path: &'p [PathPoint],
    values: &'p [f64],
    index: usize,
) -> impl Iterator<Item = (&'p [f64], &'p [f64], f64)> + 'p {
    values.iter().flat_map(move |&v| {
        path.windows(2).filter_map(move |w| {
            let [a, b] = w else { return None };
            let (ya, yb) = (*a.x.get(index)?, *b.x.get(index)?);
            // Strictly inside, or at the window's end (or the path's start):
            // a point exactly at `v` counts once.
            let first = std::ptr::eq(a, path.first()?);
            let hit = (ya - v) * (yb - v) < 0.0 || yb == v || (first && ya == v);
            (hit && ya != yb).then_some((a.x.as_slice(), b.x.as_slice(), v))
        })
    })
}
