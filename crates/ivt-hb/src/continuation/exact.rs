//! Pseudo-arclength continuation with an exact Jacobian (§3.2.3, Eq. 68–77 with
//! Newton in place of Broyden), for systems that can assemble `∂R/∂u` cheaply
//! (the STHB string, Eq. 115–125), where the secant model of
//! [`super::pseudo_arclength`] degrades and forces small steps.
//!
//! Each point's tangent solves `[J R_λ; t_prevᵀ] t = e_{m+1}` (oriented along the
//! previous one); the predictor is `u + s t`; the corrector solves
//! `[R(u); tᵀ(u − u_pred)] = 0`, first as a chord iteration on the tangent's LU
//! (no new factorization), falling back to full Newton. With
//! [`ContinuationOptions::second_order_predictor`] the predictor adds the
//! curvature of the last two tangents, the chord's matrix is assembled and
//! factored at the prediction, and that LU (bordered by the tangent) gives the
//! next point's tangent. A step about to leave
//! `[lambda_min, lambda_max]` (predicted or corrected past a bound) is
//! corrected on `λ = bound` instead, so the path ends exactly on the bound
//! and no point lies outside. A sign change of the tangent's λ component marks
//! a fold.

use super::corrector::{ExactNewton, Prediction};
use faer::Mat;
use ivt_num::vector::{dot, norm2};
use ivt_num::{newton, BorderedLu, NewtonOptions, NewtonWorkspace};

use super::{non_finite_start, turn, ContinuationOptions, Fold, Path, PathPoint};
use super::{SolveError, Termination};
use crate::error::HbError;

/// `R(u, λ) = 0`, `R: R^m × R → R^m`, with its exact Jacobian.
pub trait PathSystem {
    /// Number of unknowns `m` (without λ).
    fn dim(&self) -> usize;
    /// `R(u, λ)` into `r`.
    fn residual(&mut self, u: &[f64], lambda: f64, r: &mut [f64]);
    /// `R(u, λ)` into `r` and `∂R/∂u` into `jac` (`m × m`, overwritten).
    fn residual_jacobian(&mut self, u: &[f64], lambda: f64, r: &mut [f64], jac: &mut Mat<f64>);
    /// `∂R/∂u` alone into `jac`: all the tangent needs. The default calls
    /// [`Self::residual_jacobian`] into scratch; a system whose Jacobian does
    /// not need `R` (the Galerkin Jacobian needs only `∂g`) saves a residual
    /// evaluation per path point by overriding it.
    fn jacobian(&mut self, u: &[f64], lambda: f64, jac: &mut Mat<f64>) {
        let mut r = vec![0.0; self.dim()];
        self.residual_jacobian(u, lambda, &mut r, jac);
    }
    /// `∂R/∂λ` at `(u, λ)` into `r_lambda`.
    fn d_residual_d_lambda(&mut self, u: &[f64], lambda: f64, r_lambda: &mut [f64]);
}

/// Corrector iterations counted as this many chord iterations per full Newton
/// step (a Newton step assembles and factors the Jacobian).
const NEWTON_WEIGHT: usize = 2;

