//! Dense square solves for the bordered and extended systems of fold location and
//! limit cycles (faer LU with partial pivoting; sizes `m + 1` or `m + 2`, a few
//! solves per Newton step, so a fresh factorisation per call is fine).

use faer::linalg::solvers::Solve;
use faer::Mat;

/// Factors the row-major `n×n` matrix `a` and solves `A x = rhs` (or `Aᵀ x = rhs`
/// with `transpose`) in place. Returns `false` if the solution is not finite
/// (singular or poisoned matrix).
pub(crate) fn solve_dense(a: &[f64], n: usize, rhs: &mut [f64], transpose: bool) -> bool {
    debug_assert!(a.len() == n * n && rhs.len() == n);
    let mat = Mat::<f64>::from_fn(n, n, |i, j| a[i * n + j]);
    let lu = mat.partial_piv_lu();
    let mut x = Mat::<f64>::from_fn(n, 1, |i, _| rhs[i]);
    if transpose {
        lu.solve_transpose_in_place(&mut x);
    } else {
        lu.solve_in_place(&mut x);
    }
    for (i, r) in rhs.iter_mut().enumerate() {
        *r = x[(i, 0)];
    }
    rhs.iter().all(|v| v.is_finite())
}

/// Euclidean norm.
pub(crate) fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_and_transposed_solves_a_3x3() {
        // A = [[2, 1, 0], [0, 3, 1], [1, 0, 4]], x = (1, −1, 2): A x = (1, −1, 9),
        // Aᵀ x = (4, −2, 7).
        let a = [2.0, 1.0, 0.0, 0.0, 3.0, 1.0, 1.0, 0.0, 4.0];
        let mut b = [1.0, -1.0, 9.0];
        assert!(solve_dense(&a, 3, &mut b, false));
        let mut bt = [4.0, -2.0, 7.0];
        assert!(solve_dense(&a, 3, &mut bt, true));
        for (x, w) in b.iter().chain(&bt).zip([1.0, -1.0, 2.0, 1.0, -1.0, 2.0]) {
            assert!((x - w).abs() < 1e-14, "{b:?} {bt:?}");
        }
    }

    #[test]
    fn singular_matrix_is_reported() {
        let a = [1.0, 2.0, 2.0, 4.0];
        let mut b = [1.0, 1.0];
        assert!(!solve_dense(&a, 2, &mut b, false));
    }
}
