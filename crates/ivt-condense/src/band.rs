//! Complex banded LU with partial pivoting (Golub & Van Loan, *Matrix
//! Computations*, 4th ed., Alg. 4.3.5 with row interchanges; LAPACK's
//! `zgbtrf` layout): the dynamic stiffness of a structure whose DOFs are
//! numbered along it (the cantilever: half-bandwidth 3) factored in
//! `O(n·kl·(kl + ku))` with no symbolic analysis, no allocation per column
//! and contiguous rows. Pivoting widens `U`'s upper band to `kl + ku`.

use faer::{c64, MatMut};
use ivt_hb::HbError;

/// Largest half-bandwidth (`max(kl, ku)`) the band factorization is chosen
/// for ([`super::Structure::new`]); wider patterns go to the sparse LU.
pub(crate) const MAX_HALF_BANDWIDTH: usize = 16;

/// `P A = L U` of a band matrix, rows stored densely over the widened band.
#[derive(Debug, Clone)]
pub(crate) struct BandLu {
    n: usize,
    kl: usize,
    ku: usize,
    /// Row `i`, column `j` at `i·width + j + kl − i` for
    /// `i − kl ≤ j ≤ i + kl + ku`; `L`'s multipliers below the diagonal.
    rows: Vec<c64>,
    /// Row exchanged with row `p` at step `p`.
    pivots: Vec<usize>,
}

impl BandLu {
    fn width(&self) -> usize {
        2 * self.kl + self.ku + 1
    }

    fn slot(&self, i: usize, j: usize) -> usize {
        i * self.width() + j + self.kl - i
    }

    /// Factors the `n×n` matrix with lower/upper half-bandwidths `kl`, `ku`
    /// given by its entries `(i, j, value)` (every `|i − j|` within the band;
    /// duplicates summed). `omega` names the frequency in the error.
    ///
    /// # Errors
    /// [`HbError::Singular`] for a zero pivot, [`HbError::InvalidInput`] for
    /// an entry outside the band.
    pub(crate) fn factor(
        n: usize,
        (kl, ku): (usize, usize),
        entries: impl Iterator<Item = (usize, usize, c64)>,
        omega: f64,
    ) -> Result<Self, HbError> {
        let width = 2 * kl + ku + 1;
        let mut lu = Self {
            n,
            kl,
            ku,
            rows: vec![c64::new(0.0, 0.0); n * width],
            pivots: vec![0; n],
        };
        for (i, j, v) in entries {
            let inside = i < n && j < n && j + kl >= i && j <= i + ku;
            let slot = if inside { Some(lu.slot(i, j)) } else { None };
            match slot.and_then(|s| lu.rows.get_mut(s)) {
                Some(e) => *e += v,
                None => {
                    return Err(HbError::InvalidInput(format!(
                        "entry ({i}, {j}) outside the band ({kl}, {ku})"
                    )))
                }
            }
        }
        for p in 0..n {
            lu.eliminate(p, omega)?;
        }
        Ok(lu)
    }

    /// Step `p` of the elimination: the pivot row exchanged in, the rows
    /// below reduced.
    fn eliminate(&mut self, p: usize, omega: f64) -> Result<(), HbError> {
        let (n, kl, ku, width) = (self.n, self.kl, self.ku, self.width());
        let last_row = (p + kl).min(n - 1);
        let span = (p + kl + ku).min(n - 1) - p + 1;
        // |re| + |im| (LAPACK's cabs1): no hypot in the search.
        let size = |z: &c64| z.re.abs() + z.im.abs();
        let mut best = (p, 0.0f64);
        for i in p..=last_row {
            let v = self.rows.get(self.slot(i, p)).map_or(0.0, size);
            if v > best.1 {
                best = (i, v);
            }
        }
        let (r, biggest) = best;
        let singular = || HbError::Singular { omega };
        if biggest == 0.0 || !biggest.is_finite() {
            return Err(HbError::Singular { omega });
        }
        if let Some(slot) = self.pivots.get_mut(p) {
            *slot = r;
        }
        // Row p's band from column p on, and the rows below.
        let start = self.slot(p, p);
        let (head, tail) = self.rows.split_at_mut(start + width - kl);
        let pivot_row = head.get_mut(start..start + span).ok_or_else(singular)?;
        if r != p {
            let other = (r - p) * width - (r - p);
            let row_r = tail
                .get_mut(other - (width - kl)..other - (width - kl) + span)
                .ok_or_else(singular)?;
            pivot_row.swap_with_slice(row_r);
        }
        let (pivot, upper) = pivot_row.split_first().ok_or_else(singular)?;
        for t in 1..=last_row - p {
            // Row p + t, column p at offset kl − t of its band.
            let at = t * (width - 1) - (width - kl);
            let row = tail.get_mut(at..at + span).ok_or_else(singular)?;
            let (lead, rest) = row.split_first_mut().ok_or_else(singular)?;
            let f = *lead / pivot;
            *lead = f;
            if f != c64::new(0.0, 0.0) {
                rest.iter_mut().zip(upper).for_each(|(a, u)| *a -= f * u);
            }
        }
        Ok(())
    }

