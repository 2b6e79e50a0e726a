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
    /// The relative accuracy asked of ω and the coefficients
    /// ([`DEFAULT_TOL`]); 0: the harmonics stay as given (the estimate is
    /// still reported).
    pub tol: f64,
}

impl Default for LimitCycleRequest {
    /// ω ≈ 1, start x_0 = cos τ, `tol` [`DEFAULT_TOL`].
    fn default() -> Self {
        Self {
            omega_guess: 1.0,
            guess: None,
            x0: None,
            amplitude: 1.0,
            tol: DEFAULT_TOL,
        }
    }
}

/// The default relative accuracy of a limit cycle's ω and coefficients.
pub const DEFAULT_TOL: f64 = 1e-8;

/// Most harmonics the accuracy loop grows n to; beyond, the result says
/// `accuracy: "not met"` with its estimate.
pub const MAX_HARMONICS: usize = 160;

/// The estimate is this multiple of the change from n to the next n: the
/// error of n is at most the change plus the error of the next n, which is
/// at most half that of n where the harmonics converge (each step adds
/// half the harmonics).
const ESTIMATE_FACTOR: f64 = 2.0;

/// The estimate's floor: the accuracy of the Newton solves themselves (their
/// last step is below 1e-10 relative and Newton converges quadratically) and
/// of double-precision sums over the harmonics; below it a change between n
/// and the next n is rounding.
const ESTIMATE_FLOOR: f64 = 1e-11;

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
        if !(self.tol.is_finite() && self.tol >= 0.0) {
            return Err(HbError::InvalidInput(format!(
                "tol = {:?} must be finite and ≥ 0 (0: the harmonics as given)",
                self.tol
            )));
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
    /// Harmonics n of the result.
    pub harmonics: usize,
    /// Half the AFT samples N of the result.
    pub samples: usize,
    /// Relative error estimate of ω and of the coefficients (relative to
    /// their largest): twice the largest change of either from this n to
    /// the next, 1.5·n, and at least 1e-11 (the solves' floor); None if the
    /// next n did not converge.
    pub error_estimate: Option<f64>,
    /// The relative accuracy asked (0: none, n as given).
    pub tol: f64,
    /// `"met"` (the estimate is at most `tol`), `"not met"` (n reached
    /// [`MAX_HARMONICS`], or the next n failed, first), or `"not asked"`
    /// (`tol` = 0).
    pub accuracy: &'static str,
}

/// The limit cycle of `problem` near `req`'s start, with its error
/// estimate; with `req.tol` > 0 the harmonics grow (n → 1.5·n, samples in
/// proportion) until the estimate meets it, up to [`MAX_HARMONICS`]
/// ([`Cycle::accuracy`]). Samples N ≤ n are raised to the default
/// proportion 64 per 20 harmonics.
///
/// # Errors
/// [`LimitCycleRequest::validate`]'s, those of [`ivt_hb::limit_cycle`]
/// (non-convergence, collapse onto the equilibrium) and, without a guess,
/// those of [`ivt_hb::limit_cycle_from_state`] (a transient that comes to rest).
pub fn limit_cycle(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    req: &LimitCycleRequest,
) -> Result<Cycle, HbError> {
    let problem = &problem;
    req.validate()?;
    ivt_hb::branches::autonomous::require_autonomous(problem, "a limit cycle")?;
    // Too few samples for n (e.g. n = 80 with the default 64): the default
    // proportion, 64 per 20 harmonics.
    let mut hb = hb.clone();
    if hb.n_half <= hb.harmonics {
        hb.n_half = samples_for(hb.harmonics, 20, 64);
    }
    let hb = &hb;
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
            ivt_hb::limit_cycle_from_state(problem, hb, &state, &START_TRANSIENT, steps)?
        }
    };
    certified(problem, hb, req.tol, lc)
}

