//! Autonomous periodic orbits (limit cycles of unforced systems): the response
//! frequency ω is an unknown beside the Fourier coefficients, and the time origin,
//! free for an autonomous system, is fixed by the phase condition `b₁ = 0` on DOF 0
//! (its first harmonic is a pure cosine). Newton's method on
//!
//! `[R(q, ω); b₁(q)] = 0`,  Jacobian `[[Φ_q, ∂R/∂ω], [e_{b₁}ᵀ, 0]]`,
//!
//! with `R` the HB residual Eq. 61 (p = 1; the problem's excitation must be zero),
//! `Φ_q` the exact Galerkin Jacobian Eq. 56 and `∂R/∂ω` by a central difference
//! relative to ω. Stability: Hsu's monodromy (Eq. 80) has the trivial multiplier
//! +1 (the phase shift); the orbit is classified by the others.
//!
//! [`limit_cycle_branch`] follows a limit cycle in a parameter μ of a family of
//! problems by the engine's pseudo-arclength continuation ([`ivt_path::continuation::Stepper`],
//! Eq. 68–77) on `[R(q, ω; μ); b₁] = 0` with unknowns `{q, ω, μ}`.

use crate::orbit::galerkin::GalerkinJacobian;
use crate::orbit::ihb::{HbError, HbOptions, HbResidual, HbSolution};
use crate::problem::PeriodicProblem;
use crate::stability::floquet::HsuRule;
use crate::stability::{classify, StabilityAnalyzer, StabilityKind};
use faer::c64;
use ivt_num::BroydenStats;
use ivt_num::{newton_bordered, Border, NewtonOptions, NewtonSystem, NewtonWorkspace, StepCheck};
use ivt_path::continuation::{follow_residual, ContinuationOptions, PathPoint, Traced, Turn};

/// A converged limit cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitCycle {
    /// The orbit (`omega_f` is the response frequency ω, `subharmonic` 1).
    pub solution: HbSolution,
    /// Floquet multipliers (Hsu), decreasing modulus, the trivial +1 included.
    pub multipliers: Vec<c64>,
    /// Classification by the multipliers other than the trivial one.
    pub kind: StabilityKind,
}

impl LimitCycle {
    /// Response frequency ω.
    pub fn omega(&self) -> f64 {
        self.solution.omega_f
    }
    /// Period 2π/ω.
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.solution.omega_f
    }
    /// All non-trivial multipliers inside the unit circle.
    pub fn stable(&self) -> bool {
        self.kind == StabilityKind::Stable
    }
}

/// A limit-cycle branch traced in a parameter: `(μ, cycle)` in path order;
/// its events are the stepper's turning points in μ ([`Turn`]: estimated
/// from the three points around each, not located; [`crate::cycle_branch()`]
/// locates them).
pub type LimitCycleBranch = Traced<(f64, LimitCycle), Turn>;

/// Follows the limit cycle `start` of `family(mu_from)` in μ up to `mu_to`
/// (pseudo-arclength, `opts`; its λ bounds are set from `mu_from`/`mu_to`),
/// with the multipliers of every point (`stability_steps` Hsu sub-intervals).
/// `family(μ)` must build an autonomous problem of the same size for every μ.
///
/// # Errors
/// [`HbError::InvalidInput`] for sizes or bounds, [`PathError::ContinuationStart`](ivt_path::PathError::ContinuationStart)
/// when the start does not converge; trouble later on ends the branch with a
/// [`ivt_path::continuation::Termination`].
pub fn limit_cycle_branch<P, F>(
    family: F,
    hb: &HbOptions,
    start: &LimitCycle,
    mu_from: f64,
    mu_to: f64,
    opts: &ContinuationOptions,
    stability_steps: usize,
) -> Result<LimitCycleBranch, HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> P,
{
    let span = (mu_from, mu_to);
    limit_cycle_leg(family, hb, start, span, opts, stability_steps, |_| true)
}

