//! Pseudo-arclength continuation of `R(x) = 0`, `R: R^{m+1} → R^m` (the last entry of
//! `x` is the path parameter λ, e.g. ω), after §3.2.3 (Eq. 68–77).
//!
//! Each step predicts `x₀ = x_p + x_d Δη` along the secant `x_d` (Eq. 71) and
//! corrects with Broyden on the augmented system `[R(x); x_dᵀ(x − x_p) − Δη] = 0`.
//! The approximate Jacobian is `B_x = [[B_q, B_λ], [x_dᵀ]]` (Eq. 72): `B_q` is carried
//! over from the previous point, `B_λ` is refreshed by one finite difference, and
//! the last row is kept exact through every update ([`BroydenWorkspace::exact_rows`],
//! Eq. 77). Step length follows the corrector's iteration count; a failed corrector
//! halves the step and refreshes the Jacobian. A sign change of the secant's λ
//! component marks a fold (turning point).

use crate::broyden::{broyden_solve, BroydenOptions, BroydenWorkspace, SolveError};
use crate::error::HbError;
use ivt_num::vector::{dot, norm2};
use ivt_num::LuWorkspace;

mod corrector;
mod exact;
mod start;
pub use exact::{pseudo_arclength_exact, PathSystem};
pub use start::correct_at_fixed_lambda;

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
    /// Corrector options (tolerance, iteration limit, refresh policy).
    pub broyden: BroydenOptions,
    /// [`pseudo_arclength_exact`] only: predict along the tangent and the
    /// curvature of the last two tangents, `x + Δη t + ½Δη² κ` with
    /// `κ = (t − t_prev)/‖x − x_prev‖`, and assemble and factor the chord
    /// corrector's Jacobian at that prediction instead of at the previous
    /// point. From a distance of O(Δη³) the chord then converges in about two
    /// iterations (on the 2-DOF chain of `tests/corrector.rs`: 3.5 calls of
    /// `g` per point instead of 7.2, measured; < 0.6× asserted), and its LU, bordered by the
    /// tangent, gives the next tangent. The price: the last Jacobian assembled
    /// when `on_point` runs is the prediction's, not the point's.
    pub second_order_predictor: bool,
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
            broyden: BroydenOptions {
                max_iter: 25,
                ..BroydenOptions::default()
            },
            second_order_predictor: false,
        }
    }
}

/// The corrector of a path follower.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Corrector {
    /// Broyden on the secant model with the exact constraint row (Eq. 68–77,
    /// [`pseudo_arclength`]): many cheap iterations per point, no Jacobian
    /// assembly; the thesis's method and the cheapest when the residual is.
    #[default]
    Broyden,
    /// Chord iterations on the exact bordered Jacobian, Newton as fallback
    /// ([`pseudo_arclength_exact`]): one Jacobian assembly and a few residuals
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
    /// that matrix ([`pseudo_arclength_exact`]: the tangent's LU, bordered by
    /// the previous tangent, has the same sign); `None` from Broyden.
    pub bordered_sign: Option<f64>,
}

impl PathPoint {
    /// The path parameter λ (last entry of `x`).
    pub fn lambda(&self) -> f64 {
        *self.x.last().expect("non-empty point")
    }
}

/// A fold (turning point in λ): the secant's λ component changed sign between
/// the points `bracket`, `bracket + 1` and `bracket + 2`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fold {
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
}

impl Termination {
    /// The snake_case word of JSON and Python (SPEC §6), never Debug text.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::LeftInterval => "left_interval",
            Self::MaxPoints => "max_points",
            Self::Stopped => "stopped",
            Self::StepTooSmall(_) => "step_too_small",
        }
    }
}

/// Serialized as [`Termination::as_str`] (the corrector error is not part of it).
impl serde::Serialize for Termination {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

/// A traced path.
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    /// Converged points in order.
    pub points: Vec<PathPoint>,
    /// Detected folds.
    pub folds: Vec<Fold>,
    /// Why tracing stopped.
    pub termination: Termination,
}

impl ContinuationOptions {
    /// The largest step at the point `x`: `ds_max`, relative to `‖x‖₂`
    /// above `ds_relative_scale`.
    pub fn step_cap(&self, x: &[f64]) -> f64 {
        self.ds_max * (norm2(x) / self.ds_relative_scale).max(1.0)
    }
}

/// The error of a start point or step that is not finite.
fn non_finite_start() -> HbError {
    HbError::InvalidInput("continuation: non-finite start or step".into())
}

