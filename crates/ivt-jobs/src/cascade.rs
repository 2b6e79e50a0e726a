//! The period-doubling cascade of the Mathieu–Duffing equation Eq. 81
//! (§3.2.5, Eq. 81–85): β at the first three period doublings, each where a
//! Floquet multiplier crosses −1 along the branch in β.

use super::{all_finite, pairs, positive};
use ivt_hb::branches::mathieu::{period_doubling_cascade, CascadeOptions, PeriodDoubling};
use ivt_hb::HbError;
use serde::Serialize;
use std::time::Instant;

/// β1, β2, β4 as printed in §3.2.5.
pub const THESIS_BETAS: [f64; 3] = [4.825, 5.194, 5.253];

/// The equation's parameters, the harmonics of the period-1 orbit and the
/// search's settings: the options of [`period_doubling_cascade`] themselves
/// (the command line and Python set ξ̂, α̂, Ω, γ and n; the rest keeps
/// §3.2.5's defaults).
pub type CascadeRequest = CascadeOptions;

/// The job's check of its request.
///
/// # Errors
/// [`HbError::InvalidInput`] for a non-finite parameter, Ω ≤ 0, samples
/// that do not exceed n, or steps the period-1 leg refuses.
pub fn validate(req: &CascadeRequest) -> Result<(), HbError> {
    all_finite(&[
        ("xi", req.xi),
        ("alpha", req.alpha),
        ("gamma", req.gamma),
        ("beta0", req.beta0),
    ])?;
    positive("omega", req.omega)?;
    req.period_one_samples()?;
    req.period_one_path().map(|_| ())
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
/// [`validate`]'s and the continuation's.
pub fn cascade(req: &CascadeRequest) -> Result<Cascade, HbError> {
    validate(req)?;
    let t0 = Instant::now();
    let doublings = period_doubling_cascade(req)?;
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

    #[test]
    fn samples_and_steps_are_checked_before_solving() {
        let refused = |req: CascadeRequest| cascade(&req).unwrap_err().to_string();
        let few = refused(CascadeRequest {
            samples: Some(12),
            ..CascadeRequest::default()
        });
        assert!(few.contains("`samples` = 12 must exceed `n` = 12"), "{few}");
        let ds = refused(CascadeRequest {
            steps: ivt_path::continuation::Steps {
                ds_min: Some(0.5),
                ..Default::default()
            },
            ..CascadeRequest::default()
        });
        assert!(ds.contains("`ds_min` = 0.5"), "{ds}");
    }

    #[test]
    fn a_leg_cut_short_says_how_it_ended() {
        let short = CascadeRequest {
            steps: ivt_path::continuation::Steps {
                max_points: Some(4),
                ..Default::default()
            },
            ..CascadeRequest::default()
        };
        let e = cascade(&short).unwrap_err().to_string();
        assert!(
            e.contains(
                "period-1 branch never reached μ = −1: it ended with `max_points` after 4 points"
            ),
            "{e}"
        );
    }
}
