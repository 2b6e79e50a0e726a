//! Dense LU with partial pivoting on caller-owned storage: the factor, the
//! permutation and faer's scratch are allocated once per problem size, so
//! Newton iterations allocate nothing.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, Mat, MatMut, Par};

/// An `n × n` matrix factored in place, with its permutation and scratch.
pub(crate) struct LuWorkspace {
    /// The matrix to factor; after [`LuWorkspace::factor`] it holds `L` and `U`.
    pub(crate) mat: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
    /// Sign of the determinant of the last factored matrix.
    pub(crate) det_sign: f64,
}

impl LuWorkspace {
    pub(crate) fn new(n: usize) -> Self {
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

    /// Factor `self.mat` in place. Returns `false` if a pivot is zero or not
    /// finite (singular or poisoned matrix); the factor is then unusable.
    pub(crate) fn factor(&mut self) -> bool {
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
    pub(crate) fn solve(&mut self, rhs: &mut [f64]) {
        let n = self.mat.nrows();
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
