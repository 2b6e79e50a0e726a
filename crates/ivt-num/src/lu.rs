//! Dense LU with partial pivoting on faer, on caller-owned storage: the
//! factor, the permutation and faer's scratch are allocated once per problem
//! size, so a Newton or continuation loop that refactors and solves
//! allocates nothing (faer's `*_scratch` requirements + `MemStack`). The
//! scratch covers a solve with up to `n` right-hand sides, so the explicit
//! inverse ([`LuWorkspace::inverse_into`], `n` of them) allocates nothing
//! either.

use crate::vector::dot;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Conj, Mat, MatMut, MatRef, Par};

/// An `n × n` matrix factored in place, with its permutation and scratch.
pub struct LuWorkspace {
    /// The matrix to factor; after [`LuWorkspace::factor`] it holds `L` and `U`.
    pub mat: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    mem: MemBuffer,
    /// Scratch of the one-vector [`LuWorkspace::solve`].
    column: Vec<f64>,
    /// Sign of the determinant of the last factored matrix (NaN after a
    /// factorization that met a non-finite pivot).
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
            solve::solve_in_place_scratch::<usize, f64>(n, n, Par::Seq),
            solve::solve_transpose_in_place_scratch::<usize, f64>(n, n, Par::Seq),
        ]);
        Self {
            mat: Mat::zeros(n, n),
            perm: vec![0; n],
            perm_inv: vec![0; n],
            mem: MemBuffer::new(req),
            column: vec![0.0; n],
            det_sign: 1.0,
        }
    }

    /// Dimension n.
    pub fn dim(&self) -> usize {
        self.mat.nrows()
    }

    /// Copy the row-major `n × n` matrix `a` into [`LuWorkspace::mat`].
    ///
    /// # Errors
    /// An `a` shorter than `n²` (a caller's bug) fills the matrix with NaN,
    /// so the next [`LuWorkspace::factor`] reports `false`, instead of a panic.
    pub fn set_row_major(&mut self, a: &[f64]) {
        let n = self.dim();
        match a.get(..n * n) {
            Some(a) => self.mat.copy_from(MatRef::from_row_major_slice(a, n, n)),
            None => self.mat.fill(f64::NAN),
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
                self.det_sign = f64::NAN;
                return false;
            }
            sign *= u.signum();
            max_pivot = max_pivot.max(u.abs());
            min_pivot = min_pivot.min(u.abs());
        }
        self.det_sign = sign;
        n == 0 || min_pivot > max_pivot * f64::EPSILON * n as f64
    }

    /// Copy the row-major `n × n` matrix `a` into [`LuWorkspace::mat`] and
    /// factor it ([`LuWorkspace::factor`]).
    pub fn factor_row_major(&mut self, a: &[f64]) -> bool {
        self.set_row_major(a);
        self.factor()
    }

    /// Solve `A x = rhs` in place with the last factorization: the row
    /// permutation, then forward and back substitution by columns of the
    /// column-major factor (contiguous AXPYs). For one right-hand side at the
    /// sizes of a Newton or chord step this is several times faster than
    /// faer's blocked triangular solves, whose set-up dominates there
    /// (m = 83: ≈ 0.4 µs against ≈ 5 µs, measured, not asserted); the
    /// arithmetic is the same up to the order of the sums.
    ///
    /// # Errors
    /// An `rhs` shorter than `n` (a caller's bug) is filled with NaN instead
    /// of a panic.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        let n = self.dim();
        let Some(rhs) = leading(rhs, n) else { return };
        let (mat, y) = (&self.mat, &mut self.column);
        for (yi, &p) in y.iter_mut().zip(&self.perm) {
            *yi = rhs.get(p).copied().unwrap_or(f64::NAN);
        }
        // L y = P b, L unit lower triangular (below the diagonal of `mat`).
        for j in 0..n {
            let Some((head, tail)) = y.split_at_mut_checked(j + 1) else {
                break;
            };
            let yj = head.last().copied().unwrap_or(0.0);
            if yj != 0.0 {
                let col = mat.col_as_slice(j).get(j + 1..).unwrap_or_default();
                tail.iter_mut().zip(col).for_each(|(t, l)| *t -= l * yj);
            }
        }
        // U x = y, U upper triangular (on and above the diagonal).
        for j in (0..n).rev() {
            let col = mat.col_as_slice(j);
            let Some((head, tail)) = y.split_at_mut_checked(j) else {
                break;
            };
            let (Some(yj), Some(&ujj)) = (tail.first_mut(), col.get(j)) else {
                break;
            };
            let xj = *yj / ujj;
            *yj = xj;
            if xj != 0.0 {
                head.iter_mut().zip(col).for_each(|(h, u)| *h -= u * xj);
            }
        }
        rhs.iter_mut().zip(y.iter()).for_each(|(r, yi)| *r = *yi);
    }

    /// Solve `Aᵀ x = rhs` in place with the last factorization (left null
    /// vectors, bordered systems): `Uᵀ z = b`, `Lᵀ w = z`, `x = Pᵀ w`, each
    /// row of `Uᵀ`, `Lᵀ` a contiguous column of the factor (dot products),
    /// as [`LuWorkspace::solve`].
    ///
    /// # Errors
    /// As [`LuWorkspace::solve`]: a short `rhs` is filled with NaN.
    pub fn solve_transpose(&mut self, rhs: &mut [f64]) {
        let n = self.dim();
        let Some(rhs) = leading(rhs, n) else { return };
        let (mat, w) = (&self.mat, &mut self.column);
        for i in 0..n {
            let col = mat.col_as_slice(i);
            let Some((done, rest)) = w.split_at_mut_checked(i) else {
                break;
            };
            let (Some(wi), Some(&uii), Some(&bi)) = (rest.first_mut(), col.get(i), rhs.get(i))
            else {
                break;
            };
            // `dot` runs over the common length: the first i entries of col.
            *wi = (bi - dot(col, done)) / uii;
        }
        for i in (0..n).rev() {
            let col = mat.col_as_slice(i).get(i + 1..).unwrap_or_default();
            let Some((head, rest)) = w.split_at_mut_checked(i + 1) else {
                break;
            };
            if let Some(wi) = head.last_mut() {
                *wi -= dot(col, rest);
            }
        }
        for (wi, &p) in w.iter().zip(&self.perm) {
            if let Some(r) = rhs.get_mut(p) {
                *r = *wi;
            }
        }
    }

    /// Solve `A X = B` (or `Aᵀ X = B` with `transpose`) in place for the
    /// columns of `rhs` (`n × k`, `k ≤ n`).
    ///
    /// # Errors
    /// If `rhs` has not `n` rows or has more than `n` columns (a caller's
    /// bug: the scratch covers `n` columns), it is filled with NaN instead of
    /// a panic.
    pub fn solve_mat(&mut self, mut rhs: MatMut<'_, f64>, transpose: bool) {
        let n = self.dim();
        if rhs.nrows() != n || rhs.ncols() > n.max(1) {
            rhs.fill(f64::NAN);
            return;
        }
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
        let lu = self.mat.as_ref();
        let stack = MemStack::new(&mut self.mem);
        if transpose {
            solve::solve_transpose_in_place_with_conj(lu, lu, perm, Conj::No, rhs, Par::Seq, stack);
        } else {
            solve::solve_in_place_with_conj(lu, lu, perm, Conj::No, rhs, Par::Seq, stack);
        }
    }

    /// The inverse of the last factored matrix into the row-major `n × n`
    /// slice `out`, solved column by column from `A X = I` with the factor.
    /// Each column then has the small residual of a plain solve, so
    /// `‖A X − I‖` is at rounding level even for an ill-conditioned `A`: a
    /// quasi-Newton step `x − H r` with `H = X` behaves like a solve with `A`.
    /// (The product of triangular inverses bounds `‖X A − I‖` instead, and
    /// Broyden's parameter stepping stalls with it on a badly conditioned
    /// strongly nonlinear Duffing, ivt-hb's `strong_nonlinearity_up_to_eps_100`.)
    /// Returns `false` if an entry is not finite, or if `out` is shorter than
    /// `n²` (then filled with NaN).
    pub fn inverse_into(&mut self, out: &mut [f64]) -> bool {
        let n = self.dim();
        let Some(out) = out.get_mut(..n * n) else {
            out.fill(f64::NAN);
            return false;
        };
        out.fill(0.0);
        out.iter_mut().step_by(n + 1).for_each(|d| *d = 1.0);
        // Column-major storage of X is Xᵀ row-major: transpose in place.
        self.solve_mat(MatMut::from_column_major_slice_mut(out, n, n), false);
        for i in 0..n {
            for j in i + 1..n {
                out.swap(i * n + j, j * n + i);
            }
        }
        out.iter().all(|v| v.is_finite())
    }
}

