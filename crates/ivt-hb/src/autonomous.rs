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
//! problems by the engine's pseudo-arclength continuation ([`pseudo_arclength`],
//! Eq. 68–77) on `[R(q, ω; μ); b₁] = 0` with unknowns `{q, ω, μ}`.

use crate::broyden::{BroydenStats, SolveError};
use crate::continuation::{pseudo_arclength, ContinuationOptions, Termination};
use crate::floquet::HsuRule;
use crate::galerkin::GalerkinJacobian;
use crate::ihb::{HbError, HbOptions, HbResidual, HbSolution};
use crate::problem::PeriodicProblem;
use crate::stability::{classify, StabilityAnalyzer, StabilityKind};
use faer::c64;
use ivt_num::vector::norm2;
use ivt_num::BorderedLu;

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

/// A limit-cycle branch traced in a parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitCycleBranch {
    /// `(μ, cycle)` in path order.
    pub points: Vec<(f64, LimitCycle)>,
    /// Why tracing stopped.
    pub termination: Termination,
}

/// Follows the limit cycle `start` of `family(mu_from)` in μ up to `mu_to`
/// (pseudo-arclength, `opts`; its λ bounds are set from `mu_from`/`mu_to`),
/// with the multipliers of every point (`stability_steps` Hsu sub-intervals).
/// `family(μ)` must build an autonomous problem of the same size for every μ.
///
/// # Errors
/// [`HbError::InvalidInput`] for sizes or bounds, [`HbError::ContinuationStart`]
/// when the start does not converge; trouble later on ends the branch with a
/// [`Termination`].
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
    let path = pseudo_arclength(
        |x: &[f64], r: &mut [f64]| {
            let problem = family(x[m + 1]);
            res.eval(&problem, &x[..m], x[m], 1.0, &mut r[..m]);
            r[m] = x[phase];
        },
        &x0,
        None,
        mu_to - mu_from,
        &copts,
        |_| true,
    )?;
    let mut points = Vec::with_capacity(path.points.len());
    for p in &path.points {
        let mu = p.lambda();
        let problem = family(mu);
        let solution = HbSolution {
            coeffs: p.x[..m].to_vec(),
            omega_f: p.x[m],
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
        termination: path.termination,
    })
}

/// Multipliers of an autonomous orbit and its class by the non-trivial ones.
fn classify_cycle<P: PeriodicProblem>(
    problem: &P,
    solution: HbSolution,
    stability_steps: usize,
) -> Result<LimitCycle, HbError> {
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
pub fn limit_cycle<P: PeriodicProblem>(
    problem: &P,
    hb: &HbOptions,
    omega_guess: f64,
    guess: &[f64],
    stability_steps: usize,
) -> Result<LimitCycle, HbError> {
    if hb.subharmonic != 1 {
        return Err(HbError::InvalidInput(
            "a limit cycle has no excitation: subharmonic order must be 1".into(),
        ));
    }
    crate::ihb::validate_omega(omega_guess)?;
    let mut res = HbResidual::new(problem, hb)?;
    let m = res.len();
    let n = hb.harmonics;
    let q_guess = guess.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if guess.len() != m || !guess.iter().all(|v| v.is_finite()) || q_guess == 0.0 {
        return Err(HbError::InvalidInput(format!(
            "guess must have {m} finite entries, not all zero"
        )));
    }
    let mut galerkin = GalerkinJacobian::new(&res);
    let n1 = m + 1;
    let phase = n + 1; // b₁ of DOF 0
    let mut q = guess.to_vec();
    let mut omega = omega_guess;
    let (mut r, mut rp, mut rm) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let mut jac = vec![0.0; m * m];
    let mut r_omega = vec![0.0; m];
    // The phase condition b₁ = 0 (DOF 0) as the border row, ω as the border column.
    let mut phase_row = vec![0.0; m];
    phase_row[phase] = 1.0;
    let mut lu = BorderedLu::new(m, 1);
    let mut step = vec![0.0; n1];
    let (mut q_trial, mut r_trial) = (vec![0.0; m], vec![0.0; m]);
    let norm_f = |r: &[f64], q: &[f64]| (norm2(r).powi(2) + q[phase] * q[phase]).sqrt();
    let tol = hb.residual_tol(res.force_scale(problem, &q, omega, &mut r));
    res.eval(problem, &q, omega, 1.0, &mut r);
    let mut norm = norm_f(&r, &q);
    let mut history = vec![norm];
    let mut stats = BroydenStats {
        iterations: 0,
        residual_evals: 1,
        jacobian_refreshes: 0,
        residual_norm: norm,
    };
    let mut last_step = f64::INFINITY;
    loop {
        if !norm.is_finite() {
            return Err(HbError::Solve(SolveError::NonFinite {
                iteration: stats.iterations,
                history,
            }));
        }
        if norm <= tol && last_step <= 1e-10 {
            break;
        }
        if stats.iterations >= hb.broyden.max_iter {
            return Err(HbError::Solve(SolveError::NonConvergence {
                iterations: stats.iterations,
                history,
            }));
        }
        stats.iterations += 1;
        galerkin.assemble(&mut res, problem, &q, omega, 1.0, &mut jac);
        stats.jacobian_refreshes += 1;
        let h = 1e-6 * omega;
        res.eval(problem, &q, omega + h, 1.0, &mut rp);
        res.eval(problem, &q, omega - h, 1.0, &mut rm);
        stats.residual_evals += 2;
        for i in 0..m {
            r_omega[i] = (rp[i] - rm[i]) / (2.0 * h);
        }
        step[..m].iter_mut().zip(&r).for_each(|(s, r)| *s = -r);
        step[m] = -q[phase];
        if lu
            .factor(&jac, &r_omega, &phase_row, &[0.0])
            .and_then(|()| lu.solve(&mut step))
            .is_err()
        {
            return Err(HbError::Solve(SolveError::SingularJacobian {
                iteration: stats.iterations,
                history,
            }));
        }
        // Damped step: halve while ‖F‖ does not decrease (or ω would turn ≤ 0).
        let mut t = 1.0;
        let mut accepted = false;
        for _ in 0..=hb.broyden.max_backtracks {
            let w = omega + t * step[m];
            if w > 0.0 {
                for i in 0..m {
                    q_trial[i] = q[i] + t * step[i];
                }
                res.eval(problem, &q_trial, w, 1.0, &mut r_trial);
                stats.residual_evals += 1;
                let nt = norm_f(&r_trial, &q_trial);
                if nt.is_finite() && (nt < norm || nt <= tol) {
                    accepted = true;
                    norm = nt;
                    break;
                }
            }
            t *= 0.5;
        }
        if !accepted {
            return Err(HbError::Solve(SolveError::NonConvergence {
                iterations: stats.iterations,
                history,
            }));
        }
        let q_scale = q_trial.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let dq = step[..m].iter().fold(0.0f64, |a, v| a.max(v.abs())) * t;
        last_step = (dq / q_scale.max(f64::MIN_POSITIVE)).max((t * step[m] / omega).abs());
        omega += t * step[m];
        q.copy_from_slice(&q_trial);
        std::mem::swap(&mut r, &mut r_trial);
        history.push(norm);
        if q_scale <= 1e-8 * q_guess {
            return Err(HbError::Equilibrium);
        }
    }
    stats.residual_norm = norm;
    let solution = HbSolution {
        coeffs: q,
        omega_f: omega,
        harmonics: n,
        subharmonic: 1,
        stats,
    };
    classify_cycle(problem, solution, stability_steps)
}