/// Traces the solution path of `residual` from `start` (`m+1` entries, λ last; it is
/// first corrected at fixed λ) in the direction of increasing λ if `direction > 0`.
/// `jac0`, if given, is an initial row-major `m×(m+1)` Jacobian estimate at
/// `start` (otherwise finite differences). `on_point` sees each converged point and
/// returns `false` to stop.
///
/// # Errors
/// [`HbError::ContinuationStart`] if the start cannot be converged,
/// [`HbError::SingularStart`] if it has no tangent, [`HbError::InvalidInput`]
/// for bad sizes or non-finite inputs;
/// trouble later on ends the path with a [`Termination`] instead.
pub fn pseudo_arclength<R, C>(
    mut residual: R,
    start: &[f64],
    jac0: Option<&[f64]>,
    direction: f64,
    opts: &ContinuationOptions,
    mut on_point: C,
) -> Result<Path, HbError>
where
    R: FnMut(&[f64], &mut [f64]),
    C: FnMut(&PathPoint) -> bool,
{
    let n1 = start.len();
    if n1 < 2 {
        return Err(HbError::InvalidInput(
            "continuation needs at least one unknown and the parameter".into(),
        ));
    }
    if !start.iter().all(|v| v.is_finite())
        || opts.ds.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
    {
        return Err(non_finite_start());
    }
    let m = n1 - 1;
    // Jacobian estimate J (m × (m+1)).
    let mut jac = vec![0.0; m * n1];
    let mut r0 = vec![0.0; m];
    let mut r1 = vec![0.0; m];
    let mut xp = start.to_vec();
    // Forward-difference Jacobian with its own scratch (no allocation per call).
    let (mut f0, mut f1, mut xt) = (vec![0.0; m], vec![0.0; m], vec![0.0; n1]);
    let fd = opts.broyden.fd_step;
    let mut fd_jac = |res: &mut R, x: &[f64], jac: &mut [f64]| {
        xt.copy_from_slice(x);
        res(x, &mut f0);
        for j in 0..n1 {
            let h = fd * x[j].abs().max(1.0);
            xt[j] = x[j] + h;
            res(&xt, &mut f1);
            for i in 0..m {
                jac[i * n1 + j] = (f1[i] - f0[i]) / h;
            }
            xt[j] = x[j];
        }
    };
    match jac0 {
        Some(j) if j.len() == m * n1 => jac.copy_from_slice(j),
        Some(_) => {
            return Err(HbError::InvalidInput(
                "continuation: jac0 must be m×(m+1)".into(),
            ))
        }
        None => fd_jac(&mut residual, &xp, &mut jac),
    }
    // Correct the start at fixed λ.
    let lam0 = xp[m];
    let mut wsq = BroydenWorkspace::new(m);
    let bq: Vec<f64> = (0..m)
        .flat_map(|i| jac[i * n1..i * n1 + m].to_vec())
        .collect();
    if wsq.set_jacobian(&bq).is_err() {
        wsq.clear_jacobian();
    }
    let mut q = xp[..m].to_vec();
    let mut xfull = xp.clone();
    {
        let mut fixed = |qv: &[f64], r: &mut [f64]| {
            xfull[..m].copy_from_slice(qv);
            xfull[m] = lam0;
            residual(&xfull, r);
        };
        broyden_solve(&mut fixed, &mut q, &mut wsq, &opts.broyden).map_err(|cause| {
            HbError::ContinuationStart {
                lambda: lam0,
                cause,
            }
        })?;
    }
    xp[..m].copy_from_slice(&q);
    for i in 0..m {
        jac[i * n1..i * n1 + m].copy_from_slice(&wsq.jacobian()[i * m..(i + 1) * m]);
    }
    // Tangent at the start: B_q z = B_λ, t = [−z; 1].
    let mut lu = LuWorkspace::new(m);
    for i in 0..m {
        for j in 0..m {
            lu.mat[(i, j)] = jac[i * n1 + j];
        }
    }
    // A start near a fold has an ill-conditioned B_q and still a tangent: only
    // a non-finite solution (an exactly singular B_q) is refused.
    lu.factor();
    let mut z: Vec<f64> = (0..m).map(|i| jac[i * n1 + m]).collect();
    lu.solve(&mut z);
    if !z.iter().all(|v| v.is_finite()) {
        return Err(HbError::SingularStart { lambda: lam0 });
    }
    let mut xd: Vec<f64> = z.iter().map(|v| -v).chain(std::iter::once(1.0)).collect();
    let nt = norm2(&xd);
    let sign = if direction >= 0.0 { 1.0 } else { -1.0 };
    xd.iter_mut().for_each(|v| *v *= sign / nt);

    let mut points = vec![PathPoint {
        x: xp.clone(),
        iterations: 0,
        dlambda: xd[m],
        bordered_sign: None,
    }];
    let mut folds = Vec::new();
    if !on_point(&points[0]) {
        return Ok(Path {
            points,
            folds,
            termination: Termination::Stopped,
        });
    }
    let mut ws = BroydenWorkspace::new(n1);
    ws.exact_rows = m..n1;
    let mut b = vec![0.0; n1 * n1];
    let mut x = vec![0.0; n1];
    let mut ds = opts.ds;
    let mut fresh = true;
    // A corrected point fell outside the interval: redo the step onto the bound.
    let mut force_landing = false;
    let mut e_lambda = vec![0.0; n1];
    e_lambda[m] = 1.0;
    let termination = loop {
        if points.len() >= opts.max_points {
            break Termination::MaxPoints;
        }
        // A step that would leave [lambda_min, lambda_max] is shortened to
        // reach the bound and corrected on λ = bound (no point outside).
        let bound = if xd[m] > 0.0 {
            opts.lambda_max
        } else {
            opts.lambda_min
        };
        let to_bound = (bound - xp[m]) / xd[m];
        let landing = (to_bound.is_finite() && (force_landing || to_bound <= ds)).then_some(bound);
        let step = if landing.is_some() { to_bound } else { ds };
        if step.is_nan() || step <= 0.0 {
            break Termination::LeftInterval;
        }
        // Predictor (Eq. 71) and B_λ by one finite difference at the prediction.
        for i in 0..n1 {
            x[i] = xp[i] + xd[i] * step;
        }
        if let Some(l) = landing {
            x[m] = l;
        }
        let h = opts.broyden.fd_step * x[m].abs().max(1.0);
        residual(&x, &mut r0);
        x[m] += h;
        residual(&x, &mut r1);
        x[m] -= h;
        for i in 0..m {
            jac[i * n1 + m] = (r1[i] - r0[i]) / h;
        }
        // B_x = [[B_q, B_λ], [x_dᵀ]] (Eq. 72). After a successful step only the
        // λ column and the augmenting row change: two Sherman–Morrison updates.
        // The constraint row: the secant, or e_λ when landing.
        let row = if landing.is_some() { &e_lambda } else { &xd };
        let set = if fresh {
            b[..m * n1].copy_from_slice(&jac);
            b[m * n1..].copy_from_slice(row);
            ws.set_jacobian(&b)
        } else {
            let mut col: Vec<f64> = (0..m).map(|i| jac[i * n1 + m]).collect();
            col.push(ws.jacobian()[m * n1 + m]);
            ws.replace_col(m, &col)
                .and_then(|()| ws.replace_row(m, row))
        };
        fresh = false;
        let (xp_c, xd_c) = (xp.clone(), xd.clone());
        let mut aug = |xv: &[f64], r: &mut [f64]| {
            residual(xv, &mut r[..m]);
            r[m] = match landing {
                Some(l) => xv[m] - l,
                None => {
                    let mut g = 0.0;
                    for i in 0..n1 {
                        g += xd_c[i] * (xv[i] - xp_c[i]);
                    }
                    g - step
                }
            };
        };
        let outcome = match set {
            Ok(()) => broyden_solve(&mut aug, &mut x, &mut ws, &opts.broyden),
            Err(e) => Err(e),
        };
        let ok = match &outcome {
            Ok(_) => {
                let dist: f64 = x
                    .iter()
                    .zip(&xp)
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum::<f64>()
                    .sqrt();
                dist <= 3.0 * step
            }
            Err(_) => false,
        };
        if !ok {
            ds *= 0.5;
            if ds < opts.ds_min {
                let err = outcome.err().unwrap_or(SolveError::NonConvergence {
                    iterations: 0,
                    history: ws.history().to_vec(),
                });
                break Termination::StepTooSmall(err);
            }
            fd_jac(&mut residual, &xp, &mut jac);
            fresh = true;
            continue;
        }
        let iters = outcome.map(|s| s.iterations).unwrap_or(0);
        if landing.is_none() && (x[m] < opts.lambda_min || x[m] > opts.lambda_max) {
            force_landing = true;
            fresh = true;
            continue;
        }
        // Carry B_q forward.
        for i in 0..m {
            jac[i * n1..i * n1 + m].copy_from_slice(&ws.jacobian()[i * n1..i * n1 + m]);
        }
        // New secant (Eq. 71).
        let mut new_xd: Vec<f64> = x.iter().zip(&xp).map(|(a, b)| a - b).collect();
        let nn = norm2(&new_xd);
        new_xd.iter_mut().for_each(|v| *v /= nn);
        if dot(&new_xd, &xd) < 0.0 {
            // The corrector went backwards along the path: treat as a failure.
            ds *= 0.5;
            if ds < opts.ds_min {
                break Termination::StepTooSmall(SolveError::NonConvergence {
                    iterations: iters,
                    history: ws.history().to_vec(),
                });
            }
            fresh = true;
            continue;
        }
        let prev_dl = points.last().map(|p| p.dlambda).unwrap_or(new_xd[m]);
        let point = PathPoint {
            x: x.clone(),
            iterations: iters,
            dlambda: new_xd[m],
            bordered_sign: None,
        };
        if prev_dl * new_xd[m] < 0.0 && points.len() >= 2 {
            let k = points.len() - 1;
            let (x, nearest) = turn(&points[k - 1], &points[k], &point);
            folds.push(Fold {
                index: k - 1 + nearest,
                lambda: x[m],
                bracket: k - 1,
            });
        }
        xp.copy_from_slice(&x);
        xd = new_xd;
        let lam = point.lambda();
        points.push(point);
        if !on_point(points.last().expect("just pushed")) {
            break Termination::Stopped;
        }
        if landing.is_some() || lam < opts.lambda_min || lam > opts.lambda_max {
            break Termination::LeftInterval;
        }
        if iters * 2 <= opts.target_iter {
            ds = (ds * opts.growth).min(opts.step_cap(&xp));
        } else if iters > opts.target_iter {
            ds = (ds * 0.7).max(opts.ds_min);
        }
    };
    Ok(Path {
        points,
        folds,
        termination,
    })
}

