//! Level-1/2 kernels on slices (dot, norm, axpy, row-major matrix–vector
//! product) for the quasi-Newton and continuation loops, where vectors of a
//! few dozen entries are updated many times per solve and a call into a
//! dense-matrix library costs more than the arithmetic.

/// Independent partial sums in [`dot`]: enough to hide the add latency and let the
/// compiler use SIMD lanes (a single running sum serialises every addition).
const LANES: usize = 8;

/// Dot product over the common length, summed in `LANES` interleaved partial sums
/// (a different, not less accurate, rounding order than a left-to-right sum).
#[inline]
pub fn dot(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len().min(y.len());
    let (x, y) = (x.get(..n).unwrap_or(x), y.get(..n).unwrap_or(y));
    let mut acc = [0.0; LANES];
    let ((xc, xr), (yc, yr)) = (x.as_chunks::<LANES>(), y.as_chunks::<LANES>());
    let tail: f64 = xr.iter().zip(yr).map(|(a, b)| a * b).sum();
    for (a, b) in xc.iter().zip(yc) {
        for ((s, a), b) in acc.iter_mut().zip(a).zip(b) {
            *s += a * b;
        }
    }
    acc.iter().sum::<f64>() + tail
}

/// Euclidean norm.
#[inline]
pub fn norm2(x: &[f64]) -> f64 {
    dot(x, x).sqrt()
}

/// `y ← y + alpha·x` over the common length.
#[inline]
pub fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}

/// `y = A x` for row-major `A` (`rows×cols`), over the first `rows` entries
/// of `y` and the whole rows `A` has (`cols = 0`: empty sums, `y = 0`).
#[inline]
pub fn matvec(a: &[f64], rows: usize, cols: usize, x: &[f64], y: &mut [f64]) {
    if cols == 0 {
        y.iter_mut().take(rows).for_each(|v| *v = 0.0);
        return;
    }
    for (yi, row) in y.iter_mut().take(rows).zip(a.chunks_exact(cols)) {
        *yi = dot(row, x);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lane_split_dot_matches_the_plain_sum_at_every_length() {
        // Lengths 0…20 cover empty, tail-only, whole chunks and chunk + tail; the
        // integer-valued data make every partial sum exact, so equality is exact.
        for n in 0usize..=20 {
            let x: Vec<f64> = (0..n).map(|i| (i % 5) as f64 - 2.0).collect();
            let y: Vec<f64> = (0..n).map(|i| (i * 3 % 7) as f64).collect();
            let plain: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
            assert_eq!(dot(&x, &y), plain, "n = {n}");
            assert_eq!(
                dot(&x, &y[..n.saturating_sub(1)]),
                dot(&x[..n.saturating_sub(1)], &y)
            );
        }
        let mut y = vec![1.0; 9];
        axpy(2.0, &[1.0; 9], &mut y);
        assert!(y.iter().all(|&v| v == 3.0));
    }

    #[test]
    fn row_major_product_and_norm() {
        // [[1, 2, 3], [4, 5, 6]] (1, 0, −1) = (−2, −2); ‖(3, 4)‖ = 5 (exact).
        let mut y = [0.0; 2];
        matvec(
            &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            2,
            3,
            &[1.0, 0.0, -1.0],
            &mut y,
        );
        assert_eq!(y, [-2.0, -2.0]);
        assert_eq!(norm2(&[3.0, 4.0]), 5.0);
        // No columns: empty sums; y beyond `rows` untouched.
        let mut y = [1.0; 3];
        matvec(&[], 2, 0, &[], &mut y);
        assert_eq!(y, [0.0, 0.0, 1.0]);
    }
}
