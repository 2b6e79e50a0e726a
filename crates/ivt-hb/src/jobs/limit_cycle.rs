//! Limit cycle of an autonomous system: harmonic balance with the response
//! frequency ω an unknown and the phase condition b1 = 0 on DOF 0 (§3.2.4,
//! Newton with the Galerkin Jacobian), its multipliers by Hsu (Eq. 78).

use super::{finite, pairs, stability_steps, Array};
use crate::error::HbError;
use crate::ihb::HbOptions;
use crate::problem::PeriodicProblem;
use crate::stability::StabilityKind;
use serde::Serialize;

/// Where the iteration starts.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitCycleRequest {
    /// Guess of ω (finite, > 0).
    pub omega_guess: f64,
    /// Start coefficients (n_dof blocks of `[a0, a1..an, b1..bn]`); None:
    /// `x_0 = amplitude·cos τ`.
    pub guess: Option<Vec<f64>>,
    /// Amplitude of the default start.
    pub amplitude: f64,
}

impl Default for LimitCycleRequest {
    /// ω ≈ 1, start x_0 = cos τ.
    fn default() -> Self {
        Self {
            omega_guess: 1.0,
            guess: None,
            amplitude: 1.0,
        }
    }
}

impl LimitCycleRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for a non-finite ω guess or amplitude.
    pub fn validate(&self) -> Result<(), HbError> {
        finite("omega_guess", self.omega_guess)?;
        finite("amplitude", self.amplitude)?;
        Ok(())
    }
}

/// A limit cycle: the keys of `ivt.hb.limit_cycle`.
#[derive(Debug, Clone, Serialize)]
pub struct Cycle {
    /// Response frequency ω.
    pub omega: f64,
    /// Period 2π/ω.
    pub period: f64,
    /// Coefficients (n_dof blocks).
    pub coeffs: Array<f64>,
    /// Multipliers `[[re, im], ...]`, the trivial +1 included.
    pub multipliers: Vec<[f64; 2]>,
    /// All non-trivial multipliers inside the unit circle.
    pub stable: bool,
    /// Their class.
    pub stability: StabilityKind,
    /// Newton steps.
    pub iterations: usize,
    /// ‖r‖₂ at the result.
    pub residual_norm: f64,
}

/// The limit cycle of `problem` near `req`'s start.
///
/// # Errors
/// [`LimitCycleRequest::validate`]'s and those of [`crate::limit_cycle`]
/// (non-convergence, collapse onto the equilibrium).
pub fn limit_cycle<P: PeriodicProblem>(
    problem: &P,
    hb: &HbOptions,
    req: &LimitCycleRequest,
) -> Result<Cycle, HbError> {
    req.validate()?;
    let start = match &req.guess {
        Some(q) => q.clone(),
        None => {
            // x_0 = amplitude·cos τ: a1 of DOF 0 (index 1), all else zero.
            let len = problem
                .n_dof()
                .saturating_mul(hb.harmonics.saturating_mul(2).saturating_add(1));
            let mut q = vec![0.0; len];
            if let Some(a1) = q.get_mut(1) {
                *a1 = req.amplitude;
            }
            q
        }
    };
    let lc = crate::limit_cycle(
        problem,
        hb,
        req.omega_guess,
        &start,
        stability_steps(hb.harmonics),
    )?;
    Ok(Cycle {
        omega: lc.omega(),
        period: lc.period(),
        coeffs: Array(lc.solution.coeffs.clone()),
        multipliers: pairs(&lc.multipliers),
        stable: lc.stable(),
        stability: lc.kind,
        iterations: lc.solution.stats.iterations,
        residual_norm: lc.solution.stats.residual_norm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::GeneralProblem;

    #[test]
    fn weak_van_der_pol_has_amplitude_two_and_is_stable() {
        // Van der Pol x'' − μ(1 − x²)x' + x = 0 (C = −μ, g = μx²v): by
        // averaging the cycle is x ≈ 2 cos t for small μ (ω → 1, a1 → 2),
        // corrections O(μ²).
        let mu = 0.05;
        let p = GeneralProblem::new(
            1,
            vec![1.0],
            vec![-mu],
            vec![1.0],
            move |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| g[0] = mu * x[0] * x[0] * v[0],
            |_t: f64, out: &mut [f64]| out[0] = 0.0,
        );
        let hb = HbOptions::new(8, 32);
        let c = limit_cycle(&p, &hb, &LimitCycleRequest::default()).unwrap();
        assert!((c.omega - 1.0).abs() < 1e-3, "{}", c.omega);
        assert!((c.coeffs.0[1].hypot(c.coeffs.0[9]) - 2.0).abs() < 1e-2);
        assert!(c.stable);
    }
}
