//! Small dense row-major linear algebra that allocates nothing: LU with partial
//! pivoting, solve and inverse. Used inside the Broyden/Newton loops where faer's
//! allocating front end would break the "no allocation per iteration" rule.

/// A matrix is numerically singular (zero pivot or a non-finite entry).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Singular;

/// LU factorisation in place (row-major `m×m`), partial pivoting; `piv[i]` is the
/// row swapped into position `i`.
///
/// # Errors
/// [`Singular`] if a pivot is zero or not finite.
pub fn lu_factor(a: &mut [f64], m: usize, piv: &mut [usize]) -> Result<(), Singular> {
    debug_assert!(a.len() >= m * m && piv.len() >= m);
    for k in 0..m {
        let mut p = k;
        let mut best = a[k * m + k].abs();
        for i in k + 1..m {
            let v = a[i * m + k].abs();
            if v > best {
                best = v;
                p = i;
            }
        }
        if best == 0.0 || !best.is_finite() {
            return Err(Singular);
        }
        piv[k] = p;
        if p != k {
            for j in 0..m {
                a.swap(k * m + j, p * m + j);
            }
        }
        let inv = 1.0 / a[k * m + k];
        for i in k + 1..m {
            let l = a[i * m + k] * inv;
            a[i * m + k] = l;
            if l != 0.0 {
                for j in k + 1..m {
                    a[i * m + j] -= l * a[k * m + j];
                }
            }
        }
    }
    Ok(())
}

/// Solves `A x = b` in place with the factors of [`lu_factor`].
pub fn lu_solve(lu: &[f64], m: usize, piv: &[usize], b: &mut [f64]) {
    for k in 0..m {
        b.swap(k, piv[k]);
    }
    for i in 0..m {
        let mut s = b[i];
        for j in 0..i {
            s -= lu[i * m + j] * b[j];
        }
        b[i] = s;
    }
    for i in (0..m).rev() {
        let mut s = b[i];
        for j in i + 1..m {
            s -= lu[i * m + j] * b[j];
        }
        b[i] = s / lu[i * m + i];
    }
}

/// Inverse of the row-major `m×m` matrix `a` into `inv`, using `lu` (`m*m`) and
/// `piv` (`m`) as scratch.
///
/// # Errors
/// [`Singular`] if `a` is numerically singular.
pub fn invert(
    a: &[f64],
    m: usize,
    inv: &mut [f64],
    lu: &mut [f64],
    piv: &mut [usize],
) -> Result<(), Singular> {
    lu[..m * m].copy_from_slice(&a[..m * m]);
    lu_factor(lu, m, piv)?;
    // Solve for the columns of the transpose, i.e. rows of inv^T, then transpose.
    for j in 0..m {
        let col = &mut inv[j * m..(j + 1) * m];
        col.fill(0.0);
        col[j] = 1.0;
        lu_solve(lu, m, piv, col);
    }
    // inv now holds columns of A^{-1} as rows: transpose in place.
    for i in 0..m {
        for j in i + 1..m {
            inv.swap(i * m + j, j * m + i);
        }
    }
    if inv[..m * m].iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(Singular)
    }
}

/// `y = A x` for row-major `A` (`rows×cols`).
pub fn matvec(a: &[f64], rows: usize, cols: usize, x: &[f64], y: &mut [f64]) {
    for (yi, row) in y[..rows].iter_mut().zip(a.chunks_exact(cols)) {
        *yi = dot(row, x);
    }
}

/// Euclidean norm.
pub fn norm2(x: &[f64]) -> f64 {
    dot(x, x).sqrt()
}

/// Independent partial sums in [`dot`]: enough to hide the add latency and let the
/// compiler use SIMD lanes (a single running sum serialises every addition).
const LANES: usize = 8;

/// Dot product over the common length, summed in [`LANES`] interleaved partial sums
/// (a different, not less accurate, rounding order than a left-to-right sum).
pub fn dot(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len().min(y.len());
    let (x, y) = (&x[..n], &y[..n]);
    let mut acc = [0.0; LANES];
    let (xc, yc) = (x.chunks_exact(LANES), y.chunks_exact(LANES));
    let tail: f64 = xc
        .remainder()
        .iter()
        .zip(yc.remainder())
        .map(|(a, b)| a * b)
        .sum();
    for (a, b) in xc.zip(yc) {
        for k in 0..LANES {
            acc[k] += a[k] * b[k];
        }
    }
    acc.iter().sum::<f64>() + tail
}

/// `y ← y + alpha·x` over the common length.
pub fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
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
    fn inverse_of_a_known_matrix() {
        // [[4, 3], [6, 3]]^{-1} = [[-0.5, 0.5], [1, -2/3]] (det = -6).
        let inv = invert_2x2(&[4.0, 3.0, 6.0, 3.0]).unwrap();
        let want = [-0.5, 0.5, 1.0, -2.0 / 3.0];
        for (g, w) in inv.iter().zip(want) {
            assert!((g - w).abs() < 1e-15);
        }
    }

    #[test]
    fn singular_is_reported() {
        assert_eq!(invert_2x2(&[1.0, 2.0, 2.0, 4.0]), Err(Singular));
    }

    /// [`invert`] of a row-major 2×2 matrix with its own scratch.
    fn invert_2x2(a: &[f64; 4]) -> Result<[f64; 4], Singular> {
        let (mut inv, mut lu, mut piv) = ([0.0; 4], [0.0; 4], [0; 2]);
        invert(a, 2, &mut inv, &mut lu, &mut piv).map(|()| inv)
    }
}
