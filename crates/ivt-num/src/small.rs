//! Small dense row-major matrices on nalgebra: products of the
//! `2·n_dof`-sized matrices of the Floquet steps, where faer's per-call
//! set-up (~0.1 µs for a 2×2 product, measured, not asserted) exceeds the
//! arithmetic.
//!
//! nalgebra stores column-major, so a row-major `A` viewed in place is `Aᵀ`:
//! `C = A·B` is computed as `Cᵀ = Bᵀ·Aᵀ`. Nothing is copied into
//! nalgebra-owned storage.

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