/// Traces the path of `system` from the converged point `start` (`u` then λ)
/// in the direction of increasing λ if `direction > 0`.
///
/// Uses `opts.broyden.tol` as the absolute tolerance on `‖[R; constraint]‖₂`
/// and `opts.broyden.max_iter` as the Newton iteration limit (the chord
/// iteration may take three times as many while it contracts by ½ or better).
/// Step control: a point whose corrector took at most `target_iter / 2`
/// chord iterations (a Newton iteration counts as two) grows the step by
/// `growth`, `target_iter` or more shrinks it by 0.7, a failed corrector
/// halves it. `PathPoint::dlambda` is the λ component of the unit tangent.
///
/// `on_point` is called once the point's tangent is computed, so the last
/// Jacobian `system` assembled is the one the tangent used: the point's own,
/// or, with [`ContinuationOptions::second_order_predictor`] after a chord
/// correction, the predictor's. It returns `false` to stop.
///
/// # Errors
/// [`HbError::InvalidInput`] for bad sizes or non-finite inputs,
/// [`HbError::SingularStart`] when the start has no tangent.
pub fn pseudo_arclength_exact<S, C>(
    system: &mut S,
    start: &[f64],
    start_iterations: usize,
    direction: f64,
    opts: &ContinuationOptions,
    mut on_point: C,
) -> Result<Path, HbError>
where
    S: PathSystem,
    C: FnMut(&mut S, &PathPoint) -> bool,
{
    let m = system.dim();
    if start.len() != m + 1 {
        return Err(HbError::InvalidInput(
            "continuation: start must hold m unknowns and λ".into(),
        ));
    }
    if !(start.iter().all(|v| v.is_finite()) && opts.ds > 0.0 && opts.ds_min > 0.0) {
        return Err(non_finite_start());
    }
    let mut corrector = Corrector::new(m, opts);
    let mut x = start.to_vec();
    let mut tangent = vec![0.0; m + 1];
    tangent[m] = if direction >= 0.0 { 1.0 } else { -1.0 };
    let mut points: Vec<PathPoint> = Vec::new();
    let mut folds = Vec::new();
    let mut step = opts.ds;
    let mut iterations = start_iterations;
    let mut landed = false;
    let mut u_pred = vec![0.0; m + 1];
    // `aug` holds the predictor's LU of the chord that reached `x`, bordered
    // by the tangent: the next tangent comes from it.
    let mut factored_near_x = false;
    // The previous point's tangent, and the curvature vector of the second-order predictor.
    let mut prev_tangent = vec![0.0; m + 1];
    let mut curvature = vec![0.0; m + 1];
    let termination = loop {
        prev_tangent.copy_from_slice(&tangent);
        let tangent_found = if factored_near_x {
            corrector.solve_tangent(&mut tangent)
        } else {
            corrector.tangent(system, &x, &mut tangent)
        };
        if !tangent_found {
            if points.is_empty() {
                return Err(HbError::SingularStart { lambda: start[m] });
            }
            break Termination::StepTooSmall(SolveError::SingularJacobian {
                iteration: 0,
                history: Vec::new(),
            });
        }
        let point = PathPoint {
            x: x.clone(),
            iterations,
            dlambda: tangent[m],
            bordered_sign: Some(corrector.aug.det_sign()),
        };
        let k = points.len();
        if k >= 2 && points[k - 1].dlambda * point.dlambda < 0.0 {
            let (turned, nearest) = turn(&points[k - 2], &points[k - 1], &point);
            folds.push(Fold {
                index: k - 2 + nearest,
                lambda: turned[m],
                bracket: k - 2,
            });
        }
        points.push(point);
        if !on_point(system, &points[k]) {
            break Termination::Stopped;
        }
        if landed || x[m] < opts.lambda_min || x[m] > opts.lambda_max {
            break Termination::LeftInterval;
        }
        if points.len() >= opts.max_points {
            break Termination::MaxPoints;
        }
        // Predictor–corrector with step halving.
        let mut chord_ok = true;
        // The curvature term is dropped where it would move the prediction by
        // more than a quarter of the step (a turn sharper than the step).
        let curved = opts.second_order_predictor
            && k >= 1
            && curvature_between(
                &points[k - 1].x,
                &x,
                &prev_tangent,
                &tangent,
                &mut curvature,
            );
        let kappa = norm2(&curvature);
        let outside = |l: f64| l < opts.lambda_min || l > opts.lambda_max;
        let mut force_landing = false;
        let err = loop {
            for (p, (xi, ti)) in u_pred.iter_mut().zip(x.iter().zip(&tangent)) {
                *p = xi + step * ti;
            }
            if curved && 0.5 * step * kappa <= 0.25 {
                for (p, c) in u_pred.iter_mut().zip(&curvature) {
                    *p += 0.5 * step * step * c;
                }
            }
            let clip = if tangent[m] > 0.0 && (force_landing || u_pred[m] > opts.lambda_max) {
                Some(opts.lambda_max)
            } else if tangent[m] < 0.0 && (force_landing || u_pred[m] < opts.lambda_min) {
                Some(opts.lambda_min)
            } else {
                None
            };
            let pred = Prediction {
                u_pred: &u_pred,
                tangent: &tangent,
                fix: clip,
            };
            corrector.start(&pred);
            // A fresh LU at the predictor (its residual is the chord's first).
            let fresh = chord_ok && opts.second_order_predictor;
            if fresh && !corrector.factor_at_start(system, &pred) {
                chord_ok = false;
            }
            let chord = if chord_ok {
                corrector.chord(system, &pred, fresh)
            } else {
                Err(SolveError::NonConvergence {
                    iterations: 0,
                    history: Vec::new(),
                })
            };
            let attempt = match chord {
                Ok(its) => Ok(its),
                Err(_) => {
                    // From the chord's best iterate (the predictor at worst).
                    chord_ok = false;
                    corrector
                        .newton(system, &pred)
                        .map(|its| its * NEWTON_WEIGHT)
                }
            };
            match attempt {
                Ok(_) if clip.is_none() && !force_landing && outside(corrector.u[m]) => {
                    // Corrected past a bound: redo the step onto it.
                    force_landing = true;
                }
                Ok(weighted) => {
                    landed = clip.is_some();
                    // Not after landing: bordered by e_{m+1}, the LU's
                    // determinant is det J, not the branch-point test's.
                    factored_near_x = fresh && chord_ok && !landed;
                    x.copy_from_slice(&corrector.u);
                    iterations = if chord_ok {
                        weighted
                    } else {
                        weighted / NEWTON_WEIGHT
                    };
                    if weighted * 2 <= opts.target_iter {
                        step = (step * opts.growth).min(opts.step_cap(&x));
                    } else if weighted >= opts.target_iter {
                        step *= 0.7;
                    }
                    break None;
                }
                Err(e) => {
                    step *= 0.5;
                    if step < opts.ds_min {
                        break Some(e);
                    }
                }
            }
        };
        if let Some(e) = err {
            break Termination::StepTooSmall(e);
        }
    };
    Ok(Path {
        points,
        folds,
        termination,
    })
}

