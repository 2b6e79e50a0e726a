//! Orbit + stability: one periodic solution at a fixed ω_f by the modified
//! IHB (§3.2.2, AFT residual Eq. 62 + Broyden Eq. 63–67) or the classic IHB
//! (§3.2.1, Newton with the Galerkin Jacobian Eq. 56–61), then its Floquet
//! multipliers by Hsu's method (Eq. 78) with Magnus-4 steps, as many as
//! reach 1e-6 by their Richardson estimate ([`AdaptiveHsu`] with
//! [`HsuSteps::default`], the rule of the FRC points).

use super::{finite_pairs, positive, Array};
use ivt_hb::orbit::ihb::{HbOptions, HbSolution, HbSolver};
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::stability::{AdaptiveHsu, HsuSteps, StabilityKind};
use ivt_hb::HbError;
use ivt_hb::{ClassicIhb, ModifiedIhb};
use serde::Serialize;
use std::str::FromStr;
use std::time::Instant;

/// Which IHB variant solves the orbit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// §3.2.2: AFT residual + Broyden seeded with the linear Jacobian.
    #[default]
    Modified,
    /// §3.2.1: Newton with the Galerkin Jacobian.
    Classic,
}

impl FromStr for Method {
    type Err = HbError;

    /// `"modified"` or `"classic"`.
    fn from_str(s: &str) -> Result<Self, HbError> {
        super::one_of(
            "method",
            s,
            [("modified", Self::Modified), ("classic", Self::Classic)],
        )
    }
}

/// What to solve at which frequency.
#[derive(Debug, Clone, PartialEq)]
pub struct OrbitRequest {
    /// Excitation frequency ω_f (finite, > 0).
    pub omega_f: f64,
    /// IHB variant.
    pub method: Method,
    /// Start coefficients (default: the solver's own start).
    pub guess: Option<Vec<f64>>,
    /// Compute the Floquet multipliers.
    pub stability: bool,
}

impl Default for OrbitRequest {
    /// Fig. 28's ω_f = 0.4, modified IHB, with stability.
    fn default() -> Self {
        Self {
            omega_f: 0.4,
            method: Method::Modified,
            guess: None,
            stability: true,
        }
    }
}

impl OrbitRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for a non-finite or non-positive ω_f.
    pub fn validate(&self) -> Result<(), HbError> {
        positive("omega_f", self.omega_f).map(|_| ())
    }
}

/// One orbit: the keys of `ivt hb duffing --json` and `ivt.hb.duffing`.
#[derive(Debug, Clone, Serialize)]
pub struct Orbit {
    /// `[a0, a1..an, b1..bn]` per DOF (u = a0/2 + Σ a_k cos kτ + b_k sin kτ).
    pub coeffs: Array<f64>,
    /// Solver iterations.
    pub iterations: usize,
    /// ‖r‖₂ at the result.
    pub residual_norm: f64,
    /// Residual evaluations.
    pub residual_evals: usize,
    /// Wall time of the solve alone (not the stability).
    pub solve_time_s: f64,
    /// Excitation frequency.
    pub omega_f: f64,
    /// Harmonics n.
    pub harmonics: usize,
    /// Period multiple p (period p·2π/ω_f).
    pub subharmonic: usize,
    /// max |x_0| over the period (DOF 0).
    pub amplitude: f64,
    /// Floquet multipliers `[[re, im], ...]`, decreasing modulus (empty
    /// without stability).
    pub floquet: Vec<[f64; 2]>,
    /// Richardson estimate of the multipliers' error, relative to
    /// max(1, |μ|) (at most 1e-6 unless 4096 sub-intervals did not reach
    /// it; None without stability).
    pub multiplier_error: Option<f64>,
    /// All multipliers inside the unit circle (None without stability).
    pub stable: Option<bool>,
    /// The leading multiplier's class (None without stability).
    pub stability: Option<StabilityKind>,
    /// The solution itself (for plots; not serialized).
    #[serde(skip)]
    pub solution: HbSolution,
}

impl Orbit {
    /// Largest |μ| (0 without stability).
    pub fn max_modulus(&self) -> f64 {
        self.floquet
            .iter()
            .map(|[re, im]| re.hypot(*im))
            .fold(0.0, f64::max)
    }
}

