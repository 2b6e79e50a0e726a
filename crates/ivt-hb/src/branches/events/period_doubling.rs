//! Period doubling: a real Floquet multiplier through −1 (Eq. 80). On a
//! traced path the test `Re Π(μᵢ + 1)` of the points' multipliers changes
//! sign; the locator solves `R = 0` with the bordered test function of
//! `Φ + I` (Φ the monodromy matrix), singular exactly at the crossing.

use super::multipliers::locate_crossing;
use super::BifurcationError;
use crate::branches::family::{Family, FamilyBranch};
use faer::c64;
use ivt_path::events::{Bifurcation, BifurcationKind, Detector, PathSoFar, Start};

/// `Φ + I` into `a`; returns its size `dim`.
pub(crate) fn shifted_monodromy(phi: &[f64], dim: usize, a: &mut Vec<f64>) -> usize {
    a.clear();
    a.extend_from_slice(phi);
    a.iter_mut()
        .step_by(dim + 1)
        .take(dim)
        .for_each(|d| *d += 1.0);
    dim
}

/// `Re Π(μᵢ + 1)`: changes sign when a real multiplier crosses −1.
fn indicator(mu: &[c64]) -> f64 {
    mu.iter().fold(c64::new(1.0, 0.0), |a, z| a * (z + 1.0)).re
}

/// The period-doubling event of a traced path.
#[derive(Debug, Clone, Copy, Default)]
pub struct PeriodDoubling;

impl<F: Family> Detector<FamilyBranch<F>, BifurcationError> for PeriodDoubling {
    fn kind(&self) -> BifurcationKind {
        BifurcationKind::PeriodDoubling
    }

    fn test(&mut self, _branch: &mut FamilyBranch<F>, path: &PathSoFar, k: usize) -> f64 {
        path.multipliers(k).map_or(f64::NAN, indicator)
    }

    fn locate(&mut self, at: Start<'_, FamilyBranch<F>>) -> Result<Bifurcation, BifurcationError> {
        let (q, lambda) = at.point()?;
        let kind = (BifurcationKind::PeriodDoubling, shifted_monodromy as _);
        locate_crossing(at.branch, kind, q, lambda, at.opts)
    }
}