/// The curvature vector `(t₁ − t₀)/‖x₁ − x₀‖` of the path between two
/// consecutive points and their unit tangents into `out`; `false` for
/// coincident points.
fn curvature_between(x0: &[f64], x1: &[f64], t0: &[f64], t1: &[f64], out: &mut [f64]) -> bool {
    let ds = x0
        .iter()
        .zip(x1)
        .map(|(a, b)| (b - a) * (b - a))
        .sum::<f64>()
        .sqrt();
    if !(ds > 0.0 && ds.is_finite()) {
        return false;
    }
    for ((o, a), b) in out.iter_mut().zip(t0).zip(t1) {
        *o = (b - a) / ds;
    }
    true
}

/// Buffers of the tangent and the correctors; `aug` holds the LU of the last
/// bordered matrix `[J R_λ; rowᵀ]`.
struct Corrector {
    aug: BorderedLu,
    jac: Mat<f64>,
    r: Vec<f64>,
    r_lambda: Vec<f64>,
    rhs: Vec<f64>,
    /// The corrected point.
    u: Vec<f64>,
    /// `jac` was assembled at `u` as Newton converged there: the tangent at
    /// that point reuses it instead of assembling it again.
    jac_at_u: bool,
    /// Buffers of the Newton corrector.
    newton: NewtonWorkspace,
    tol: f64,
    max_newton: usize,
}

impl Corrector {
    fn new(m: usize, opts: &ContinuationOptions) -> Self {
        Self {
            aug: BorderedLu::new(m, 1),
            jac: Mat::zeros(m, m),
            r: vec![0.0; m],
            r_lambda: vec![0.0; m],
            rhs: vec![0.0; m + 1],
            u: vec![0.0; m + 1],
            jac_at_u: false,
            newton: NewtonWorkspace::new(m + 1),
            tol: opts.broyden.tol,
            max_newton: opts.broyden.max_iter,
        }
    }

    /// `R` and `J` at `x` into `r`, `jac`.
    fn assemble<S: PathSystem>(&mut self, system: &mut S, x: &[f64]) {
        let m = self.jac.nrows();
        system.residual_jacobian(&x[..m], x[m], &mut self.r, &mut self.jac);
        self.jac_at_u = false;
    }

    /// Factors `[J R_λ; rowᵀ]` with the `J` of the last [`Self::assemble`] at `x`;
    /// `false` if singular.
    fn factor<S: PathSystem>(&mut self, system: &mut S, x: &[f64], row: &[f64]) -> bool {
        let m = self.jac.nrows();
        system.d_residual_d_lambda(&x[..m], x[m], &mut self.r_lambda);
        let (row, corner) = row.split_at(m);
        self.aug
            .factor_mat(self.jac.as_ref(), &self.r_lambda, row, corner)
            .is_ok()
    }

    /// The unit tangent at `x`, oriented along the previous `tangent` (which
    /// also borders the matrix); leaves its LU in `aug` for the chord corrector.
    fn tangent<S: PathSystem>(&mut self, system: &mut S, x: &[f64], tangent: &mut [f64]) -> bool {
        let m = self.jac.nrows();
        // After Newton converged, `jac` is already the Jacobian at `x`.
        let reuse = self.jac_at_u && self.u == x;
        if !reuse {
            system.jacobian(&x[..m], x[m], &mut self.jac);
        }
        self.jac_at_u = false;
        self.factor(system, x, tangent) && self.solve_tangent(tangent)
    }

