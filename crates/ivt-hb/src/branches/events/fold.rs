//! The fold of a [`Family`] branch with the Floquet multipliers of the
//! located orbit: the path engine's [`Fold`] (the λ component of the secant
//! changes sign; Newton on Govaerts' minimally extended system,
//! [`ivt_path::events::locate_fold`]), then Hsu's monodromy there.

use super::multipliers::Monodromy;
use crate::branches::family::{Family, FamilyBranch};
use crate::orbit::ihb::HbError;
use ivt_path::events::{Bifurcation, BifurcationKind, Detector, Fold, PathSoFar, Start};
use ivt_path::PathError;

/// The [`Fold`] of a [`Family`] branch with the multipliers of the located
/// fold (Hsu, `LocateOptions::stability_steps`): the fold detector of
/// [`super::trace`] and of the frequency response.
#[derive(Debug, Clone, Copy, Default)]
pub struct FamilyFold;

impl<F: Family, E: From<HbError> + From<PathError>> Detector<FamilyBranch<F>, E> for FamilyFold {
    fn kind(&self) -> BifurcationKind {
        BifurcationKind::Fold
    }

    fn start(&self, path: &PathSoFar) -> Option<usize> {
        Fold::start(path)
    }

    fn test(&mut self, _branch: &mut FamilyBranch<F>, path: &PathSoFar, k: usize) -> f64 {
        Fold::test(path, k)
    }

    /// [`Fold`]'s location, then the multipliers there.
    fn locate(&mut self, at: Start<'_, FamilyBranch<F>>) -> Result<Bifurcation, E> {
        Fold::locate_with(at, |branch, q, lambda, opts| {
            let mut mono = Monodromy::new(branch, lambda, opts.stability_steps)?;
            Ok(mono.multipliers(branch, q, lambda))
        })
    }
}

#[cfg(test)]
mod tests;