    /// `X = A⁻¹ B` in place, column by column.
    pub(crate) fn solve_in_place(&self, mut rhs: MatMut<'_, c64>) {
        let (n, kl, width) = (self.n, self.kl, self.width());
        let mut x = vec![c64::new(0.0, 0.0); n];
        for col in 0..rhs.ncols() {
            x.iter_mut()
                .zip(rhs.as_ref().col(col).iter())
                .for_each(|(v, b)| *v = *b);
            for (p, &r) in self.pivots.iter().enumerate() {
                x.swap(p, r);
                let (head, below) = x.split_at_mut(p + 1);
                let xp = head.last().copied().unwrap_or_default();
                for (t, xi) in below.iter_mut().take(kl).enumerate() {
                    let at = (p + t + 1) * width + kl - t - 1;
                    *xi -= self.rows.get(at).copied().unwrap_or_default() * xp;
                }
            }
            for i in (0..n).rev() {
                let base = self.slot(i, i);
                let (head, after) = x.split_at_mut(i + 1);
                let band = self.rows.get(base..base + width - kl).unwrap_or_default();
                if let (Some(xi), Some((d, upper))) = (head.last_mut(), band.split_first()) {
                    let s = upper
                        .iter()
                        .zip(after.iter())
                        .fold(*xi, |s, (a, v)| s - a * v);
                    *xi = s / d;
                }
            }
            rhs.as_mut()
                .col_mut(col)
                .iter_mut()
                .zip(&x)
                .for_each(|(b, v)| *b = *v);
        }
    }

    /// `X = A⁻ᵀ B` in place: `Uᵀ` forward, then the steps of `L` and the
    /// row exchanges transposed, in reverse order.
    pub(crate) fn solve_transpose_in_place(&self, mut rhs: MatMut<'_, c64>) {
        let (n, kl, ku) = (self.n, self.kl, self.ku);
        let entry =
            |i: usize, j: usize| self.rows.get(self.slot(i, j)).copied().unwrap_or_default();
        let mut x = vec![c64::new(0.0, 0.0); n];
        for col in 0..rhs.ncols() {
            x.iter_mut()
                .zip(rhs.as_ref().col(col).iter())
                .for_each(|(v, b)| *v = *b);
            for j in 0..n {
                let first = j.saturating_sub(kl + ku);
                let s = (first..j)
                    .zip(x.iter().skip(first))
                    .fold(x.get(j).copied().unwrap_or_default(), |s, (i, v)| {
                        s - entry(i, j) * v
                    });
                if let Some(xj) = x.get_mut(j) {
                    *xj = s / entry(j, j);
                }
            }
            for (p, &r) in self.pivots.iter().enumerate().rev() {
                let below = x.iter().skip(p + 1).take(kl);
                let s = below
                    .enumerate()
                    .fold(x.get(p).copied().unwrap_or_default(), |s, (t, v)| {
                        s - entry(p + t + 1, p) * v
                    });
                if let Some(xp) = x.get_mut(p) {
                    *xp = s;
                }
                x.swap(p, r);
            }
            rhs.as_mut()
                .col_mut(col)
                .iter_mut()
                .zip(&x)
                .for_each(|(b, v)| *b = *v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// A non-symmetric band matrix (kl = 2, ku = 1) whose first pivot is
    /// small (row exchanges happen), against faer's dense LU.
    #[test]
    fn solves_equal_the_dense_lu() {
        let n = 9;
        let value = |i: usize, j: usize| {
            let d = i as f64 - j as f64;
            c64::new(
                if i == j && i == 0 {
                    1e-3
                } else {
                    1.0 + d * 0.3 + (i % 3) as f64
                },
                0.2 * d + 0.1 * j as f64,
            )
        };
        let inside = |i: usize, j: usize| j + 2 >= i && j <= i + 1;
        let entries = (0..n).flat_map(|i| (0..n).map(move |j| (i, j)));
        let entries = entries
            .filter(|&(i, j)| inside(i, j))
            .map(|(i, j)| (i, j, value(i, j)));
        let lu = BandLu::factor(n, (2, 1), entries, 1.0).unwrap();
        assert!(lu.pivots.iter().enumerate().any(|(p, &r)| r != p));
        let dense = Mat::<c64>::from_fn(n, n, |i, j| {
            if inside(i, j) {
                value(i, j)
            } else {
                c64::new(0.0, 0.0)
            }
        });
        let b = Mat::<c64>::from_fn(n, 2, |i, j| c64::new(i as f64 + 1.0, j as f64 - 0.5));
        for transpose in [false, true] {
            let mut x = b.clone();
            let a = if transpose {
                lu.solve_transpose_in_place(x.as_mut());
                dense.transpose().to_owned()
            } else {
                lu.solve_in_place(x.as_mut());
                dense.clone()
            };
            let r = &a * &x - &b;
            let worst = (0..n)
                .flat_map(|i| (0..2).map(move |j| (i, j)))
                .map(|(i, j)| r[(i, j)].norm())
                .fold(0.0f64, f64::max);
            assert!(worst < 1e-12, "transpose {transpose}: residual {worst:e}");
        }
    }

    #[test]
    fn a_zero_pivot_and_an_entry_outside_the_band_are_errors() {
        let zero = [(0, 0, c64::new(0.0, 0.0)), (1, 1, c64::new(1.0, 0.0))];
        assert!(matches!(
            BandLu::factor(2, (0, 0), zero.into_iter(), 2.0),
            Err(HbError::Singular { omega }) if omega == 2.0
        ));
        let outside = [(1, 0, c64::new(1.0, 0.0))];
        assert!(matches!(
            BandLu::factor(2, (0, 1), outside.into_iter(), 1.0),
            Err(HbError::InvalidInput(_))
        ));
    }
}