/// [`limit_cycle_branch`] handing each path point `{q, ω, μ}` to
/// `on_point` as it arrives (`false` stops the path): the hook of an
/// observer ([`crate::branches::cycle_branch`]'s fold events).
pub(crate) fn limit_cycle_leg<P, F>(
    family: F,
    hb: &HbOptions,
    start: &LimitCycle,
    (mu_from, mu_to): (f64, f64),
    opts: &ContinuationOptions,
    stability_steps: usize,
    on_point: impl FnMut(&PathPoint) -> bool,
) -> Result<LimitCycleBranch, HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> P,
{
    if !(mu_from.is_finite() && mu_to.is_finite() && mu_from != mu_to) {
        return Err(HbError::InvalidInput(
            "parameter bounds must be finite and distinct".into(),
        ));
    }
    let mut res = HbResidual::new(&family(mu_from), hb)?;
    let m = res.len();
    if start.solution.coeffs.len() != m {
        return Err(HbError::InvalidInput(format!(
            "start cycle must have {m} coefficients"
        )));
    }
    let phase = hb.harmonics + 1;
    let mut x0 = start.solution.coeffs.clone();
    x0.extend([start.omega(), mu_from]);
    let mut copts = opts.clone();
    copts.lambda_min = mu_from.min(mu_to);
    copts.lambda_max = mu_from.max(mu_to);
    // x = {q, ω, μ}: the HB residual at μ and the phase condition b₁ = 0.
    let residual =
        |x: &[f64], r: &mut [f64]| match (x.split_at_checked(m), r.split_at_mut_checked(m)) {
            (Some((q, &[omega, mu])), Some((r_q, [r_phase]))) => {
                res.eval(&family(mu), q, omega, 1.0, r_q);
                *r_phase = x.get(phase).copied().unwrap_or(f64::NAN);
            }
            _ => r.fill(f64::NAN),
        };
    let path = follow_residual(residual, &x0, None, mu_to - mu_from, &copts, on_point)?;
    let mut points = Vec::with_capacity(path.points.len());
    for p in &path.points {
        let mu = p.lambda();
        let problem = family(mu);
        let (coeffs, omega_f) = match p.x.split_at_checked(m) {
            Some((q, [omega, _])) => (q.to_vec(), *omega),
            _ => {
                return Err(HbError::InvalidInput(
                    "limit cycle: point of the wrong size".into(),
                ))
            }
        };
        let solution = HbSolution {
            coeffs,
            omega_f,
            harmonics: hb.harmonics,
            subharmonic: 1,
            stats: BroydenStats {
                iterations: p.iterations,
                residual_evals: 0,
                jacobian_refreshes: 0,
                residual_norm: 0.0,
            },
        };
        points.push((mu, classify_cycle(&problem, solution, stability_steps)?));
    }
    Ok(LimitCycleBranch {
        points,
        events: path.events,
        termination: path.termination,
    })
}

/// Multipliers of an autonomous orbit and its class by the non-trivial ones
/// (Hsu with `stability_steps` sub-intervals, Eq. 78).
///
/// # Errors
/// Those of [`StabilityAnalyzer::new`] (`stability_steps` ≤ the orbit's
/// harmonics, a problem without DOFs).
pub fn classify_cycle(
    problem: &dyn PeriodicProblem,
    solution: HbSolution,
    stability_steps: usize,
) -> Result<LimitCycle, HbError> {
    let problem = &problem;
    let mut analyzer = StabilityAnalyzer::new(problem, solution.harmonics, stability_steps)?;
    let multipliers = analyzer
        .hsu(problem, &solution, HsuRule::Magnus4)
        .multipliers;
    let trivial = multipliers
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1 - 1.0).norm().total_cmp(&(b.1 - 1.0).norm()))
        .map(|(i, _)| i);
    let others: Vec<c64> = multipliers
        .iter()
        .enumerate()
        .filter(|(i, _)| Some(*i) != trivial)
        .map(|(_, m)| *m)
        .collect();
    Ok(LimitCycle {
        solution,
        kind: classify(&others),
        multipliers,
    })
}