    /// `[R(u); ·]` and the LU of `[J R_λ; rowᵀ]` at the corrector's start
    /// (the predictor), `row` the constraint's gradient: the chord's matrix
    /// of [`ContinuationOptions::second_order_predictor`]. `false` if singular.
    fn factor_at_start<S: PathSystem>(&mut self, system: &mut S, pred: &Prediction) -> bool {
        let u = std::mem::take(&mut self.u);
        self.assemble(system, &u);
        let factored = self.factor(system, &u, &pred.row());
        self.u = u;
        factored
    }

    /// The unit solution of `aug · z = e_{m+1}` (the tangent of the factored
    /// bordered matrix), oriented along the previous `tangent`, into it.
    fn solve_tangent(&mut self, tangent: &mut [f64]) -> bool {
        let m = self.jac.nrows();
        let z = &mut self.rhs;
        z.fill(0.0);
        z[m] = 1.0;
        let solved = self.aug.solve(z).is_ok();
        let norm = norm2(z);
        let along: f64 = z.iter().zip(tangent.iter()).map(|(a, b)| a * b).sum();
        let sign = if along < 0.0 { -1.0 } else { 1.0 };
        for (t, v) in tangent.iter_mut().zip(z.iter()) {
            *t = sign * v / norm;
        }
        solved && norm.is_finite()
    }

    /// The start of a corrector: `u_pred`, on `λ = fix` if given.
    fn start(&mut self, pred: &Prediction<'_>) {
        self.u.copy_from_slice(pred.u_pred);
        if let Some(l) = pred.fix {
            let m = self.u.len() - 1;
            self.u[m] = l;
        }
    }

    /// Chord iteration from [`Self::start`] on the tangent's factorization `A₀`,
    /// accelerated by Broyden's updates of it (Kelley's `brsol`: the update of
    /// `A₀⁻¹` applied through the stored steps by Sherman–Morrison, no new
    /// factorization): superlinear where the plain chord contracts linearly.
    /// Fails fast when the residual does not fall by ½ per iteration (over
    /// two) or grows, leaving `u` at the best iterate for Newton to start
    /// from. Returns the iteration count.
    fn chord<S: PathSystem>(
        &mut self,
        sys: &mut S,
        pred: &Prediction,
        start_residual_known: bool,
    ) -> Result<usize, SolveError> {
        let (m, mut history) = (self.jac.nrows(), Vec::new());
        let mut steps: Vec<Vec<f64>> = Vec::new();
        let mut best = (f64::INFINITY, self.u.clone());
        for it in 0..=3 * self.max_newton {
            if it == 0 && start_residual_known {
                self.rhs[..m].copy_from_slice(&self.r);
            } else {
                sys.residual(&self.u[..m], self.u[m], &mut self.rhs[..m]);
            }
            self.rhs[m] = pred.constraint(&self.u);
            if let Some(done) = settle(&mut history, norm2(&self.rhs), self.tol) {
                return done;
            }
            if history[it] < best.0 {
                best.0 = history[it];
                best.1.copy_from_slice(&self.u);
            }
            let grew = it >= 1 && history[it] >= history[it - 1];
            if grew || (it >= 2 && history[it] > 0.25 * history[it - 2]) {
                break;
            }
            // z = −A₀⁻¹F, then the updates s_{j+1} s_jᵀ z / ‖s_j‖² in order.
            let mut z = self.rhs.clone();
            if self.aug.solve(&mut z).is_err() {
                break;
            }
            z.iter_mut().for_each(|v| *v = -*v);
            for pair in steps.windows(2) {
                let c = dot(&pair[0], &z) / dot(&pair[0], &pair[0]);
                z.iter_mut().zip(&pair[1]).for_each(|(v, s)| *v += c * s);
            }
            if let Some(last) = steps.last() {
                let denom = 1.0 - dot(last, &z) / dot(last, last);
                z.iter_mut().for_each(|v| *v /= denom);
            }
            for (x, d) in self.u.iter_mut().zip(&z) {
                *x += d;
            }
            steps.push(z);
        }
        self.u.copy_from_slice(&best.1);
        Err(SolveError::NonConvergence {
            iterations: history.len() - 1,
            history,
        })
    }

