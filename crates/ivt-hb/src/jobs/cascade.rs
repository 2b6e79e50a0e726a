//! The period-doubling cascade of the Mathieu–Duffing equation Eq. 81
//! (§3.2.5, Eq. 81–85): β at the first three period doublings, each where a
//! Floquet multiplier crosses −1 along the branch in β.

use super::{all_finite, pairs, positive};
use crate::error::HbError;
use crate::mathieu::{period_doubling_cascade, CascadeOptions, PeriodDoubling};
use serde::Serialize;
use std::time::Instant;

/// β1, β2, β4 as printed in §3.2.5.
pub const THESIS_BETAS: [f64; 3] = [4.825, 5.194, 5.253];

/// The equation's parameters and the harmonics of the period-1 orbit.
#[derive(Debug, Clone, PartialEq)]
pub struct CascadeRequest {
    /// Damping ratio ξ̂.
    pub xi: f64,
    /// Stiffness α̂ (enters as −α̂).
    pub alpha: f64,
    /// Parametric excitation frequency Ω (> 0).
    pub omega: f64,
    /// Cubic stiffness γ.
    pub gamma: f64,
    /// Harmonics of the period-1 solution (period 2^k uses 2^k n).
    pub harmonics: usize,
}

impl Default for CascadeRequest {
    /// §3.2.5: ξ̂ = 0.125, α̂ = 1, Ω = 2, γ = 1, n = 12.
    fn default() -> Self {
        let o = CascadeOptions::default();
        Self {
            xi: o.xi,
            alpha: o.alpha,
            omega: o.omega,
            gamma: o.gamma,
            harmonics: o.harmonics,
        }
    }
}

impl CascadeRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for a non-finite parameter or Ω ≤ 0.
    pub fn validate(&self) -> Result<(), HbError> {
        all_finite(&[
            ("xi", self.xi),
            ("alpha", self.alpha),
            ("gamma", self.gamma),
        ])?;
        positive("omega", self.omega).map(|_| ())
    }
}

/// The cascade: the keys of `ivt hb mathieu-duffing --json` and
/// `ivt.hb.mathieu_cascade`.
#[derive(Debug, Clone, Serialize)]
pub struct Cascade {
    /// β at each doubling.
    pub period_doubling_beta: Vec<f64>,
    /// Period multiple of the branch that doubles (1, 2, 4).
    pub periods: Vec<usize>,
    /// The multiplier through −1 at each doubling `[re, im]`.
    pub multipliers: Vec<[f64; 2]>,
    /// [`THESIS_BETAS`].
    pub thesis: [f64; 3],
    /// Wall time.
    pub time_s: f64,
    /// The doublings with their orbits (for plots; not serialized).
    #[serde(skip)]
    pub doublings: Vec<PeriodDoubling>,
}

/// Follow the cascade of `req`.
///
/// # Errors
/// [`CascadeRequest::validate`]'s and the continuation's.
pub fn cascade(req: &CascadeRequest) -> Result<Cascade, HbError> {
    req.validate()?;
    let opts = CascadeOptions {
        xi: req.xi,
        alpha: req.alpha,
        omega: req.omega,
        gamma: req.gamma,
        harmonics: req.harmonics,
        ..CascadeOptions::default()
    };
    let t0 = Instant::now();
    let doublings = period_doubling_cascade(&opts)?;
    let mu: Vec<_> = doublings.iter().map(|p| p.multiplier).collect();
    Ok(Cascade {
        period_doubling_beta: doublings.iter().map(|p| p.beta).collect(),
        periods: doublings.iter().map(|p| p.period).collect(),
        multipliers: pairs(&mu),
        thesis: THESIS_BETAS,
        time_s: t0.elapsed().as_secs_f64(),
        doublings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_positive_excitation_frequency_is_refused_before_solving() {
        let req = CascadeRequest {
            omega: 0.0,
            ..CascadeRequest::default()
        };
        let e = cascade(&req).unwrap_err();
        assert_eq!(e.kind(), "input");
        assert!(e.to_string().contains("`omega`"), "{e}");
    }
}
