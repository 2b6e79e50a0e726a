//! The whole open-loop refit of thesis §4.2.1 in one call: IHB r̄ over a
//! (V_m, T_U) grid, the Eq. 158 polynomial through its feasible points, the
//! Eq. 159 over-drive boundary (r̄ = r_max) and the under-drive one (r̄ = 0),
//! and the ω_a error of the refitted law and of the thesis's printed law.
//! `ivt ol fit` and `ivt.design.ol_fit` both report this.

use crate::fit::{self, LawError, OpenLoopLaw, PolyFit, PolyForm};
use crate::steady::IhbOptions;
use crate::sweep::{self, Grid};
use crate::IvtError;
use ivt_kin::plant::PlantParams;

/// A straight line V_m = α T_U + β through the T_U values of the grid where
/// r̄ reaches a target (Eq. 159 form).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundary {
    /// Slope α \[V/(N·m)\].
    pub alpha: f64,
    /// Intercept β \[V\].
    pub beta: f64,
    /// Max |V_m − (α T_U + β)| over the T_U values \[V\].
    pub max_dev_v: f64,
}

/// Everything the refit measures.
#[derive(Clone, Debug, PartialEq)]
pub struct FitReport {
    /// The refitted law: polynomial plus the over-drive boundary, clamped to [0, r_max].
    pub law: OpenLoopLaw,
    /// The polynomial fit and its error in r over the feasible points.
    pub fit: PolyFit,
    /// r̄ = r_max boundary (Eq. 159).
    pub overdrive: Boundary,
    /// r̄ = 0 boundary.
    pub underdrive: Boundary,
    /// ω_a error of [`FitReport::law`] at the feasible grid points.
    pub law_error: LawError,
    /// ω_a error of the thesis's printed law ([`OpenLoopLaw::thesis`]) at the same points.
    pub thesis_error: LawError,
}

/// Sweep `grid` with the n-harmonic IHB of `opts`, fit `form`, both
/// boundaries, and the ω_a errors. `progress` is called once per grid point.
///
/// # Errors
/// Bad grid, plant or options ([`IvtError::Input`], [`IvtError::EmptyGrid`],
/// [`IvtError::Plant`]); every grid point failing ([`IvtError::AllFailed`]);
/// fewer feasible points than terms; solver failures on a boundary or in the
/// ω_a check.
pub fn fit_law<P: Fn() + Sync>(
    plant: &PlantParams,
    grid: &Grid,
    form: PolyForm,
    opts: IhbOptions,
    progress: P,
) -> Result<FitReport, IvtError> {
    let pts = sweep::sweep(plant, grid, opts, progress)?;
    sweep::require_some_solved(&pts)?;
    let fit = fit::fit_polynomial(&pts, plant.r_max, form)?;
    let boundary = |r_target| {
        fit::fit_boundary(plant, &grid.t_u, grid.omega0, r_target, opts).map(
            |(alpha, beta, max_dev_v)| Boundary {
                alpha,
                beta,
                max_dev_v,
            },
        )
    };
    let overdrive = boundary(plant.r_max)?;
    let underdrive = boundary(0.0)?;
    let law = OpenLoopLaw {
        poly: fit.poly,
        boundary: [1.0, -overdrive.alpha, -overdrive.beta],
        r_max: plant.r_max,
    };
    let law_error = fit::law_error(plant, &law, &pts)?;
    let thesis_error = fit::law_error(plant, &OpenLoopLaw::thesis(), &pts)?;
    Ok(FitReport {
        law,
        fit,
        overdrive,
        underdrive,
        law_error,
        thesis_error,
    })
}
