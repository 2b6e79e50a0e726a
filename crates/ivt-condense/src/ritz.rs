//! The reduced basis of the condensed stability analysis: load-dependent
//! Ritz vectors of the nonlinear DOFs `S` (Wilson, Yuan & Dickens, *Dynamic
//! analysis by direct superposition of Ritz vectors*, 1982), the block
//! Krylov space of `K⁻¹M` started from the static modes `K⁻¹E_S`,
//! M-orthonormal, and the structure's matrices projected onto its leading
//! vectors (the Galerkin projection of Eq. 78's linear part).
//!
//! The spaces of successive blocks are nested. When a block adds nothing
//! (every new vector is rounding), the basis spans an invariant subspace of
//! `K⁻¹M` holding `K⁻¹E_S`; if `K⁻¹C` maps it into itself too (checked: its
//! part outside is measured), the rest of the structure is M-, C- and
//! K-orthogonal to it and zero at `S`, so it is uncoupled from the orbit and
//! the basis truncation costs nothing but that measured part.

use super::dynamic::{Factored, Part, Structure};
use faer::{c64, Mat};
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::HbError;
use ivt_num::vector::dot;

/// A new vector that keeps at most this part of its M-norm after
/// orthogonalization is rounding, and dropped.
const DROP: f64 = 1e-10;

/// The structure's linear part on the first `size` basis vectors.
#[derive(Debug, Clone)]
pub(super) struct Reduced {
    pub(super) size: usize,
    /// `VᵀMV`, `VᵀCV`, `VᵀKV` plus the local problem's own matrices
    /// (`V_Sᵀ M_l V_S`, …), row-major `size×size`.
    pub(super) m: Vec<f64>,
    pub(super) c: Vec<f64>,
    pub(super) k: Vec<f64>,
    /// `V_S` (rows `S` of `V`), row-major `s×size`.
    pub(super) at_dofs: Vec<f64>,
    /// `V_Sᵀ (V_S V_Sᵀ)⁻¹`, row-major `size×s`: the reduced coordinates of
    /// least norm with `V_S z = x_S`.
    pub(super) lift: Vec<f64>,
}

/// The Ritz basis of `S` up to a cap on its blocks, projected.
#[derive(Debug, Clone)]
pub(super) struct RitzBasis {
    /// `VᵀMV`, `VᵀCV`, `VᵀKV`, `V_S` of the whole basis (no local part, no lift).
    whole: Reduced,
    /// Basis size after each block.
    sizes: Vec<usize>,
    /// `Some(part)` when the basis closed an invariant subspace: the
    /// relative part of `K⁻¹M V` and `K⁻¹C V` outside it (module docs).
    invariant: Option<f64>,
}

impl RitzBasis {
    /// At most `max_blocks` blocks for the DOFs `dofs` of `structure`.
    ///
    /// # Errors
    /// [`HbError::Singular`] (ω = 0) for a singular `K`.
    pub(super) fn new(
        structure: &Structure,
        dofs: &[usize],
        max_blocks: usize,
    ) -> Result<Self, HbError> {
        let n = structure.n_dof();
        let factored = structure.factor(0.0)?;
        let units: Vec<Vec<f64>> = dofs
            .iter()
            .map(|&d| (0..n).map(|i| if i == d { 1.0 } else { 0.0 }).collect())
            .collect();
        let mut block = static_solve(structure, &factored, &units)?;
        let mut basis: Vec<Vec<f64>> = Vec::new();
        let mut mass_basis: Vec<Vec<f64>> = Vec::new();
        let mut sizes = Vec::with_capacity(max_blocks);
        let mut closed = false;
        for _ in 0..max_blocks {
            let start = basis.len();
            for v in block {
                if let Some((v, mv)) = orthonormal(structure, &basis, &mass_basis, v) {
                    basis.push(v);
                    mass_basis.push(mv);
                }
            }
            if basis.len() == start {
                closed = true;
                break;
            }
            sizes.push(basis.len());
            block = static_solve(
                structure,
                &factored,
                mass_basis.get(start..).unwrap_or_default(),
            )?;
        }
        // A basis of all DOFs is invariant whatever its last block did.
        closed |= basis.len() == n;
        let invariant = if closed {
            Some(outside_part(structure, &factored, &basis, &mass_basis)?)
        } else {
            None
        };
        Ok(Self {
            whole: project(structure, &basis, dofs),
            sizes,
            invariant,
        })
    }

