//! The events of harmonic-balance branches on the path engine's event
//! machinery (`ivt_path::events`, re-exported here: the [`Detector`] and
//! [`Observer`] traits, the [`observe`] driver, the [`Fold`] of any branch):
//! the Floquet multipliers of each point ([`Multipliers`], Hsu, Eq. 78–80,
//! a [`PointMultipliers`]), and the events that need them — period
//! doubling, Neimark–Sacker and branch point on a [`FamilyBranch`], and the
//! fold with its multipliers ([`FamilyFold`]). [`trace`] follows a branch
//! and runs them as the points arrive, as BifurcationKit does, instead of
//! searching the finished path.
//!
//! - fold ([`Fold`], [`FamilyFold`]): the λ component of the secant changes sign;
//! - period doubling ([`period_doubling`]): `Π(μᵢ + 1)` changes sign (a real μ
//!   crosses −1);
//! - Neimark–Sacker ([`neimark_sacker`]): `Πᵢ<ⱼ(μᵢμⱼ − 1)` changes sign with a
//!   complex pair present;
//! - branch point ([`branch_point`]): `det [[R_q, R_λ], [tᵀ]]` changes sign (it
//!   keeps its sign through a fold, where only `det R_q` does).
//!
//! `∂R/∂q` is the exact Galerkin Jacobian (Eq. 56); `∂R/∂λ` and the derivatives
//! of the test functions are central differences. Branch switching at the
//! located points is in [`crate::branches::switching`].

pub mod branch_point;
pub mod fold;
pub mod multipliers;
pub mod neimark_sacker;
pub mod period_doubling;
mod trace;

pub use branch_point::{locate_branch_point, BranchPoint};
pub use fold::FamilyFold;
pub use ivt_path::events::{
    dot, locate_fold, observe, Bifurcation, BifurcationKind, Detector, EventObserver, Fold,
    FoldLocation, LocateOptions, Observer, PathSoFar, PointMultipliers, Start, TracedPoint,
    Unlocated,
};
pub use multipliers::Multipliers;
pub use neimark_sacker::NeimarkSacker;
pub use period_doubling::PeriodDoubling;
pub use trace::{every_event, observer, trace, PathOptions, Trace, TraceOptions};

/// Adds to the reason of each unlocated `at` point the family's own error
/// where the family fails at its value (`fails(value, near)`): a curve's
/// residual turns a failing member into NaN, so the locator's reason alone
/// says only that the residual was not finite.
pub(crate) fn name_family_failures<T>(
    unlocated: &mut [Unlocated<T>],
    fails: impl Fn(f64, &T) -> Option<crate::HbError>,
) {
    for u in unlocated {
        if let Some(e) = u.value.and_then(|v| fails(v, &u.near)) {
            u.add_cause(format_args!("the family fails there: {e}"));
        }
    }
}

use crate::branches::family::{Family, FamilyBranch};
use crate::orbit::ihb::HbError;
use ivt_path::PathError;
use thiserror::Error;

/// An event of a harmonic-balance branch, with its location or why it
/// could not be located.
pub type Event = ivt_path::events::Event<BifurcationError>;

/// Errors of bifurcation location.
#[derive(Debug, Clone, Error, PartialEq)]
pub enum BifurcationError {
    /// Sizes, solves or Newton failures (with the residual history).
    #[error(transparent)]
    Hb(#[from] HbError),
    /// The Neimark–Sacker test converged to a real pair `μ, 1/μ`.
    #[error(
        "neutral saddle at λ = {lambda:?} (real multipliers μ and 1/μ), not a Neimark–Sacker point"
    )]
    NeutralSaddle {
        /// Where.
        lambda: f64,
    },
}

impl From<PathError> for BifurcationError {
    fn from(e: PathError) -> Self {
        Self::Hb(e.into())
    }
}

/// Locates the period doubling (multiplier −1) or Neimark–Sacker point (complex
/// pair on the unit circle) nearest the converged orbit `(q0, λ0)` of `branch`,
/// as the [`PeriodDoubling`] and [`NeimarkSacker`] detectors locate them.
///
/// # Errors
/// [`BifurcationError::Hb`] for another kind, sizes, a singular bordered or
/// extended system (with the history), non-convergence;
/// [`BifurcationError::NeutralSaddle`] when a Neimark–Sacker search ends on
/// a real pair `μ, 1/μ`.
pub fn locate_multiplier_crossing<F: Family>(
    branch: &mut FamilyBranch<F>,
    kind: BifurcationKind,
    q0: &[f64],
    lambda0: f64,
    opts: &LocateOptions,
) -> Result<Bifurcation, BifurcationError> {
    match kind {
        BifurcationKind::PeriodDoubling => {
            let matrix = (kind, period_doubling::shifted_monodromy as _);
            multipliers::locate_crossing(branch, matrix, q0, lambda0, opts)
        }
        BifurcationKind::NeimarkSacker => {
            neimark_sacker::locate_neimark_sacker(branch, (q0, lambda0), opts)
        }
        BifurcationKind::Fold | BifurcationKind::BranchPoint | BifurcationKind::Crossing => {
            Err(HbError::InvalidInput(
                "locate_multiplier_crossing takes period doubling or Neimark–Sacker".into(),
            )
            .into())
        }
    }
}
