//! Small dense row-major matrices on nalgebra: products of the
//! `2·n_dof`-sized matrices of the Floquet steps and the inverses of the
//! per-harmonic blocks of the linear HB operator, where faer's per-call
//! set-up (~0.1 µs for a 2×2 product, measured, not asserted) exceeds the
//! arithmetic.
//!
//! nalgebra stores column-major, so a row-major `A` viewed in place is `Aᵀ`:
//! `C = A·B` is computed as `Cᵀ = Bᵀ·Aᵀ`. Nothing is copied into
//! nalgebra-owned storage.

use nalgebra::{DMatrix, DMatrixView, DMatrixViewMut, SMatrix};

/// `c = a·b` for row-major `dim × dim` matrices (no allocation). Sizes 1–8
/// (the state sizes `2·n_dof` of systems up to 4 DOF) use a product of
/// compile-time size, which the compiler unrolls; larger ones nalgebra's gemm.
/// Only the leading `dim²` entries of each slice are used.
///
/// # Errors
/// A slice shorter than `dim²` is a caller's bug: `c` is filled with NaN,
/// which every finiteness check downstream (Floquet multipliers, residuals)
/// reports, instead of a panic.
pub fn matmul(a: &[f64], b: &[f64], dim: usize, c: &mut [f64]) {
    let d2 = dim * dim;
    let (Some(a), Some(b)) = (a.get(..d2), b.get(..d2)) else {
        c.fill(f64::NAN);
        return;
    };
    let Some(c) = c.get_mut(..d2) else {
        c.fill(f64::NAN);
        return;
    };
    match dim {
        1 => matmul_n::<1>(a, b, c),
        2 => matmul_n::<2>(a, b, c),
        3 => matmul_n::<3>(a, b, c),
        4 => matmul_n::<4>(a, b, c),
        5 => matmul_n::<5>(a, b, c),
        6 => matmul_n::<6>(a, b, c),
        7 => matmul_n::<7>(a, b, c),
        8 => matmul_n::<8>(a, b, c),
        _ => {
            let at = DMatrixView::from_slice(a, dim, dim);
            let bt = DMatrixView::from_slice(b, dim, dim);
            DMatrixViewMut::from_slice(c, dim, dim).gemm(1.0, &bt, &at, 0.0);
        }
    }
}

/// [`matmul`] for a compile-time size `N ≥ 1` on slices of `N²` entries,
/// for callers that know `N` (the Floquet steps of `2·n_dof ≤ 8` states call
/// it without [`matmul`]'s dispatch on the size).
///
/// # Errors
/// As [`matmul`]: a slice shorter than `N²` fills `c` with NaN.
pub fn matmul_n<const N: usize>(a: &[f64], b: &[f64], c: &mut [f64]) {
    // Re-sliced to the compile-time length N², so that the loops below unroll.
    let (Some(a), Some(b)) = (a.get(..N * N), b.get(..N * N)) else {
        return c.fill(f64::NAN);
    };
    let Some(c) = c.get_mut(..N * N) else {
        return c.fill(f64::NAN);
    };
    for (ci, ai) in c.chunks_exact_mut(N).zip(a.chunks_exact(N)) {
        ci.fill(0.0);
        for (&aik, bk) in ai.iter().zip(b.chunks_exact(N)) {
            for (cij, &bkj) in ci.iter_mut().zip(bk) {
                *cij += aik * bkj;
            }
        }
    }
}

/// `out = a⁻¹` for a row-major `dim × dim` matrix; `false` if `a` is singular
/// or the inverse is not finite. Sizes 1–4 use nalgebra's fixed-size inverse
/// on the stack (no allocation); larger sizes allocate (nalgebra's LU).
///
/// # Errors
/// `false` too if a slice is shorter than `dim²` (a caller's bug; `out` is
/// then filled with NaN), instead of a panic.
pub fn inverse(a: &[f64], dim: usize, out: &mut [f64]) -> bool {
    let d2 = dim * dim;
    let Some(a) = a.get(..d2) else {
        out.fill(f64::NAN);
        return false;
    };
    let Some(out) = out.get_mut(..d2) else {
        out.fill(f64::NAN);
        return false;
    };
    match dim {
        1 => inverse_fixed::<1>(a, out),
        2 => inverse_fixed::<2>(a, out),
        3 => inverse_fixed::<3>(a, out),
        4 => inverse_fixed::<4>(a, out),
        // Row-major `a` read column-major is `aᵀ`, and `(aᵀ)⁻¹ = (a⁻¹)ᵀ`
        // written column-major is `a⁻¹` row-major.
        _ => match DMatrix::from_column_slice(dim, dim, a).try_inverse() {
            Some(inv) => {
                out.copy_from_slice(inv.as_slice());
                out.iter().all(|v| v.is_finite())
            }
            None => false,
        },
    }
}

