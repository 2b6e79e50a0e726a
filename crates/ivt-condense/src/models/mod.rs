//! Structural test models with local nonlinearity (issue 28): an
//! Euler–Bernoulli cantilever of Hermite-cubic elements, pyHarm's lumped
//! bladed disk and (issue 42) a solid plate of linear tetrahedra. Each is a [`SparseModel`]: sparse `M`, `C`, `K`, the DOF the
//! nonlinear element and the force act on. The tests and the benches of
//! [`crate`] use them; Python exposes the cantilever as
//! `ivt.hb.models.cantilever`.

mod bladed_disk;
mod cantilever;
mod plate;

pub use bladed_disk::{bladed_disk, bladed_disk_mistuned, BladedDisk, SECTORS};
pub use cantilever::{cantilever, element_dofs, BeamProperties, Cantilever};
pub use plate::{plate, Plate, SolidProperties};

use faer::sparse::{SparseColMat, Triplet};
use ivt_hb::HbError;

/// Sparse mass, damping and stiffness of a linear structure (`n_dof × n_dof`,
/// column-compressed; duplicates of the assembly summed).
#[derive(Debug, Clone)]
pub struct SparseModel {
    /// Mass matrix `M`.
    pub m: SparseColMat<usize, f64>,
    /// Damping matrix `C`.
    pub c: SparseColMat<usize, f64>,
    /// Stiffness matrix `K`.
    pub k: SparseColMat<usize, f64>,
}

impl SparseModel {
    /// Number of DOFs.
    pub fn n_dof(&self) -> usize {
        self.m.nrows()
    }

    /// `(row, col, value)` triplets of `M`, `C` and `K` (column by column).
    pub fn triplets(&self) -> [Vec<(usize, usize, f64)>; 3] {
        [&self.m, &self.c, &self.k].map(|a| {
            (0..a.ncols())
                .flat_map(|j| {
                    let rows = a.symbolic().row_idx_of_col_raw(j);
                    rows.iter()
                        .zip(a.val_of_col(j))
                        .map(move |(&i, &v)| (i, j, v))
                })
                .collect()
        })
    }
}

/// A sparse matrix from `(row, col, value)` triplets (duplicates summed).
pub(crate) fn from_triplets(
    n: usize,
    entries: &[(usize, usize, f64)],
) -> Result<SparseColMat<usize, f64>, HbError> {
    let triplets: Vec<Triplet<usize, usize, f64>> = entries
        .iter()
        .map(|&(row, col, val)| Triplet { row, col, val })
        .collect();
    SparseColMat::try_new_from_triplets(n, n, &triplets)
        .map_err(|e| HbError::InvalidInput(format!("sparse assembly failed: {e:?}")))
}
