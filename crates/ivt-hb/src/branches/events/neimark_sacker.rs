//! Neimark–Sacker: a complex pair of Floquet multipliers through the unit
//! circle (Eq. 80). On a traced path the test `Re Πᵢ<ⱼ(μᵢμⱼ − 1)` changes sign
//! with a complex pair present at either point; the locator solves `R = 0`
//! with the bordered test function of `Φ⊙Φ − I`, `Φ⊙Φ` the second compound
//! (bialternate product) of the monodromy matrix, whose eigenvalues are the
//! products `μᵢμⱼ`, `i < j`. A real pair `μ, 1/μ` (neutral saddle) is also a
//! zero of that test and is reported as [`BifurcationError::NeutralSaddle`].

use super::multipliers::locate_crossing;
use super::BifurcationError;
use crate::branches::family::{Family, FamilyBranch};
use faer::c64;
use ivt_path::events::{
    Bifurcation, BifurcationKind, Detector, LocateOptions, PathSoFar, Start, TracedPoint,
};

/// `Φ⊙Φ − I` into `a`: rows and columns are the pairs `i < j`, entries the
/// 2×2 minors of Φ; returns its size `dim(dim − 1)/2`.
pub(crate) fn compound_minus_identity(phi: &[f64], dim: usize, a: &mut Vec<f64>) -> usize {
    a.clear();
    let at = |r: usize, c: usize| phi.get(r * dim + c).copied().unwrap_or(f64::NAN);
    let pairs: Vec<(usize, usize)> = (0..dim)
        .flat_map(|i| (i + 1..dim).map(move |j| (i, j)))
        .collect();
    let s = pairs.len();
    for &(i, j) in &pairs {
        for &(k, l) in &pairs {
            a.push(at(i, k) * at(j, l) - at(i, l) * at(j, k));
        }
    }
    a.iter_mut().step_by(s + 1).take(s).for_each(|d| *d -= 1.0);
    s
}

/// `Re Πᵢ<ⱼ(μᵢμⱼ − 1)`: changes sign when a pair's product crosses 1.
fn indicator(mu: &[c64]) -> f64 {
    let mut p = c64::new(1.0, 0.0);
    for (i, a) in mu.iter().enumerate() {
        for b in mu.iter().skip(i + 1) {
            p *= a * b - 1.0;
        }
    }
    p.re
}

/// Whether the point has a complex multiplier.
fn complex(p: &TracedPoint) -> bool {
    p.multipliers.iter().any(|z| z.im.abs() > 1e-7 * z.norm())
}

/// The Neimark–Sacker event of a traced path.
#[derive(Debug, Clone, Copy, Default)]
pub struct NeimarkSacker;

/// Locates the Neimark–Sacker point nearest the converged orbit `start =
/// (q0, λ0)`.
///
/// # Errors
/// [`BifurcationError::Hb`] for sizes, a singular bordered or extended
/// system (with the history), non-convergence;
/// [`BifurcationError::NeutralSaddle`] when the search ends on a real pair
/// `μ, 1/μ`.
pub(crate) fn locate_neimark_sacker<F: Family>(
    branch: &mut FamilyBranch<F>,
    (q0, lambda0): (&[f64], f64),
    opts: &LocateOptions,
) -> Result<Bifurcation, BifurcationError> {
    let kind = (BifurcationKind::NeimarkSacker, compound_minus_identity as _);
    let found = locate_crossing(branch, kind, q0, lambda0, opts)?;
    let on_circle = found
        .multipliers
        .iter()
        .any(|z| (z.norm() - 1.0).abs() < 1e-6 && z.im.abs() > 1e-6);
    if !on_circle {
        return Err(BifurcationError::NeutralSaddle {
            lambda: found.lambda,
        });
    }
    Ok(found)
}

impl<F: Family> Detector<FamilyBranch<F>, BifurcationError> for NeimarkSacker {
    fn kind(&self) -> BifurcationKind {
        BifurcationKind::NeimarkSacker
    }

    fn test(&mut self, _branch: &mut FamilyBranch<F>, path: &PathSoFar, k: usize) -> f64 {
        path.multipliers(k).map_or(f64::NAN, indicator)
    }

    /// The older of the two newest points, if either has a complex pair.
    fn start(&self, path: &PathSoFar) -> Option<usize> {
        let k = path.len().checked_sub(2)?;
        let pair = path.traced.get(k..)?;
        pair.iter().any(complex).then_some(k)
    }

    fn locate(&mut self, at: Start<'_, FamilyBranch<F>>) -> Result<Bifurcation, BifurcationError> {
        locate_neimark_sacker(at.branch, at.point()?, at.opts)
    }
}