    /// Blocks held.
    pub(super) fn blocks(&self) -> usize {
        self.sizes.len()
    }

    /// The part outside of the invariant subspace the whole basis spans,
    /// at least the [`DROP`] threshold that closed it (`None`: not
    /// invariant).
    pub(super) fn invariant(&self) -> Option<f64> {
        self.invariant.map(|part| part.max(DROP))
    }

    /// The reduced problem of the first `blocks` blocks with `local`'s own
    /// matrices added.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for a block count not held or a basis that
    /// does not reach every nonlinear DOF.
    pub(super) fn reduced<P: PeriodicProblem>(
        &self,
        blocks: usize,
        s: usize,
        local: &P,
    ) -> Result<Reduced, HbError> {
        let size = blocks
            .checked_sub(1)
            .and_then(|b| self.sizes.get(b))
            .copied()
            .ok_or_else(|| {
                HbError::InvalidInput(format!(
                    "the stability basis has {} blocks, not {blocks}",
                    self.sizes.len()
                ))
            })?;
        truncate(&self.whole, size, s, local)
    }
}

/// `K⁻¹ columns` (real parts of the refined complex solve at ω = 0).
fn static_solve(
    structure: &Structure,
    factored: &Factored,
    columns: &[Vec<f64>],
) -> Result<Vec<Vec<f64>>, HbError> {
    let n = structure.n_dof();
    let mut rhs = Mat::<c64>::from_fn(n, columns.len(), |i, j| {
        c64::new(columns.get(j).map_or(0.0, |c| at(c, i)), 0.0)
    });
    let error = structure.solve_refined(factored, rhs.as_mut());
    if !error.is_finite() {
        return Err(HbError::Singular { omega: 0.0 });
    }
    Ok((0..columns.len())
        .map(|j| (0..n).map(|i| rhs[(i, j)].re).collect())
        .collect())
}

/// `v` M-orthogonalized against `basis` (Gram–Schmidt twice) and
/// M-normalized, with `Mv`; `None` when it keeps at most [`DROP`] of its
/// M-norm (NaN, an indefinite M, too).
fn orthonormal(
    structure: &Structure,
    basis: &[Vec<f64>],
    mass_basis: &[Vec<f64>],
    mut v: Vec<f64>,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let mut mv = vec![0.0; v.len()];
    structure.times(Part::Mass, &v, &mut mv);
    let before = dot(&v, &mv).sqrt();
    orthogonalize(basis, mass_basis, &mut v);
    structure.times(Part::Mass, &v, &mut mv);
    let norm = dot(&v, &mv).sqrt();
    if norm > DROP * before {
        v.iter_mut().for_each(|x| *x /= norm);
        mv.iter_mut().for_each(|x| *x /= norm);
        Some((v, mv))
    } else {
        None
    }
}

/// `v` minus its M-projection on the M-orthonormal `basis` (`mass_basis`
/// = `M basis`), classical Gram–Schmidt twice.
fn orthogonalize(basis: &[Vec<f64>], mass_basis: &[Vec<f64>], v: &mut [f64]) {
    for _ in 0..2 {
        for (b, mb) in basis.iter().zip(mass_basis) {
            let c = dot(mb, v);
            v.iter_mut().zip(b).for_each(|(x, y)| *x -= c * y);
        }
    }
}

/// The largest relative M-norm of the part of `K⁻¹M v` and `K⁻¹C v`
/// (`v` in `basis`) M-orthogonal to `basis`; infinity for a non-finite one.
fn outside_part(
    structure: &Structure,
    factored: &Factored,
    basis: &[Vec<f64>],
    mass_basis: &[Vec<f64>],
) -> Result<f64, HbError> {
    let n = structure.n_dof();
    let mut mw = vec![0.0; n];
    let mut worst = 0.0f64;
    for part in [Part::Mass, Part::Damping] {
        let images: Vec<Vec<f64>> = basis
            .iter()
            .map(|v| {
                let mut image = vec![0.0; n];
                structure.times(part, v, &mut image);
                image
            })
            .collect();
        for mut w in static_solve(structure, factored, &images)? {
            structure.times(Part::Mass, &w, &mut mw);
            let before = dot(&w, &mw).sqrt();
            orthogonalize(basis, mass_basis, &mut w);
            structure.times(Part::Mass, &w, &mut mw);
            let after = dot(&w, &mw).sqrt();
            // A zero image (C = 0) is inside.
            let part = if before > 0.0 { after / before } else { 0.0 };
            worst = if part.is_finite() {
                worst.max(part)
            } else {
                f64::INFINITY
            };
        }
    }
    Ok(worst)
}