/// Refuses a forced `problem` for an autonomous analysis (`what`): an
/// excitation `f(θ)` that is not zero, or a `g` whose value depends on θ
/// (both sampled at four θ; the state for `g` is a fixed non-zero one). Its
/// forcing would be ignored: the cycle's θ is its own phase, not a forcing.
/// A hysteretic `g` (history-dependent, no pointwise value) is checked by
/// its excitation only.
///
/// # Errors
/// [`HbError::InvalidInput`] naming the forcing.
pub fn require_autonomous<P: PeriodicProblem>(problem: &P, what: &str) -> Result<(), HbError> {
    let n = problem.n_dof();
    let thetas = [0.0, 1.0, 2.5, 4.0];
    let mut out = vec![0.0; n];
    for &theta in &thetas {
        problem.excitation(theta, &mut out);
        if out.iter().any(|f| *f != 0.0) {
            return Err(HbError::InvalidInput(format!(
                "{what} needs an autonomous system, but the excitation f(θ) is not zero (at θ = \
                 {theta}): a forced system has no limit cycles of its own; use frc or solve"
            )));
        }
    }
    if problem.hysteretic() {
        return Ok(());
    }
    let x: Vec<f64> = (0..n).map(|i| 0.37 + 0.11 * i as f64).collect();
    let v: Vec<f64> = (0..n).map(|i| -0.23 + 0.07 * i as f64).collect();
    let mut first = vec![0.0; n];
    problem.nonlinear(&x, &v, 0.0, &mut first);
    for &theta in &thetas[1..] {
        problem.nonlinear(&x, &v, theta, &mut out);
        let moved = out.iter().zip(&first).any(|(a, b)| {
            let scale = a.abs().max(b.abs()).max(f64::MIN_POSITIVE);
            (a - b).abs() > 1e-12 * scale
        });
        if moved {
            return Err(HbError::InvalidInput(format!(
                "{what} needs an autonomous system, but g(x, v, θ) depends on θ (a parametric \
                 or forced term): its forcing would be ignored; use frc or solve"
            )));
        }
    }
    Ok(())
}

/// Finds the limit cycle of the autonomous `problem` near the orbit `guess`
/// (coefficients, `n_dof·(2n+1)`, not all zero) at frequency `omega_guess`.
/// Convergence: ‖[R; b₁]‖₂ ≤ `atol + rtol·S` ([`HbOptions`], S = ‖L(ω)q₀‖₂ of the
/// guess) and a last Newton step below 1e-10
/// relative to ‖q‖∞ and ω. `stability_steps` Hsu sub-intervals (> n).
///
/// # Errors
/// [`HbError::InvalidInput`] for a bad guess, frequency or size;
/// [`HbError::Solve`] when Newton does not converge within
/// `hb.broyden.max_iter` steps (with the ‖F‖ history) or the matrix is
/// singular; [`HbError::Equilibrium`] if the iteration collapses onto `x = 0`.
pub fn limit_cycle(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    omega_guess: f64,
    guess: &[f64],
    stability_steps: usize,
) -> Result<LimitCycle, HbError> {
    let solution = limit_cycle_orbit(problem, hb, omega_guess, guess)?;
    classify_cycle(problem, solution, stability_steps)
}

/// The orbit of [`limit_cycle`] without its multipliers (a refinement
/// whose stability is not reported).
///
/// # Errors
/// Those of [`limit_cycle`].
pub fn limit_cycle_orbit(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    omega_guess: f64,
    guess: &[f64],
) -> Result<HbSolution, HbError> {
    let problem = &problem;
    if hb.subharmonic != 1 {
        return Err(HbError::InvalidInput(
            "a limit cycle has no excitation: subharmonic order must be 1".into(),
        ));
    }
    crate::orbit::ihb::validate_omega(omega_guess)?;
    require_autonomous(problem, "a limit cycle")?;
    let res = HbResidual::new(problem, hb)?;
    let m = res.len();
    let n = hb.harmonics;
    let q_guess = guess.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if guess.len() != m || !guess.iter().all(|v| v.is_finite()) || q_guess == 0.0 {
        return Err(HbError::InvalidInput(format!(
            "guess must have {m} finite entries, not all zero"
        )));
    }
    let mut r = vec![0.0; m];
    let tol = hb.residual_tol(res.force_scale(problem, guess, omega_guess, &mut r));
    let phase = n + 1; // b₁ of DOF 0
    let mut system = Cycle {
        galerkin: GalerkinJacobian::new(&res),
        res,
        problem,
        m,
        jac: vec![0.0; m * m],
        r_omega: (vec![0.0; m], vec![0.0; m]),
        tol,
        q_guess,
    };
    let mut x = guess.to_vec();
    x.push(omega_guess);
    // The phase condition b₁ = 0 (DOF 0) as the border row.
    let mut phase_row = vec![0.0; m + 1];
    if let Some(b1) = phase_row.get_mut(phase) {
        *b1 = 1.0;
    }
    let border = Border {
        rows: &phase_row,
        values: &[0.0],
        origin: &[],
    };
    let nopts = NewtonOptions {
        ftol: 0.0,
        max_iter: hb.broyden.max_iter,
        max_halvings: hb.broyden.max_backtracks,
        accept_below: tol,
        ..NewtonOptions::default()
    };
    let mut ws = NewtonWorkspace::bordered(m + 1, 1);
    let stats = newton_bordered(&mut system, border, &mut x, &mut ws, &nopts)
        .map_err(|e| e.infallible().map_or_else(|e| e, HbError::Solve))?;
    let omega = x.pop().unwrap_or(omega_guess);
    let q = x;
    let stats = BroydenStats {
        iterations: stats.iterations,
        residual_evals: stats.residual_evals + 2 * stats.jacobian_evals,
        jacobian_refreshes: stats.jacobian_evals,
        residual_norm: stats.residual_norm,
    };
    Ok(HbSolution {
        coeffs: q,
        omega_f: omega,
        harmonics: n,
        subharmonic: 1,
        stats,
    })
}

