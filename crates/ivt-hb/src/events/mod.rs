//! Events on a branch `R(q, λ) = 0`: fold, period doubling, Neimark–Sacker and
//! branch point, each one file implementing one trait ([`Detector`]: a test
//! function at every accepted path point, and a locator — Newton on a
//! minimally extended system, Govaerts' bordering on [`ivt_num::BorderedLu`] —
//! started where the test changes sign), and the Floquet multipliers
//! ([`Multipliers`], Hsu, Eq. 78–80) as the observer that gives each point its
//! multipliers. [`trace`] follows a branch and runs them as the points arrive
//! ([`EventObserver`], an [`Observer`]), as BifurcationKit does, instead of
//! searching the finished path.
//!
//! - fold ([`fold`]): the λ component of the secant changes sign;
//! - period doubling ([`period_doubling`]): `Π(μᵢ + 1)` changes sign (a real μ
//!   crosses −1);
//! - Neimark–Sacker ([`neimark_sacker`]): `Πᵢ<ⱼ(μᵢμⱼ − 1)` changes sign with a
//!   complex pair present;
//! - branch point ([`branch_point`]): `det [[R_q, R_λ], [tᵀ]]` changes sign (it
//!   keeps its sign through a fold, where only `det R_q` does).
//!
//! `∂R/∂q` is the exact Galerkin Jacobian (Eq. 56); `∂R/∂λ` and the derivatives
//! of the test functions are central differences. Branch switching at the
//! located points is in [`crate::switching`].

pub mod branch_point;
mod detector;
pub(crate) mod extended;
pub mod fold;
pub mod multipliers;
pub mod neimark_sacker;
pub mod period_doubling;
mod trace;

pub use branch_point::{locate_branch_point, BranchPoint};
pub(crate) use detector::dot;
pub use detector::{
    Bifurcation, BifurcationError, BifurcationKind, Detector, Event, LocateOptions, Observer,
    PathSoFar, Start, TracedPoint,
};
pub use fold::{locate_fold, FamilyFold, Fold, FoldLocation};
pub use multipliers::{Multipliers, PointMultipliers};
pub use neimark_sacker::NeimarkSacker;
pub use period_doubling::PeriodDoubling;
pub use trace::{observe, trace, EventObserver, PathOptions, Trace, TraceOptions};

use crate::family::{Family, FamilyBranch};
use crate::ihb::HbError;

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
        BifurcationKind::Fold | BifurcationKind::BranchPoint => Err(HbError::InvalidInput(
            "locate_multiplier_crossing takes period doubling or Neimark–Sacker".into(),
        )
        .into()),
    }
}