/// `VᵀMV`, `VᵀCV`, `VᵀKV` and `V_S` of the whole basis.
fn project(structure: &Structure, basis: &[Vec<f64>], dofs: &[usize]) -> Reduced {
    let r = basis.len();
    let mut product = vec![0.0; structure.n_dof()];
    let mut project = |part: Part| {
        let mut out = vec![0.0; r * r];
        for (j, v) in basis.iter().enumerate() {
            structure.times(part, v, &mut product);
            for (i, u) in basis.iter().enumerate() {
                if let Some(e) = out.get_mut(i * r + j) {
                    *e = dot(u, &product);
                }
            }
        }
        out
    };
    let (m, c, k) = (
        project(Part::Mass),
        project(Part::Damping),
        project(Part::Stiffness),
    );
    let at_dofs: Vec<f64> = dofs
        .iter()
        .flat_map(|&d| basis.iter().map(move |v| at(v, d)))
        .collect();
    Reduced {
        size: r,
        m,
        c,
        k,
        at_dofs,
        lift: Vec::new(),
    }
}

/// The leading `size` basis vectors of `whole` (its matrices' leading
/// blocks), with the local problem's own matrices added and the lift.
fn truncate<P: PeriodicProblem>(
    whole: &Reduced,
    size: usize,
    s: usize,
    local: &P,
) -> Result<Reduced, HbError> {
    let r = whole.size;
    let lead = |a: &[f64]| -> Vec<f64> {
        (0..size * size)
            .map(|e| at(a, (e / size) * r + e % size))
            .collect()
    };
    let at_dofs: Vec<f64> = (0..s * size)
        .map(|e| at(&whole.at_dofs, (e / size) * r + e % size))
        .collect();
    let (mut m, mut c, mut k) = (lead(&whole.m), lead(&whole.c), lead(&whole.k));
    // V_Sᵀ A_l V_S of the local problem's matrices.
    for (out, a) in [
        (&mut m, local.mass()),
        (&mut c, local.damping()),
        (&mut k, local.stiffness()),
    ] {
        for i in 0..size {
            for j in 0..size {
                let mut sum = 0.0;
                for x in 0..s {
                    for y in 0..s {
                        sum += at(&at_dofs, x * size + i)
                            * at(a, x * s + y)
                            * at(&at_dofs, y * size + j);
                    }
                }
                if let Some(e) = out.get_mut(i * size + j) {
                    *e += sum;
                }
            }
        }
    }
    // (V_S V_Sᵀ)⁻¹: V_S has full row rank, the static modes of S being in
    // the basis.
    let gram: Vec<f64> = (0..s * s)
        .map(|e| {
            let (a, b) = (e / s, e % s);
            dot(row(&at_dofs, a, size), row(&at_dofs, b, size))
        })
        .collect();
    let inverse = ivt_num::lu::inverse(&gram, s).ok_or_else(|| {
        HbError::InvalidInput("the stability basis does not reach the nonlinear DOFs".into())
    })?;
    let lift = (0..size * s)
        .map(|e| {
            let (i, a) = (e / s, e % s);
            (0..s)
                .map(|b| at(&at_dofs, b * size + i) * at(&inverse, b * s + a))
                .sum()
        })
        .collect();
    Ok(Reduced {
        size,
        m,
        c,
        k,
        at_dofs,
        lift,
    })
}

/// `v[i]`, or 0 past the end.
pub(super) fn at(v: &[f64], i: usize) -> f64 {
    v.get(i).copied().unwrap_or(0.0)
}

/// Row `i` of the row-major `v` with rows of `len` (empty past the end).
pub(super) fn row(v: &[f64], i: usize, len: usize) -> &[f64] {
    v.get(i * len..(i + 1) * len).unwrap_or_default()
}