/// The state `{q, λ}` at the turn between three consecutive points `a`, `b`,
/// `c` around a fold: the quadratic through them in chord arclength s,
/// evaluated where its λ(s) is extremal (`b` itself if λ(s) is straight).
/// Off the path by O(Δη³) rather than the O(Δη) of the nearest point: the
/// start for [`crate::locate_fold`].
pub fn turn_estimate(a: &PathPoint, b: &PathPoint, c: &PathPoint) -> Vec<f64> {
    turn(a, b, c).0
}

/// [`turn_estimate`] and which of the three points (0, 1, 2) lies nearest
/// the turn in arclength.
pub(crate) fn turn(a: &PathPoint, b: &PathPoint, c: &PathPoint) -> (Vec<f64>, usize) {
    let dist = |p: &PathPoint, q: &PathPoint| {
        p.x.iter()
            .zip(&q.x)
            .map(|(u, v)| (u - v) * (u - v))
            .sum::<f64>()
            .sqrt()
    };
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn traces_a_circle_through_both_folds() {
        // x² + λ² = 1 from (x, λ) = (−1, 0)…: folds at λ = ±1 (x = 0).
        let res = |x: &[f64], r: &mut [f64]| r[0] = x[0] * x[0] + x[1] * x[1] - 1.0;
        let opts = ContinuationOptions {
            ds: 0.05,
            max_points: 200,
            lambda_min: -2.0,
            lambda_max: 2.0,
            ..Default::default()
        };
        let mut n = 0;
        let path = pseudo_arclength(res, &[-0.6, 0.8], None, 1.0, &opts, |p| {
            n += 1;
            assert!((p.x[0] * p.x[0] + p.x[1] * p.x[1] - 1.0).abs() < 1e-9);
            n < 150
        })
        .unwrap();
        assert!(path.folds.len() >= 2, "{:?}", path.folds);
        assert!(
            (path.folds[0].lambda - 1.0).abs() < 1e-3,
            "{:?}",
            path.folds
        );
        assert!(
            (path.folds[1].lambda + 1.0).abs() < 1e-3,
            "{:?}",
            path.folds
        );
    }

    /// A first step (0.3) far longer than the interval λ ∈ [0.8, 0.85] on
    /// the circle x² + λ² = 1: the path ends on λ = 0.85 exactly, on the
    /// circle (x = −√(1 − 0.85²)), and no point lies outside the interval.
    /// Before, the first point was kept at λ ≈ 0.8 + 0.3·0.6.
    #[test]
    fn a_long_step_lands_on_the_bound_and_never_leaves_the_interval() {
        let res = |x: &[f64], r: &mut [f64]| r[0] = x[0] * x[0] + x[1] * x[1] - 1.0;
        let opts = ContinuationOptions {
            ds: 0.3,
            lambda_min: 0.8,
            lambda_max: 0.85,
            ..Default::default()
        };
        let path = pseudo_arclength(res, &[-0.6, 0.8], None, 1.0, &opts, |_| true).unwrap();
        assert_eq!(path.termination, Termination::LeftInterval);
        for p in &path.points {
            assert!((0.8..=0.85).contains(&p.lambda()), "{:?}", path.points);
        }
        let last = path.points.last().unwrap();
        assert!((last.lambda() - 0.85).abs() <= 1e-15, "{last:?}");
        let x_exact = -(1.0f64 - 0.85 * 0.85).sqrt();
        assert!((last.x[0] - x_exact).abs() < 1e-9, "{last:?}");
    }
}
