//! Small dense row-major matrices on nalgebra: products and inverses of the
//! `2·n_dof`-sized blocks of the Floquet steps and of the linear HB Jacobian,
//! where faer's per-call set-up (~0.1 µs for a 2×2 product, ~1 µs for a 2×2
//! LU, measured, not asserted) exceeds the arithmetic.
//!
//! nalgebra stores column-major, so a row-major `A` viewed in place is `Aᵀ`:
//! `C = A·B` is computed as `Cᵀ = Bᵀ·Aᵀ`, and `(Aᵀ)⁻¹ = (A⁻¹)ᵀ` is `A⁻¹`
//! row-major. Nothing is copied into nalgebra-owned storage.

use nalgebra::{DMatrixView, DMatrixViewMut};

/// `c = a·b` for row-major `dim × dim` matrices (no allocation).
///
/// # Panics
/// If a slice is shorter than `dim²`.
pub fn matmul(a: &[f64], b: &[f64], dim: usize, c: &mut [f64]) {
    let d2 = dim * dim;
    let at = DMatrixView::from_slice(&a[..d2], dim, dim);
    let bt = DMatrixView::from_slice(&b[..d2], dim, dim);
    DMatrixViewMut::from_slice(&mut c[..d2], dim, dim).gemm(1.0, &bt, &at, 0.0);
}

/// The inverse of the row-major `dim × dim` matrix `a` into `out`: closed
/// form (nalgebra's cofactor formulas) up to 4×4, faer's LU
/// ([`crate::lu::inverse`], which allocates its workspace) above. Returns
/// `false` if `a` is singular or the inverse is not finite.
///
/// # Panics
/// If a slice is shorter than `dim²`.
pub fn inverse_into(a: &[f64], dim: usize, out: &mut [f64]) -> bool {
    let d2 = dim * dim;
    if dim > 4 {
        return match crate::lu::inverse(&a[..d2], dim) {
            Some(inv) => {
                out[..d2].copy_from_slice(&inv);
                true
            }
            None => false,
        };
    }
    out[..d2].copy_from_slice(&a[..d2]);
    DMatrixViewMut::from_slice(&mut out[..d2], dim, dim).try_inverse_mut()
        && out[..d2].iter().all(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `[[1, 2], [3, 4]]² = [[7, 10], [15, 22]]` and a non-commuting
    /// product exactly; the inverse of the
    /// non-symmetric `[[4, 3], [6, 3]]` is `[[−½, ½], [1, −⅔]]` (det −6); a
    /// 5×5 (faer route) and a 3×3 (closed form) times their inverses give
    /// the identity to 1e-14; singular matrices are refused by both routes.
    #[test]
    fn products_and_inverses_in_row_major() {
        let a = [1.0, 2.0, 3.0, 4.0];
        let mut c = [0.0; 4];
        matmul(&a, &a, 2, &mut c);
        assert_eq!(c, [7.0, 10.0, 15.0, 22.0]);
        // [[1, 2], [3, 4]]·[[0, 1], [5, 2]] = [[10, 5], [20, 11]] (order matters).
        matmul(&a, &[0.0, 1.0, 5.0, 2.0], 2, &mut c);
        assert_eq!(c, [10.0, 5.0, 20.0, 11.0]);
        let mut inv = [0.0; 4];
        assert!(inverse_into(&[4.0, 3.0, 6.0, 3.0], 2, &mut inv));
        for (g, w) in inv.iter().zip([-0.5, 0.5, 1.0, -2.0 / 3.0]) {
            assert!((g - w).abs() < 1e-15, "{inv:?}");
        }
        for dim in [3usize, 5] {
            let m: Vec<f64> = (0..dim * dim)
                .map(|k| ((k * 7) % 11) as f64 + if k % (dim + 1) == 0 { 9.0 } else { 0.0 })
                .collect();
            let mut inv = vec![0.0; dim * dim];
            let mut prod = vec![0.0; dim * dim];
            assert!(inverse_into(&m, dim, &mut inv));
            matmul(&m, &inv, dim, &mut prod);
            for i in 0..dim {
                for j in 0..dim {
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((prod[i * dim + j] - want).abs() < 1e-14, "{dim}: {prod:?}");
                }
            }
            let mut singular = m.clone();
            let (first, rest) = singular.split_at_mut(dim);
            rest[..dim].copy_from_slice(first);
            assert!(!inverse_into(&singular, dim, &mut inv), "{dim}");
        }
    }
}
