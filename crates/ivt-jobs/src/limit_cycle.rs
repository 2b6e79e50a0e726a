//! Limit cycle of an autonomous system: harmonic balance with the response
//! frequency ω an unknown and the phase condition b1 = 0 on DOF 0 (§3.2.4,
//! Newton with the Galerkin Jacobian), its multipliers by Hsu (Eq. 78).

use super::{finite, finite_pairs, stability_steps, Array};
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::stability::StabilityKind;
use ivt_hb::HbError;
use serde::Serialize;

/// Where the iteration starts.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitCycleRequest {
    /// Guess of ω (finite, > 0).
    pub omega_guess: f64,
    /// Start coefficients (n_dof blocks of `[a0, a1..an, b1..bn]`) at
    /// `omega_guess`; None: the transient from [`Self::x0`].
    pub guess: Option<Vec<f64>>,
    /// Start state `[x..., v...]` (2·n_dof entries) of the transient that
    /// settles onto the attractor before HB refines it
    /// ([`ivt_hb::limit_cycle_from_state`]); None: x = (`amplitude`, 0, …),
    /// v = 0. Not used with a `guess`.
    pub x0: Option<Vec<f64>>,
    /// x of DOF 0 in the default start state.
    pub amplitude: f64,
}

impl Default for LimitCycleRequest {
    /// ω ≈ 1, start x_0 = cos τ.
    fn default() -> Self {
        Self {
            omega_guess: 1.0,
            guess: None,
            x0: None,
            amplitude: 1.0,
        }
    }
}

impl LimitCycleRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for a non-finite ω guess, amplitude or
    /// start state, or for both a `guess` and an `x0`.
    pub fn validate(&self) -> Result<(), HbError> {
        finite("omega_guess", self.omega_guess)?;
        finite("amplitude", self.amplitude)?;
        if let Some(x0) = &self.x0 {
            if x0.iter().any(|v| !v.is_finite()) {
                return Err(HbError::InvalidInput(
                    "x0 must be finite [x..., v...]".into(),
                ));
            }
            if self.guess.is_some() {
                return Err(HbError::InvalidInput(
                    "give either `guess` (coefficients) or `x0` (a state), not both".into(),
                ));
            }
        }
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
/// [`LimitCycleRequest::validate`]'s, those of [`ivt_hb::limit_cycle`]
/// (non-convergence, collapse onto the equilibrium) and, without a guess,
/// those of [`ivt_hb::limit_cycle_from_state`] (a transient that comes to rest).
pub fn limit_cycle<P: PeriodicProblem>(
    problem: &P,
    hb: &HbOptions,
    req: &LimitCycleRequest,
) -> Result<Cycle, HbError> {
    req.validate()?;
    let steps = stability_steps(hb.harmonics);
    let lc = match &req.guess {
        Some(start) => ivt_hb::limit_cycle(problem, hb, req.omega_guess, start, steps)?,
        None => {
            let state = match &req.x0 {
                Some(x0) => x0.clone(),
                None => {
                    let mut s = vec![0.0; problem.n_dof().saturating_mul(2)];
                    if let Some(x) = s.first_mut() {
                        *x = req.amplitude;
                    }
                    s
                }
            };
            ivt_hb::limit_cycle_from_state(
                problem,
                hb,
                &state,
                &ivt_hb::TransientOptions::default(),
                steps,
            )?
        }
    };
    Ok(Cycle {
        omega: lc.omega(),
        period: lc.period(),
        coeffs: Array(lc.solution.coeffs.clone()),
        multipliers: finite_pairs(&lc.multipliers, lc.omega(), steps)?,
        stable: lc.stable(),
        stability: lc.kind,
        iterations: lc.solution.stats.iterations,
        residual_norm: lc.solution.stats.residual_norm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ivt_hb::problem::Oscillator;

    #[test]
    fn weak_van_der_pol_has_amplitude_two_and_is_stable() {
        // Van der Pol x'' − μ(1 − x²)x' + x = 0 (C = −μ, g = μx²v): by
        // averaging the cycle is x ≈ 2 cos t for small μ (ω → 1, a1 → 2),
        // corrections O(μ²).
        let p = Oscillator::VanDerPol.problem(0.05);
        let hb = HbOptions::new(8, 32);
        let c = limit_cycle(&p, &hb, &LimitCycleRequest::default()).unwrap();
        assert!((c.omega - 1.0).abs() < 1e-3, "{}", c.omega);
        assert!((c.coeffs.0[1].hypot(c.coeffs.0[9]) - 2.0).abs() < 1e-2);
        assert!(c.stable);
    }
}
