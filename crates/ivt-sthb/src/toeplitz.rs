//! Truncated Toeplitz form (Eq. 99) of a real periodic matrix `S(t)` in the
//! real temporal basis `{1, cos kt, sin kt}`.
//!
//! With `S(t) = Σ_r Ŝ_r e^{jrt}` (`Ŝ_{−r} = conj Ŝ_r`) and the harmonic
//! ordering `h = 0` (constant), `h = 2k−1` (cos kt), `h = 2k` (sin kt), the
//! Galerkin projection of `S(t) ξ(t)` (`1/2π ∫` for the constant, `1/π ∫` for
//! cos/sin) has the real blocks
//!
//! | row \ col | `1`          | `cos lt`                  | `sin lt`                  |
//! |-----------|--------------|---------------------------|---------------------------|
//! | `1`       | `Re Ŝ_0`     | `Re Ŝ_l`                  | `−Im Ŝ_l`                 |
//! | `cos kt`  | `2 Re Ŝ_k`   | `Re(Ŝ_{k−l} + Ŝ_{k+l})`   | `Im Ŝ_{k−l} − Im Ŝ_{k+l}` |
//! | `sin kt`  | `−2 Im Ŝ_k`  | `−Im(Ŝ_{k−l} + Ŝ_{k+l})`  | `Re Ŝ_{k−l} − Re Ŝ_{k+l}` |
//!
//! obtained from the complex Toeplitz form `Y_p = Σ_q Ŝ_{p−q} X_q` (Eq. 101–102)
//! with `X_{±l} = (x^c_l ∓ j x^s_l)/2`, `y^c_k = 2 Re Y_k`, `y^s_k = −2 Im Y_k`.
//! When `Ŝ_r` are the DFT coefficients of `M_s` samples (index `r mod M_s`), the
//! table is the exact derivative of the sampled (alternating frequency–time)
//! projection, aliasing included.

use faer::MatMut;
use realfft::num_complex::Complex;

/// Fourier coefficients `Ŝ_p`, `p = 0..=p_max`, of a real periodic `rows × cols`
/// matrix sampled at `ms` points (DFT normalized by `1/ms`).
#[derive(Clone, Debug)]
pub struct PeriodicSpectrum {
    /// Rows of `S(t)`.
    pub rows: usize,
    /// Columns of `S(t)`.
    pub cols: usize,
    /// Number of time samples the DFT came from.
    pub ms: usize,
    /// Highest stored harmonic.
    pub p_max: usize,
    /// `Ŝ_p[i][j]` at `(p · rows + i) · cols + j`.
    pub data: Vec<Complex<f64>>,
}

impl PeriodicSpectrum {
    /// Zero spectrum.
    pub fn zeros(rows: usize, cols: usize, ms: usize, p_max: usize) -> Self {
        Self {
            rows,
            cols,
            ms,
            p_max,
            data: vec![Complex::new(0.0, 0.0); (p_max + 1) * rows * cols],
        }
    }

    /// `Ŝ_r[i][j]` for any integer `r` (aliased modulo `ms`, conjugated for
    /// negative frequencies; zero above `p_max`).
    pub fn get(&self, r: isize, i: usize, j: usize) -> Complex<f64> {
        let ms = self.ms as isize;
        let rr = r.rem_euclid(ms) as usize;
        let (p, conj) = if rr <= self.ms / 2 {
            (rr, false)
        } else {
            (self.ms - rr, true)
        };
        if p > self.p_max {
            return Complex::new(0.0, 0.0);
        }
        // NaN for an entry (i, j) outside the matrix.
        let v = self
            .data
            .get(self.index(p, i, j))
            .copied()
            .unwrap_or(Complex::new(f64::NAN, f64::NAN));
        if conj {
            v.conj()
        } else {
            v
        }
    }

    /// The position of `Ŝ_p[i][j]` in [`Self::data`].
    pub(crate) fn index(&self, p: usize, i: usize, j: usize) -> usize {
        (p * self.rows + i) * self.cols + j
    }

    /// Mutable `Ŝ_p[i][j]`; `None` unless `p ≤ p_max`, `i < rows` and `j < cols`.
    pub fn at_mut(&mut self, p: usize, i: usize, j: usize) -> Option<&mut Complex<f64>> {
        if p > self.p_max || i >= self.rows || j >= self.cols {
            return None;
        }
        let k = self.index(p, i, j);
        self.data.get_mut(k)
    }
}