/// The transient that finds a cycle's start: settled to 1e-6 between section
/// crossings (Newton's basin, not the answer: the cycle is the harmonic
/// balance's), so it is integrated to 1e-8 rather than the default 1e-10:
/// the Van der Pol cycle of the benchmark gate from amplitude 2 with 2698
/// one-sample calls of `g` instead of 6238, the same ω to 1e-16 (measured).
const START_TRANSIENT: ivt_hb::TransientOptions = ivt_hb::TransientOptions {
    tol: 1e-8,
    settle: 1e-6,
    max_returns: 8,
    max_crossings: 5000,
    max_steps: 2_000_000,
};

/// The next n of the accuracy loop: half as many harmonics more.
fn next_harmonics(n: usize) -> usize {
    n + n.div_ceil(2).max(2)
}

/// Half the AFT samples for `n` harmonics, in the proportion `samples/from`
/// of the caller's options (so aliasing does not grow with n).
fn samples_for(n: usize, from: usize, samples: usize) -> usize {
    (samples * n).div_ceil(from.max(1)).max(n + 1)
}

/// `coeffs` (`2n + 1` per DOF) with `to` harmonics (zeros added).
fn padded(coeffs: &[f64], n: usize, to: usize) -> Vec<f64> {
    coeffs
        .chunks_exact(2 * n + 1)
        .flat_map(|block| ivt_hb::orbit::aft::embed_subharmonic(block, 1, to))
        .collect()
}

/// max(|Δω|/ω, max|Δq|/max|q|) between the cycle `coarse` (n harmonics) and
/// `fine` (more).
fn change(coarse: &ivt_hb::HbSolution, fine: &ivt_hb::HbSolution) -> f64 {
    let q = padded(&coarse.coeffs, coarse.harmonics, fine.harmonics);
    let size = fine.coeffs.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let dq = q
        .iter()
        .zip(&fine.coeffs)
        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
    let dw = (coarse.omega_f - fine.omega_f).abs() / fine.omega_f.abs();
    dw.max(dq / size)
}

/// The cycle `lc` (at `hb`) with its error estimate, n grown until the
/// estimate meets `tol` (issue 41): at each n the cycle is solved again at
/// 1.5·n (samples in proportion) from its own coefficients, and the
/// estimate is [`ESTIMATE_FACTOR`] times the change. The reported cycle is
/// the last n whose estimate is known (its multipliers by Hsu at that n).
fn certified<P: PeriodicProblem>(
    problem: &P,
    hb: &HbOptions,
    tol: f64,
    lc: ivt_hb::LimitCycle,
) -> Result<Cycle, HbError> {
    let (n0, s0) = (hb.harmonics, hb.n_half);
    let mut current = lc.solution.clone();
    let mut estimate = None;
    let mut met = false;
    loop {
        let n = current.harmonics;
        let next = next_harmonics(n);
        let mut fine_hb = hb.clone();
        fine_hb.harmonics = next;
        fine_hb.n_half = samples_for(next, n0, s0);
        let guess = padded(&current.coeffs, n, next);
        let Ok(fine) = ivt_hb::branches::autonomous::limit_cycle_orbit(
            problem,
            &fine_hb,
            current.omega_f,
            &guess,
        ) else {
            break;
        };
        let e = (ESTIMATE_FACTOR * change(&current, &fine)).max(ESTIMATE_FLOOR);
        estimate = Some(e);
        if e <= tol {
            met = true;
            break;
        }
        if tol == 0.0 || next > MAX_HARMONICS {
            break;
        }
        current = fine;
        estimate = None;
    }
    let n = current.harmonics;
    let samples = if n == n0 { s0 } else { samples_for(n, n0, s0) };
    let steps = stability_steps(n);
    let lc = if n == n0 {
        lc
    } else {
        ivt_hb::branches::autonomous::classify_cycle(problem, current, steps)?
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
        harmonics: n,
        samples,
        error_estimate: estimate,
        tol,
        accuracy: match (met, tol == 0.0) {
            (_, true) => "not asked",
            (true, false) => "met",
            (false, false) => "not met",
        },
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
