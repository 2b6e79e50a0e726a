//! Pseudo-arclength continuation of a [`Branch`] `R(u, λ) = 0`,
//! `R: R^{m+1} → R^m`, after §3.2.3 (Eq. 68–77): one [`Stepper`] that
//! predicts along the unit direction at the last point (Eq. 71,
//! `predictor.rs`), corrects with a [`PathCorrector`] (`corrector/`: Broyden
//! on the secant model with the exact constraint row, Eq. 72–77, or chord
//! and Newton on the exact bordered Jacobian), and adapts the step by one
//! rule (`step_control.rs`: the corrector's effort, halving on failure and on
//! a rejected point — one whose direction turned by more than
//! [`ContinuationOptions::max_turn`] or that lies farther than
//! [`ContinuationOptions::max_correction`]`·Δη` from its prediction — the cap
//! [`ContinuationOptions::step_cap`], landing on the bounds of λ). A sign
//! change of the direction's λ component marks a turn in λ ([`Turn`]).

use ivt_num::vector::norm2;
use ivt_num::{BroydenOptions, SolveError};

pub mod corrector;
mod predictor;
mod residual_path;
mod start;
mod step_control;
mod stepper;
mod steps;
#[cfg(test)]
mod tests;
pub use corrector::{BroydenCorrector, NewtonCorrector, PathCorrector};
pub use residual_path::follow_residual;
pub use start::correct_at_fixed_lambda;
pub use stepper::{Step, Stepper};
pub use steps::Steps;

#[cfg(doc)]
use crate::branch::Branch;

/// Options of the path follower.
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuationOptions {
    /// Initial arclength step Δη.
    pub ds: f64,
    /// Smallest step before giving up.
    pub ds_min: f64,
    /// Largest step while the solution is of order `ds_relative_scale`;
    /// beyond, the largest step grows with it ([`ContinuationOptions::step_cap`]).
    pub ds_max: f64,
    /// The size of `‖x‖₂` above which `ds_max` turns relative:
    /// `Δη ≤ ds_max·max(1, ‖x‖₂/ds_relative_scale)`. An absolute cap cannot
    /// serve a curve that is both of order one (where the sweep starts) and
    /// of order `1/(2ζ)` (the peak of a lightly damped resonance: 500 for
    /// ζ = 0.001, a circle of that diameter in the plane of the first
    /// harmonic, whose arclength would need 20 000 steps of 0.08). Default 10;
    /// `f64::INFINITY` keeps the cap absolute.
    pub ds_relative_scale: f64,
    /// Maximum number of points (including the start).
    pub max_points: usize,
    /// The interval of λ: a step that would leave it is corrected on the
    /// bound instead, and the path ends there (no point outside).
    pub lambda_min: f64,
    /// See `lambda_min`.
    pub lambda_max: f64,
    /// Corrector iterations aimed at; fewer grow the step, more shrink it.
    pub target_iter: usize,
    /// Step growth factor after an easy corrector.
    pub growth: f64,
    /// The largest angle (radians) between the directions at two consecutive
    /// points: a step whose direction turned by more is rejected and redone
    /// at half the length (COCO's `al_max`, the angle between consecutive
    /// tangents of its 1-d atlas). Without it a step longer than a sharp
    /// resonance is wide lands on the far side of the peak, and the curve
    /// misses it; a tight bound spends points on every bend.
    /// Default 1 (about 57°); `π` switches the check off.
    pub max_turn: f64,
    /// The largest distance of the corrected point from the prediction,
    /// relative to the step Δη: farther, the corrector converged onto
    /// another part of the branch, and the step is rejected and redone at
    /// half the length (the corrector-distance test of HomCont and MatCont).
    /// Default 0.5; `f64::INFINITY` switches the check off.
    pub max_correction: f64,
    /// Corrector options (tolerance, iteration limit, refresh policy).
    pub broyden: BroydenOptions,
    /// [`NewtonCorrector`] only: predict along the tangent and the
    /// curvature of the last two tangents, `x + Δη t + ½Δη² κ` with
    /// `κ = (t − t_prev)/‖x − x_prev‖`, and assemble and factor the chord
    /// corrector's Jacobian at that prediction instead of at the previous
    /// point. From a distance of O(Δη³) the chord then converges in about two
    /// iterations (on the 2-DOF chain of `tests/corrector.rs`: 3.5 calls of
    /// `g` per point instead of 7.2, measured; < 0.6× asserted), and its LU, bordered by the
    /// tangent, gives the next tangent. The price: the last Jacobian assembled
    /// when `on_point` runs is the prediction's, not the point's.
    pub second_order_predictor: bool,
    /// The corrector, where a path offers both (ivt-hb's frequency response,
    /// its traced events, the backbone): [`Corrector::Broyden`] (Eq. 68–77,
    /// the default) or [`Corrector::Newton`]. Not read by the paths that have
    /// one: [`follow_residual`] (a residual alone) is Broyden's, the string
    /// and condensed sweeps (exact Jacobians) are Newton's.
    pub corrector: Corrector,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        Self {
            ds: 0.02,
            ds_min: 1e-7,
            ds_max: 0.2,
            ds_relative_scale: 10.0,
            max_points: 5000,
            lambda_min: f64::NEG_INFINITY,
            lambda_max: f64::INFINITY,
            target_iter: 10,
            growth: 1.5,
            max_turn: 1.0,
            max_correction: 0.5,
            broyden: BroydenOptions {
                max_iter: 25,
                ..BroydenOptions::default()
            },
            second_order_predictor: false,
            corrector: Corrector::Broyden,
        }
    }
}