/// Where the blocks go: entry `(i, j)` of harmonic pair `(h, g)` is added to
/// `target[(h · row_block + row_off + i, g · col_block + col_off + j)]`.
#[derive(Clone, Copy, Debug)]
pub struct BlockLayout {
    /// Stride between harmonic blocks in rows.
    pub row_block: usize,
    /// Row offset inside a block.
    pub row_off: usize,
    /// Stride between harmonic blocks in columns.
    pub col_block: usize,
    /// Column offset inside a block.
    pub col_off: usize,
}

/// Add `scale ×` the real Toeplitz form of `s` with `harmonics` harmonics to
/// `target`. `scratch` holds the blocks `Ŝ_r, |r| ≤ 2M` (grown once, reused).
pub fn add_real_toeplitz(
    s: &PeriodicSpectrum,
    harmonics: usize,
    scale: f64,
    layout: BlockLayout,
    mut target: MatMut<'_, f64>,
    scratch: &mut Vec<Complex<f64>>,
) {
    let m = harmonics as isize;
    let (rows, cols) = (s.rows, s.cols);
    let nb = rows * cols;
    scratch.clear();
    for r in -2 * m..=2 * m {
        for i in 0..rows {
            for j in 0..cols {
                scratch.push(s.get(r, i, j));
            }
        }
    }
    // Block r of the scratch (every |r| ≤ 2M was pushed above).
    let blk = |r: isize| {
        let start = (r + 2 * m) as usize * nb;
        scratch.get(start..start + nb).unwrap_or_default()
    };
    let nan = Complex::new(f64::NAN, f64::NAN);
    let mut add = |h: usize, g: usize, i: usize, j: usize, v: f64| {
        let r = h * layout.row_block + layout.row_off + i;
        let c = g * layout.col_block + layout.col_off + j;
        target[(r, c)] += scale * v;
    };
    for k in 0..=m {
        for l in 0..=m {
            let (d, su) = (blk(k - l), blk(k + l));
            let (hc, hs) = ((2 * k - 1).max(0) as usize, (2 * k) as usize);
            let (gc, gs) = ((2 * l - 1).max(0) as usize, (2 * l) as usize);
            for i in 0..rows {
                for j in 0..cols {
                    let at = |b: &[Complex<f64>]| b.get(i * cols + j).copied().unwrap_or(nan);
                    let (d, su) = (at(d), at(su));
                    // Table in the module docs.
                    match (k == 0, l == 0) {
                        (true, true) => add(0, 0, i, j, d.re),
                        (true, false) => {
                            add(0, gc, i, j, su.re);
                            add(0, gs, i, j, -su.im);
                        }
                        (false, true) => {
                            add(hc, 0, i, j, 2.0 * d.re);
                            add(hs, 0, i, j, -2.0 * d.im);
                        }
                        (false, false) => {
                            add(hc, gc, i, j, d.re + su.re);
                            add(hc, gs, i, j, d.im - su.im);
                            add(hs, gc, i, j, -(d.im + su.im));
                            add(hs, gs, i, j, d.re - su.re);
                        }
                    }
                }
            }
        }
    }
}

/// [`add_real_toeplitz`] restricted to the odd harmonics `k, l` and to the
/// coordinates `coords` (rows and columns), into a target ordered as the full
/// one without the even harmonics: `(cos kt, coords[c])` at index
/// `(k − 1)·coords.len() + c`, `(sin kt, coords[c])` at `k·coords.len() + c`.
/// Only `Ŝ_r` of even `r = k ∓ l` enter. Rows `coords[c] ≥ s.rows` (the
/// spring's Tau row, not in `S`) get nothing.
pub fn add_real_toeplitz_odd(
    s: &PeriodicSpectrum,
    harmonics: usize,
    scale: f64,
    coords: &[usize],
    mut target: MatMut<'_, f64>,
) {
    let nc = coords.len();
    for k in (1..=harmonics).step_by(2) {
        for l in (1..=harmonics).step_by(2) {
            let (dif, sum) = (k as isize - l as isize, (k + l) as isize);
            for (ci, &i) in coords.iter().enumerate().filter(|c| *c.1 < s.rows) {
                let (hc, hs) = ((k - 1) * nc + ci, k * nc + ci);
                for (cj, &j) in coords.iter().enumerate() {
                    let (d, su) = (s.get(dif, i, j), s.get(sum, i, j));
                    let (gc, gs) = ((l - 1) * nc + cj, l * nc + cj);
                    // The (false, false) row of the table in the module docs.
                    target[(hc, gc)] += scale * (d.re + su.re);
                    target[(hc, gs)] += scale * (d.im - su.im);
                    target[(hs, gc)] -= scale * (d.im + su.im);
                    target[(hs, gs)] += scale * (d.re - su.re);
                }
            }
        }
    }
}