    /// Newton ([`ivt_num::newton()`], full steps) on `[R(u); constraint] = 0`
    /// from [`Self::start`]; diverged once ‖F‖ grows after the second step.
    /// Leaves `jac` at the solution for the tangent. Returns the iteration
    /// count.
    fn newton<S: PathSystem>(
        &mut self,
        sys: &mut S,
        pred: &Prediction,
    ) -> Result<usize, SolveError> {
        let m = self.jac.nrows();
        let nopts = NewtonOptions {
            ftol: self.tol,
            max_iter: self.max_newton,
            max_halvings: 0,
            accept_no_descent: true,
            ..NewtonOptions::default()
        };
        let mut corrected = ExactNewton {
            system: sys,
            jac: &mut self.jac,
            r_lambda: &mut self.r_lambda,
            pred,
        };
        let result = newton(&mut corrected, &mut self.u, &mut self.newton, &nopts);
        // The last residual evaluation assembled `jac` at `u`.
        self.jac_at_u = result.is_ok();
        if let Some(r) = self.newton.residual().get(..m) {
            self.r.copy_from_slice(r);
        }
        result
            .map(|stats| stats.iterations)
            .map_err(SolveError::from)
    }
}

/// Records a corrector's residual norm; `Some` once it is done: converged
/// (the iteration count) or non-finite (the error with the history).
fn settle(history: &mut Vec<f64>, norm: f64, tol: f64) -> Option<Result<usize, SolveError>> {
    let iteration = history.len();
    history.push(norm);
    if !norm.is_finite() {
        let history = std::mem::take(history);
        return Some(Err(SolveError::NonFinite { iteration, history }));
    }
    (norm <= tol).then_some(Ok(iteration))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn traces_a_circle_over_its_fold_onto_the_bound() {
        let opts = ContinuationOptions {
            ds: 0.05,
            ds_max: 0.1,
            max_points: 400,
            lambda_min: -0.99,
            lambda_max: 2.0,
            ..Default::default()
        };
        // From (u, λ) = (−0.6, 0.8) upwards: over the fold at λ = 1 and back down
        // to the bound λ = −0.99, where the path must end exactly.
        let path = pseudo_arclength_exact(&mut Circle, &[-0.6, 0.8], 0, 1.0, &opts, |_, p| {
            assert!((p.x[0] * p.x[0] + p.x[1] * p.x[1] - 1.0).abs() <= 1e-10);
            true
        })
        .unwrap();
        assert_eq!(path.termination, Termination::LeftInterval);
        assert_eq!(path.points.last().unwrap().lambda(), -0.99);
        assert_eq!(path.folds.len(), 1, "{:?}", path.folds);
        // The parabola through three points 0.1 apart on the unit circle.
        assert!(
            (path.folds[0].lambda - 1.0).abs() < 1e-3,
            "{:?}",
            path.folds
        );
    }

    /// `u² + λ² = 1`: a circle with folds at λ = ±1.
    struct Circle;

    impl PathSystem for Circle {
        fn dim(&self) -> usize {
            1
        }
        fn residual(&mut self, u: &[f64], lambda: f64, r: &mut [f64]) {
            r[0] = u[0] * u[0] + lambda * lambda - 1.0;
        }
        fn residual_jacobian(&mut self, u: &[f64], lambda: f64, r: &mut [f64], jac: &mut Mat<f64>) {
            self.residual(u, lambda, r);
            jac[(0, 0)] = 2.0 * u[0];
        }
        fn d_residual_d_lambda(&mut self, _u: &[f64], lambda: f64, r_lambda: &mut [f64]) {
            r_lambda[0] = 2.0 * lambda;
        }
    }

    /// The long-step case of the Broyden driver's test on the exact path:
    /// a step of 0.3 on x² + λ² = 1 over λ ∈ [0.8, 0.85] lands on λ = 0.85
    /// exactly (x = −√(1 − 0.85²)); no point lies outside the interval.
    #[test]
    fn a_long_step_lands_on_the_bound_and_never_leaves_the_interval() {
        let opts = ContinuationOptions {
            ds: 0.3,
            lambda_min: 0.8,
            lambda_max: 0.85,
            ..Default::default()
        };
        let path =
            pseudo_arclength_exact(&mut Circle, &[-0.6, 0.8], 0, 1.0, &opts, |_, _| true).unwrap();
        assert_eq!(path.termination, Termination::LeftInterval);
        for p in &path.points {
            assert!((0.8..=0.85).contains(&p.lambda()), "{:?}", path.points);
        }
        let last = path.points.last().unwrap();
        assert_eq!(last.lambda(), 0.85);
        assert!(
            (last.x[0] + (1.0f64 - 0.85 * 0.85).sqrt()).abs() < 1e-9,
            "{last:?}"
        );
    }
}