/// The corrector of a path follower.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Corrector {
    /// Broyden on the secant model with the exact constraint row (Eq. 68–77,
    /// [`BroydenCorrector`]): many cheap iterations per point, no Jacobian
    /// assembly; the thesis's method and the cheapest when the residual is.
    #[default]
    Broyden,
    /// Chord iterations on the exact bordered Jacobian, Newton as fallback
    /// ([`NewtonCorrector`]): one Jacobian assembly and a few residuals
    /// per point; the cheapest when residual evaluations are costly (a user's
    /// callback).
    Newton,
}

/// One converged point on the path.
#[derive(Debug, Clone, PartialEq)]
pub struct PathPoint {
    /// The solution `{q, λ}`.
    pub x: Vec<f64>,
    /// Corrector iterations used.
    pub iterations: usize,
    /// λ component of the unit secant that led here (sign = direction in λ).
    pub dlambda: f64,
    /// Sign of `det [[R_q, R_λ], [tᵀ]]` at the point (`t` the oriented unit
    /// tangent), the branch-point test function, when the corrector factored
    /// that matrix ([`NewtonCorrector`]: the tangent's LU, bordered by
    /// the previous tangent, has the same sign); `None` from Broyden.
    pub bordered_sign: Option<f64>,
}

impl PathPoint {
    /// The path parameter λ (last entry of `x`).
    pub fn lambda(&self) -> f64 {
        self.x.last().copied().unwrap_or(f64::NAN)
    }
}

/// A turning point in λ as the stepper sees it: the direction's λ component
/// changed sign between the points `bracket`, `bracket + 1` and
/// `bracket + 2` (its estimate; the fold itself is located by the
/// [`crate::events::Fold`] detector).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turn {
    /// Index of the point nearest the turn (in arclength along the parabola).
    pub index: usize,
    /// λ at the turn from a parabola through the three points around it.
    pub lambda: f64,
    /// Index of the first of the three points around the turn.
    pub bracket: usize,
}

/// Why the path follower stopped (stopping is not failing).
#[derive(Debug, Clone, PartialEq)]
pub enum Termination {
    /// λ left the requested interval.
    LeftInterval,
    /// `max_points` reached.
    MaxPoints,
    /// The callback asked to stop.
    Stopped,
    /// The step fell below `ds_min`; carries the last corrector error.
    StepTooSmall(SolveError),
    /// The caller cancelled the path ([`ivt_num::cancel`], Ctrl-C in Python).
    Interrupted,
}