/// `R(q, ω) = 0` of an autonomous problem in `x = (q, ω)` for
/// [`ivt_num::newton_bordered`] (the phase condition is the border row):
/// Jacobian `[Φ_q, ∂R/∂ω]` with `∂R/∂ω` by a central difference relative to
/// ω. A trial with ω ≤ 0 is outside the domain (NaN residual).
struct Cycle<'a, P> {
    res: HbResidual,
    galerkin: GalerkinJacobian,
    problem: &'a P,
    /// Unknowns of `q`.
    m: usize,
    jac: Vec<f64>,
    r_omega: (Vec<f64>, Vec<f64>),
    /// Residual tolerance `atol + rtol·S`.
    tol: f64,
    /// ‖guess‖∞: an orbit 1e-8 of it has collapsed onto the equilibrium.
    q_guess: f64,
}

impl<P: PeriodicProblem> NewtonSystem for Cycle<'_, P> {
    type Error = HbError;

    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), HbError> {
        match x
            .split_at_checked(self.m)
            .and_then(|(q, w)| Some(q).zip(w.first()))
        {
            Some((q, &w)) if w > 0.0 => self.res.eval(self.problem, q, w, 1.0, r),
            _ => r.fill(f64::NAN),
        }
        Ok(())
    }

    fn jacobian(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), HbError> {
        let m = self.m;
        let Some((q, omega)) = x.split_at_checked(m) else {
            return Err(HbError::InvalidInput(
                "limit cycle: unknowns of the wrong size".into(),
            ));
        };
        let omega = omega.first().copied().unwrap_or(f64::NAN);
        let (rp, rm) = (&mut self.r_omega.0, &mut self.r_omega.1);
        self.galerkin
            .assemble(&mut self.res, self.problem, q, omega, 1.0, &mut self.jac);
        let h = 1e-6 * omega;
        self.res.eval(self.problem, q, omega + h, 1.0, rp);
        self.res.eval(self.problem, q, omega - h, 1.0, rm);
        for (((row, j_row), p), mi) in out
            .chunks_exact_mut(m + 1)
            .zip(self.jac.chunks_exact(m))
            .zip(rp.iter())
            .zip(rm.iter())
        {
            if let Some((left, [last])) = row.split_at_mut_checked(m) {
                left.copy_from_slice(j_row);
                *last = (p - mi) / (2.0 * h);
            }
        }
        Ok(())
    }

    /// Converged when ‖[R; b₁]‖₂ ≤ tol and the last step is below 1e-10
    /// relative to ‖q‖∞ and ω; an orbit collapsed onto `x = 0` is
    /// [`HbError::Equilibrium`].
    fn check_step(
        &mut self,
        x: &[f64],
        step: &[f64],
        history: &[f64],
    ) -> Result<StepCheck, HbError> {
        let (Some((q, omega)), Some((dq, d_omega))) =
            (x.split_at_checked(self.m), step.split_at_checked(self.m))
        else {
            return Ok(StepCheck::Continue);
        };
        let q_scale = q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if q_scale <= 1e-8 * self.q_guess {
            return Err(HbError::Equilibrium);
        }
        let omega_before = omega.first().zip(d_omega.first()).map(|(w, d)| w - d);
        let dq = dq.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let last_step = (dq / q_scale.max(f64::MIN_POSITIVE)).max(
            d_omega
                .first()
                .zip(omega_before)
                .map_or(f64::INFINITY, |(d, w)| (d / w).abs()),
        );
        let norm = history.last().copied().unwrap_or(f64::INFINITY);
        Ok(if norm <= self.tol && last_step <= 1e-10 {
            StepCheck::Converged
        } else {
            StepCheck::Continue
        })
    }
}