/// The first `n` entries of a right-hand side, or None after filling a
/// shorter `rhs` with NaN (a caller's bug reported in the result, not a panic).
fn leading(rhs: &mut [f64], n: usize) -> Option<&mut [f64]> {
    if rhs.len() < n {
        rhs.fill(f64::NAN);
        return None;
    }
    rhs.get_mut(..n)
}

/// Inverse of the row-major `n × n` matrix `a`, row-major (set-up use: it
/// allocates its workspace). `None` if `a` is numerically singular.
pub fn inverse(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut lu = LuWorkspace::new(n);
    let mut inv = vec![0.0; n * n];
    (lu.factor_row_major(a) && lu.inverse_into(&mut inv)).then_some(inv)
}

/// Solves `A x = rhs` (or `Aᵀ x = rhs` with `transpose`) in place for the
/// row-major `n × n` matrix `a` (a one-off solve: it allocates its workspace;
/// for repeated solves keep a [`LuWorkspace`]). Near-singular pivots are
/// accepted, so it serves inverse iteration at a bifurcation; returns `false`
/// only if the solution is not finite (singular or poisoned matrix).
pub fn solve_once(a: &[f64], n: usize, rhs: &mut [f64], transpose: bool) -> bool {
    let mut lu = LuWorkspace::new(n);
    lu.factor_row_major(a);
    if transpose {
        lu.solve_transpose(rhs);
    } else {
        lu.solve(rhs);
    }
    rhs.iter().all(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `solve_once` and its transpose on a 3×3 with a known solution
    /// x = (1, −1, 2): A x = (1, −1, 9), Aᵀ x = (4, −2, 7); an exactly
    /// singular matrix gives `false`.
    #[test]
    fn one_off_solves() {
        let a = [2.0, 1.0, 0.0, 0.0, 3.0, 1.0, 1.0, 0.0, 4.0];
        let mut b = [1.0, -1.0, 9.0];
        assert!(solve_once(&a, 3, &mut b, false));
        let mut bt = [4.0, -2.0, 7.0];
        assert!(solve_once(&a, 3, &mut bt, true));
        for (x, w) in b.iter().chain(&bt).zip([1.0, -1.0, 2.0, 1.0, -1.0, 2.0]) {
            assert!((x - w).abs() < 1e-14, "{b:?} {bt:?}");
        }
        let mut s = [1.0, 1.0];
        assert!(!solve_once(&[1.0, 2.0, 2.0, 4.0], 2, &mut s, false));
    }

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

    /// `A = [[2, 1, 0], [0, 3, 1], [1, 0, 4]]`, `x = (1, −1, 2)`: `A x = (1, −1, 9)`
    /// and `Aᵀ x = (4, −2, 7)` (integer arithmetic), recovered to 1e-15 by
    /// `solve`, `solve_transpose` and a two-column `solve_mat`; the factor
    /// is reused for all of them.
    #[test]
    fn plain_transposed_and_multi_rhs_solves() {
        let a = [2.0, 1.0, 0.0, 0.0, 3.0, 1.0, 1.0, 0.0, 4.0];
        let mut lu = LuWorkspace::new(3);
        assert!(lu.factor_row_major(&a));
        let mut b = [1.0, -1.0, 9.0];
        lu.solve(&mut b);
        let mut bt = [4.0, -2.0, 7.0];
        lu.solve_transpose(&mut bt);
        let mut two = [1.0, -1.0, 9.0, 4.0, -2.0, 7.0];
        lu.solve_mat(MatMut::from_column_major_slice_mut(&mut two, 3, 2), true);
        let x = [1.0, -1.0, 2.0];
        for (got, want) in b.iter().chain(&bt).zip(x.iter().chain(&x)) {
            assert!((got - want).abs() < 1e-15, "{b:?} {bt:?}");
        }
        // Column 2 of `two` solved Aᵀ: x again; column 1 (A x as rhs of Aᵀ)
        // is checked by applying Aᵀ back.
        for (got, want) in two[3..].iter().zip(x) {
            assert!((got - want).abs() < 1e-15, "{two:?}");
        }
        for i in 0..3 {
            let back: f64 = (0..3).map(|k| a[k * 3 + i] * two[k]).sum();
            assert!((back - [1.0, -1.0, 9.0][i]).abs() < 1e-14, "{two:?}");
        }
    }
    /// The one-vector substitutions of `solve` and `solve_transpose` against
    /// faer's blocked solves of the same factor (`solve_mat`, the independent reference) on pivoting
    /// matrices of sizes 1–170 (the Newton/chord sizes of 1–4 DOF at n ≤ 20):
    /// equal to 1e-13 relative, and the residual `‖A x − b‖∞` at rounding
    /// level (≤ 1e-12·‖A‖·‖x‖).
    #[test]
    fn one_vector_substitution_equals_the_blocked_solve() {
        let mut next = crate::test_rng::uniform(0x2545_f491_4f6c_dd1du64);
        for n in [1, 2, 3, 7, 42, 83, 170] {
            // Small diagonal: partial pivoting must swap rows.
            let a: Vec<f64> = (0..n * n)
                .map(|k| next() + if k % (n + 1) == 0 { 1e-3 } else { 0.0 })
                .collect();
            let b: Vec<f64> = (0..n).map(|_| next()).collect();
            let mut lu = LuWorkspace::new(n);
            assert!(lu.factor_row_major(&a), "n = {n}");
            let norm_a = a.iter().fold(0.0f64, |m, v| m.max(v.abs())) * n as f64;
            for transpose in [false, true] {
                let mut x = b.clone();
                if transpose {
                    lu.solve_transpose(&mut x);
                } else {
                    lu.solve(&mut x);
                }
                let mut reference = b.clone();
                let col = MatMut::from_column_major_slice_mut(&mut reference, n, 1);
                lu.solve_mat(col, transpose);
                let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (got, want) in x.iter().zip(&reference) {
                    let err = (got - want).abs();
                    assert!(
                        err <= 1e-13 * scale,
                        "n = {n}, transpose {transpose}: {err:e}"
                    );
                }
                for i in 0..n {
                    let entry = |j: usize| {
                        if transpose {
                            a[j * n + i]
                        } else {
                            a[i * n + j]
                        }
                    };
                    let ax: f64 = (0..n).map(|j| entry(j) * x[j]).sum();
                    let err = (ax - b[i]).abs();
                    assert!(err <= 1e-12 * norm_a * scale, "n = {n}, row {i}: {err:e}");
                }
            }
        }
    }

    /// A caller's size bug is reported, not a panic: a short matrix makes
    /// `factor` fail, a short right-hand side or inverse comes back NaN /
    /// `false`, and a `solve_mat` of the wrong shape is NaN.
    #[test]
    fn wrong_sizes_are_nan_not_panics() {
        let mut lu = LuWorkspace::new(2);
        assert!(!lu.factor_row_major(&[1.0, 2.0, 3.0]));
        assert!(lu.factor_row_major(&[2.0, 0.0, 0.0, 4.0]));
        let mut short = [1.0];
        lu.solve(&mut short);
        assert!(short[0].is_nan());
        let mut short = [1.0];
        lu.solve_transpose(&mut short);
        assert!(short[0].is_nan());
        let mut out = [0.0; 3];
        assert!(!lu.inverse_into(&mut out));
        let mut three = [1.0; 3];
        lu.solve_mat(MatMut::from_column_major_slice_mut(&mut three, 3, 1), false);
        assert!(three.iter().all(|v| v.is_nan()));
        // A longer rhs: the first n entries are solved, the rest untouched.
        let mut long = [2.0, 4.0, 7.0];
        lu.solve(&mut long);
        assert_eq!(long, [1.0, 1.0, 7.0]); // diag(2, 4)⁻¹ (2, 4)
    }
}