impl Termination {
    /// The snake_case word of JSON and Python (SPEC §6), never Debug text.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::LeftInterval => "left_interval",
            Self::MaxPoints => "max_points",
            Self::Stopped => "stopped",
            Self::StepTooSmall(_) => "step_too_small",
            Self::Interrupted => "interrupted",
        }
    }
}

/// Serialized as [`Termination::as_str`] (the corrector error is not part of it).
impl serde::Serialize for Termination {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

/// The one result of a traced curve: its points and events in path order
/// and why tracing stopped. The stepper's [`Path`] holds the raw states and
/// its turns; ivt-hb's `Frc` and ivt-condense's `CondensedFrc` hold the same
/// curve read as orbits, its `Trace` the orbits with their multipliers and
/// every event detected, its `Backbone` and `LimitCycleBranch` the curves in
/// amplitude and in μ. Serializes (where its point and event types do) with
/// [`Termination`] as its snake_case word.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Traced<P, E> {
    /// Points in path order.
    pub points: Vec<P>,
    /// Events in path order: for [`Path`] the turns in λ the stepper
    /// detects; for the curves read from it the folds located there; for a
    /// trace every event detected, each with its location or why locating
    /// it failed.
    pub events: Vec<E>,
    /// Why tracing stopped.
    pub termination: Termination,
}

/// A traced path: the converged states and the turns the stepper detected.
pub type Path = Traced<PathPoint, Turn>;

impl ContinuationOptions {
    /// The largest step at the point `x`: `ds_max`, relative to `‖x‖₂`
    /// above `ds_relative_scale`.
    pub fn step_cap(&self, x: &[f64]) -> f64 {
        self.ds_max * (norm2(x) / self.ds_relative_scale).max(1.0)
    }
}

/// The state `{q, λ}` at the turn between three consecutive points `a`, `b`,
/// `c` around a fold: the quadratic through them in chord arclength s,
/// evaluated where its λ(s) is extremal (`b` itself if λ(s) is straight).
/// Off the path by O(Δη³) rather than the O(Δη) of the nearest point: the
/// start for [`crate::events::locate_fold`].
pub fn turn_estimate(a: &PathPoint, b: &PathPoint, c: &PathPoint) -> Vec<f64> {
    turn(a, b, c).0
}

/// [`turn_estimate`] and which of the three points (0, 1, 2) lies nearest
/// the turn in arclength.
pub(crate) fn turn(a: &PathPoint, b: &PathPoint, c: &PathPoint) -> (Vec<f64>, usize) {
    let dist = |p: &PathPoint, q: &PathPoint| predictor::distance(&p.x, &q.x);
    let (s0, s1, s2) = (0.0, dist(a, b), dist(a, b) + dist(b, c));
    let (l0, l1, l2) = (a.lambda(), b.lambda(), c.lambda());
    // Divided differences: λ = l0 + d1 (s − s0) + d2 (s − s0)(s − s1).
    let d1 = (l1 - l0) / (s1 - s0);
    let d2 = ((l2 - l1) / (s2 - s1) - d1) / (s2 - s0);
    let s = 0.5 * (s0 + s1) - d1 / (2.0 * d2);
    if d2 == 0.0 || !s.is_finite() {
        return (b.x.clone(), 1);
    }
    let nearest = [s0, s1, s2]
        .iter()
        .map(|si| (si - s).abs())
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .map_or(1, |(i, _)| i);
    // Lagrange weights of the three points at s.
    let w0 = (s - s1) * (s - s2) / ((s0 - s1) * (s0 - s2));
    let w1 = (s - s0) * (s - s2) / ((s1 - s0) * (s1 - s2));
    let w2 = (s - s0) * (s - s1) / ((s2 - s0) * (s2 - s1));
    let x =
        a.x.iter()
            .zip(&b.x)
            .zip(&c.x)
            .map(|((u, v), w)| w0 * u + w1 * v + w2 * w)
            .collect();
    (x, nearest)
}