/// [`inverse`] for a compile-time size `N` (stack storage) on slices of `N²`
/// entries.
fn inverse_fixed<const N: usize>(a: &[f64], out: &mut [f64]) -> bool {
    // As in [`inverse`]: the transpose's inverse, read back column-major.
    match SMatrix::<f64, N, N>::from_column_slice(a).try_inverse() {
        Some(inv) => {
            out.copy_from_slice(inv.as_slice());
            out.iter().all(|v| v.is_finite())
        }
        None => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The product of every size (1–8 fixed, 9 and 10 through gemm) equals the
    /// textbook triple loop on non-symmetric matrices (a transposed operand
    /// would not) to 1e-15 relative.
    #[test]
    fn products_of_every_size() {
        for dim in 1..=10 {
            let a: Vec<f64> = (0..dim * dim)
                .map(|k| ((k * 7 + 3) % 11) as f64 - 5.0)
                .collect();
            let b: Vec<f64> = (0..dim * dim)
                .map(|k| ((k * 5 + 1) % 13) as f64 * 0.5 - 3.0)
                .collect();
            let mut c = vec![0.0; dim * dim];
            matmul(&a, &b, dim, &mut c);
            for i in 0..dim {
                for j in 0..dim {
                    let want: f64 = (0..dim).map(|k| a[i * dim + k] * b[k * dim + j]).sum();
                    assert!(
                        (c[i * dim + j] - want).abs() <= 1e-15 * want.abs().max(1.0),
                        "{dim}"
                    );
                }
            }
        }
    }

    /// `A·A⁻¹ = I` to 1e-14 for every size of both paths (1–4 on the stack,
    /// 5 and 6 dynamic) on a diagonally dominant non-symmetric matrix (a
    /// transposed read would fail the product), and a singular matrix refused.
    #[test]
    fn inverses_of_every_size() {
        for dim in 1..=6 {
            let a: Vec<f64> = (0..dim * dim)
                .map(|k| {
                    if k % (dim + 1) == 0 {
                        4.0 + k as f64
                    } else {
                        ((k * 7) % 5) as f64 - 2.0
                    }
                })
                .collect();
            let mut inv = vec![0.0; dim * dim];
            assert!(inverse(&a, dim, &mut inv), "dim {dim}");
            for i in 0..dim {
                for j in 0..dim {
                    let p: f64 = (0..dim).map(|l| a[i * dim + l] * inv[l * dim + j]).sum();
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((p - want).abs() < 1e-14, "dim {dim} ({i},{j}): {p}");
                }
            }
        }
        let mut out = [0.0; 4];
        assert!(!inverse(&[1.0, 2.0, 2.0, 4.0], 2, &mut out));
    }

    /// `[[1, 2], [3, 4]]² = [[7, 10], [15, 22]]` and a non-commuting
    /// product, exactly (integer arithmetic); a 3×3 product against the
    /// triple loop.
    #[test]
    fn products_in_row_major() {
        let a = [1.0, 2.0, 3.0, 4.0];
        let mut c = [0.0; 4];
        matmul(&a, &a, 2, &mut c);
        assert_eq!(c, [7.0, 10.0, 15.0, 22.0]);
        // [[1, 2], [3, 4]]·[[0, 1], [5, 2]] = [[10, 5], [20, 11]] (order matters).
        matmul(&a, &[0.0, 1.0, 5.0, 2.0], 2, &mut c);
        assert_eq!(c, [10.0, 5.0, 20.0, 11.0]);
        let p: Vec<f64> = (0..9).map(|k| ((k * 7) % 11) as f64 - 4.0).collect();
        let q: Vec<f64> = (0..9).map(|k| ((k * 5) % 7) as f64 - 3.0).collect();
        let mut pq = [0.0; 9];
        matmul(&p, &q, 3, &mut pq);
        for i in 0..3 {
            for j in 0..3 {
                let want: f64 = (0..3).map(|l| p[i * 3 + l] * q[l * 3 + j]).sum();
                assert_eq!(pq[i * 3 + j], want, "({i},{j})");
            }
        }
    }

    /// Slices shorter than dim² are reported (NaN product, `false` inverse)
    /// instead of a panic.
    #[test]
    fn short_slices_are_reported() {
        let mut c = [0.0; 4];
        matmul(&[1.0; 3], &[1.0; 4], 2, &mut c);
        assert!(c.iter().all(|v| v.is_nan()));
        let mut out = [0.0; 4];
        assert!(!inverse(&[1.0; 3], 2, &mut out));
        assert!(out.iter().all(|v| v.is_nan()));
        assert!(!inverse(&[1.0, 0.0, 0.0, 1.0], 2, &mut [0.0; 3]));
    }
}
