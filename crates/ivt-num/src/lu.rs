//! Dense LU with partial pivoting on faer, on caller-owned storage: the
//! factor, the permutation and faer's scratch are allocated once per problem
//! size, so a Newton or continuation loop that refactors and solves
//! allocates nothing (faer's `*_scratch` requirements + `MemStack`).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, Mat, MatMut, Par};

/// An `n × n` matrix factored in place, with its permutation and scratch.
pub struct LuWorkspace {
    /// The matrix to factor; after [`LuWorkspace::factor`] it holds `L` and `U`.
    pub mat: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
    /// Sign of the determinant of the last factored matrix.
    pub det_sign: f64,
}

impl Clone for LuWorkspace {
    fn clone(&self) -> Self {
        let mut w = Self::new(self.dim());
        w.mat.clone_from(&self.mat);
        w.perm.clone_from(&self.perm);
        w.perm_inv.clone_from(&self.perm_inv);
        w.det_sign = self.det_sign;
        w
    }
}

impl core::fmt::Debug for LuWorkspace {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("LuWorkspace")
            .field("dim", &self.dim())
            .field("det_sign", &self.det_sign)
            .finish_non_exhaustive()
    }
}

impl LuWorkspace {
    /// Workspace for `n × n` matrices.
    pub fn new(n: usize) -> Self {
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()),
            solve::solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq),
        ]);
        Self {
            mat: Mat::zeros(n, n),
            perm: vec![0; n],
            perm_inv: vec![0; n],
            mem: MemBuffer::new(req),
            det_sign: 1.0,
        }
    }

    /// Dimension n.
    pub fn dim(&self) -> usize {
        self.mat.nrows()
    }

    /// Copy the row-major `n × n` matrix `a` into [`LuWorkspace::mat`].
    pub fn set_row_major(&mut self, a: &[f64]) {
        let n = self.dim();
        for i in 0..n {
            for j in 0..n {
                self.mat[(i, j)] = a[i * n + j];
            }
        }
    }

    /// Factor `self.mat` in place. Returns `false` if a pivot is not finite or
    /// below `n·ε` of the largest (singular or poisoned matrix); the factor
    /// is then unusable.
    pub fn factor(&mut self) -> bool {
        let (info, _) = factor::lu_in_place(
            self.mat.as_mut(),
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        let mut sign = if info.transposition_count % 2 == 0 {
            1.0
        } else {
            -1.0
        };
        let n = self.mat.nrows();
        let mut max_pivot: f64 = 0.0;
        let mut min_pivot = f64::INFINITY;
        for i in 0..n {
            let u = self.mat[(i, i)];
            if !u.is_finite() {
                return false;
            }
            sign *= u.signum();
            max_pivot = max_pivot.max(u.abs());
            min_pivot = min_pivot.min(u.abs());
        }
        self.det_sign = sign;
        n == 0 || min_pivot > max_pivot * f64::EPSILON * n as f64
    }

    /// Solve `A x = rhs` in place with the last factorization.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        let n = self.dim();
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
        let lu = self.mat.as_ref();
        solve::solve_in_place_with_conj(
            lu,
            lu,
            perm,
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}

/// Inverse of the row-major `n × n` matrix `a`, row-major (set-up use: it
/// allocates its workspace). `None` if `a` is numerically singular.
pub fn inverse(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut lu = LuWorkspace::new(n);
    lu.set_row_major(a);
    if !lu.factor() {
        return None;
    }
    // Solve for the columns of A⁻¹, then store them as rows of the transpose.
    let mut cols = vec![0.0; n * n];
    for (j, col) in cols.chunks_exact_mut(n.max(1)).enumerate() {
        col[j] = 1.0;
        lu.solve(col);
    }
    let inv: Vec<f64> = (0..n * n).map(|k| cols[(k % n) * n + k / n]).collect();
    inv.iter().all(|v| v.is_finite()).then_some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3×3 matrix that needs pivoting (zero leading entry): A·A⁻¹ = I to
    /// 1e-15, the determinant sign matches det = −5, and a singular matrix
    /// is refused.
    #[test]
    fn inverse_and_singularity() {
        let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let inv = inverse(&a, 3).expect("regular");
        for i in 0..3 {
            for j in 0..3 {
                let p: f64 = (0..3).map(|l| a[i * 3 + l] * inv[l * 3 + j]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((p - want).abs() < 1e-15, "({i},{j}): {p}");
            }
        }
        let mut lu = LuWorkspace::new(3);
        lu.set_row_major(&a);
        assert!(lu.factor());
        assert_eq!(lu.det_sign, -1.0);
        let singular = [1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0];
        assert!(inverse(&singular, 3).is_none());
    }
}
