//! The frequency response of a reduced model ([`ReducedModel`]): the
//! condensed path ([`condensed_response`]) on the reduced structure, any DOF
//! of the whole structure recovered from the reduced coordinates, and the
//! stability decided with the reduction's effect on the multipliers
//! estimated.
//!
//! That effect: the multipliers of each orbit on the nested reduced model
//! (the basis without its last Krylov block, same coordinates `x_S`) against
//! those on the whole reduced model; what decides stability is the largest
//! modulus ρ, so the estimate is the change of ρ. (The sets themselves
//! differ by many multipliers on a solid: with damping `C = αM` every mode
//! has |μ| = e^(−αT/2), and a block more adds modes on that circle without
//! moving ρ.) The point's `multiplier_error` is that change plus the
//! reduced model's own estimate ([`CondensedFloquet::error_estimate`]); a
//! point whose ρ lies within it of 1 is [`Verdict::Uncertain`].

use super::model::ReducedModel;
use crate::frc::series_max;
use crate::stability::{BasisGrowth, CondensedFloquet, ReducedStability};
use crate::{condensed_response, CondensedBranch, CondensedFrc, CondensedFrcOptions};
use ivt_hb::orbit::aft::Aft;
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::stability::{HsuSteps, StabilityKind};
use ivt_hb::HbError;

/// What the multipliers of a point say, given their error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// ρ plus its error below 1.
    Stable,
    /// ρ minus its error above 1 (the kind of the leading multiplier).
    Unstable(StabilityKind),
    /// ρ within its error of 1.
    Uncertain,
}

impl Verdict {
    /// `"stable"`, the instability's name (`"fold"`, …) or `"uncertain"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Stable => "stable",
            Self::Unstable(kind) => kind.name(),
            Self::Uncertain => "uncertain",
        }
    }

    /// `Some(stable)`, `None` when uncertain.
    pub fn stable(self) -> Option<bool> {
        match self {
            Self::Stable => Some(true),
            Self::Unstable(_) => Some(false),
            Self::Uncertain => None,
        }
    }

    /// The verdict on the multipliers `floquet` whose largest modulus is
    /// off by at most `error`.
    pub fn of(floquet: &CondensedFloquet, error: f64) -> Self {
        let rho = floquet.floquet.max_modulus();
        if !(rho.is_finite() && error.is_finite()) {
            Self::Uncertain
        } else if rho + error < 1.0 {
            Self::Stable
        } else if rho - error > 1.0 {
            Self::Unstable(floquet.floquet.kind)
        } else {
            Self::Uncertain
        }
    }
}

/// The stability of one point of a reduced curve.
#[derive(Debug, Clone, PartialEq)]
pub struct ReducedPoint {
    /// The reduction's effect on ρ (module docs).
    pub reduction_error: f64,
    /// The whole estimate: the reduced model's own plus `reduction_error`.
    pub multiplier_error: f64,
    /// The verdict with that error.
    pub verdict: Verdict,
}

/// A curve of a reduced model.
#[derive(Debug, Clone)]
pub struct ReducedFrc {
    /// The curve (DOFs of the whole structure in `dof_coeffs` and
    /// `amplitude`; `coeffs` are the harmonics of the nonlinear DOFs).
    pub frc: CondensedFrc,
    /// Per point, with stability asked for.
    pub stability: Vec<Option<ReducedPoint>>,
}

/// Traces the response of `model` with `g` = `local` on its nonlinear DOFs
/// (`opts.amplitude_dof` and `opts.record_dofs` are DOFs of the whole
/// structure).
///
/// # Errors
/// As [`condensed_response`]; [`HbError::InvalidInput`] for a DOF out of
/// range.
pub fn reduced_response<P: PeriodicProblem>(
    model: &ReducedModel,
    local: &P,
    hb: &HbOptions,
    opts: &CondensedFrcOptions,
) -> Result<ReducedFrc, HbError> {
    let dofs = model.dofs();
    let (s, r) = (dofs.len(), model.structure().n_dof());
    let first = dofs.first().copied().unwrap_or(0);
    let amplitude_dof = opts.amplitude_dof.unwrap_or(first);
    if let Some(bad) = opts
        .record_dofs
        .iter()
        .chain([&amplitude_dof])
        .find(|&&d| d >= model.n_dof())
    {
        return Err(HbError::InvalidInput(format!("DOF {bad} is out of range")));
    }
    let local_amplitude = dofs.iter().position(|&d| d == amplitude_dof);
    let expand = local_amplitude.is_none() || !opts.record_dofs.is_empty();
    let all: Vec<usize> = (0..r).collect();
    let reduced_opts = CondensedFrcOptions {
        amplitude_dof: Some(local_amplitude.unwrap_or(0)),
        record_dofs: if expand { all.clone() } else { Vec::new() },
        ..opts.clone()
    };
    let (load_cos, load_sin) = model.load();
    let mut branch = CondensedBranch::new(
        model.structure().clone(),
        (0..s).collect(),
        load_cos,
        load_sin,
        local,
        hb,
    )?
    .with_model_error(model.report().error_estimate);
    let mut frc = condensed_response(&mut branch, &reduced_opts)?;
    let mut aft = Aft::new(hb.harmonics, hb.n_half)?;
    let mut samples = vec![0.0; aft.n_samples()];
    for point in &mut frc.points {
        let reduced: Vec<Vec<f64>> = point.dof_coeffs.iter().map(|(_, c)| c.clone()).collect();
        if local_amplitude.is_none() {
            let x = model.expand(amplitude_dof, &reduced);
            point.amplitude = series_max(&mut aft, &mut samples, &x);
        }
        point.dof_coeffs = opts
            .record_dofs
            .iter()
            .map(|&d| (d, model.expand(d, &reduced)))
            .collect();
    }
    if local_amplitude.is_none() {
        for fold in &mut frc.events {
            let reduced = branch.recover(&fold.coeffs, fold.omega_f, &all)?;
            let x = model.expand(amplitude_dof, &reduced);
            fold.amplitude = series_max(&mut aft, &mut samples, &x);
        }
    }
    let stability = match opts.stability_blocks {
        None => vec![None; frc.points.len()],
        Some(max_blocks) => {
            let coarse_size = model.coarse_structure().n_dof();
            let zeros = vec![0.0; coarse_size];
            let coarse = CondensedBranch::new(
                model.coarse_structure().clone(),
                (0..s).collect(),
                &zeros,
                &[],
                local,
                hb,
            )?;
            let growth = BasisGrowth {
                tol: opts.stability_tol,
                max_blocks,
            };
            let mut nested = ReducedStability::new(&coarse, growth, HsuSteps::default())?;
            frc.points
                .iter()
                .map(|point| {
                    let Some(fine) = &point.floquet else {
                        return Ok(None);
                    };
                    let small = nested.floquet(&coarse, &point.coeffs, point.omega_f)?;
                    let change = (fine.floquet.max_modulus() - small.floquet.max_modulus()).abs();
                    let change = if change.is_nan() {
                        f64::INFINITY
                    } else {
                        change
                    };
                    let error = fine.error_estimate() + change;
                    Ok(Some(ReducedPoint {
                        reduction_error: change,
                        multiplier_error: error,
                        verdict: Verdict::of(fine, error),
                    }))
                })
                .collect::<Result<Vec<_>, HbError>>()?
        }
    };
    Ok(ReducedFrc { frc, stability })
}