/// Solve `problem` at `req.omega_f` and, if asked, its Floquet multipliers.
///
/// # Errors
/// [`OrbitRequest::validate`]'s, the solver's (non-convergence carries the
/// residual history), and [`HbError::NonFiniteMultipliers`] when Hsu's
/// monodromy is not finite (the stability would be unknown).
pub fn orbit(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    req: &OrbitRequest,
) -> Result<Orbit, HbError> {
    let problem = &problem;
    req.validate()?;
    let t0 = Instant::now();
    let mut solver: Box<dyn HbSolver + '_> = match req.method {
        Method::Modified => Box::new(ModifiedIhb::new(problem, hb.clone())?),
        Method::Classic => Box::new(ClassicIhb::new(problem, hb.clone())?),
    };
    let sol = solver.solve(req.omega_f, req.guess.as_deref())?;
    let solve_time_s = t0.elapsed().as_secs_f64();
    let (floquet, multiplier_error, stable, stability) = if req.stability {
        let est =
            AdaptiveHsu::new(problem, hb.harmonics, HsuSteps::default())?.floquet(problem, &sol)?;
        let f = est.floquet;
        (
            finite_pairs(&f.multipliers, req.omega_f, est.steps)?,
            est.error,
            Some(f.stable()),
            Some(f.kind),
        )
    } else {
        (Vec::new(), None, None, None)
    };
    Ok(Orbit {
        coeffs: Array(sol.coeffs.clone()),
        iterations: sol.stats.iterations,
        residual_norm: sol.stats.residual_norm,
        residual_evals: sol.stats.residual_evals,
        solve_time_s,
        omega_f: sol.omega_f,
        harmonics: sol.harmonics,
        subharmonic: sol.subharmonic,
        amplitude: sol.amplitude(0),
        floquet,
        multiplier_error,
        stable,
        stability,
        solution: sol,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ivt_hb::Duffing;

    #[test]
    fn methods_parse_by_name_and_refuse_others() {
        assert_eq!("classic".parse::<Method>(), Ok(Method::Classic));
        assert_eq!("modified".parse::<Method>(), Ok(Method::Modified));
        let e = "newton".parse::<Method>().unwrap_err();
        assert_eq!(e.kind(), "input");
    }

    #[test]
    fn an_overflowing_monodromy_is_an_error_not_an_unstable_verdict() {
        // Linear, ξ = −20, ω_f = 0.01: the orbit exists (HB is exact), but
        // its multipliers are e^{±20·2π/0.01} = overflow → stability unknown.
        let d = Duffing::new(-20.0, 1.0, 0.0, 0.1);
        let hb = HbOptions::new(5, 16).with_tol(1e-10);
        let req = OrbitRequest {
            omega_f: 0.01,
            ..OrbitRequest::default()
        };
        match orbit(&d, &hb, &req) {
            Err(e @ HbError::NonFiniteMultipliers { .. }) => assert_eq!(e.kind(), "failed"),
            other => panic!("expected NonFiniteMultipliers, got {other:?}"),
        }
        // Without stability the same orbit is an answer.
        let plain = OrbitRequest {
            stability: false,
            ..req
        };
        assert!(orbit(&d, &hb, &plain).is_ok());
    }

    #[test]
    fn both_methods_give_the_same_fig28_orbit() {
        // Fig. 28 (ξ = 0.02, α = ε = 1, F = 0.1, ω_f = 0.4): the classic and
        // the modified IHB converge to one orbit, a stable one.
        let d = Duffing::new(0.02, 1.0, 1.0, 0.1);
        let hb = HbOptions::new(20, 64).with_tol(1e-10);
        let m = orbit(&d, &hb, &OrbitRequest::default()).unwrap();
        let req = OrbitRequest {
            method: Method::Classic,
            ..OrbitRequest::default()
        };
        let c = orbit(&d, &hb, &req).unwrap();
        assert_eq!(m.coeffs.0.len(), 41);
        for (a, b) in m.coeffs.0.iter().zip(&c.coeffs.0) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
        assert_eq!(m.stable, Some(true));
        assert!(m.max_modulus() < 1.0);
    }

    #[test]
    fn tiny_frequency_gives_a_failed_error_not_nan_multipliers() {
        let d = Duffing::new(0.02, 1.0, 1.0, 0.1);
        let req = OrbitRequest {
            omega_f: 1e-6,
            ..OrbitRequest::default()
        };
        let e = orbit(&d, &HbOptions::new(20, 64), &req).unwrap_err();
        assert_eq!(e.kind(), "failed", "{e}");
        assert!(e.to_string().contains("not finite"), "{e}");
        let bad = OrbitRequest {
            omega_f: f64::NAN,
            ..OrbitRequest::default()
        };
        assert_eq!(bad.validate().unwrap_err().kind(), "input");
    }
}
