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
        let v = self.data[(p * self.rows + i) * self.cols + j];
        if conj {
            v.conj()
        } else {
            v
        }
    }

    /// Mutable `Ŝ_p[i][j]`.
    pub fn at_mut(&mut self, p: usize, i: usize, j: usize) -> &mut Complex<f64> {
        &mut self.data[(p * self.rows + i) * self.cols + j]
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

/// Add `scale ×` the real Toeplitz form of `s` with `harmonics` harmonics to `target`.
pub fn add_real_toeplitz(
    s: &PeriodicSpectrum,
    harmonics: usize,
    scale: f64,
    layout: BlockLayout,
    mut target: MatMut<'_, f64>,
) {
    let nh = 2 * harmonics + 1;
    let freq = |h: usize| h.div_ceil(2) as isize;
    for h in 0..nh {
        for g in 0..nh {
            let (k, l) = (freq(h), freq(g));
            for i in 0..s.rows {
                for j in 0..s.cols {
                    let dif = s.get(k - l, i, j);
                    let sum = s.get(k + l, i, j);
                    let single = s.get(if h == 0 { l } else { k }, i, j);
                    // Table in the module docs; `single` is Ŝ_l (row 1) or Ŝ_k (column 1).
                    let v = match (h == 0, h % 2 == 1, g == 0, g % 2 == 1) {
                        (true, _, true, _) => single.re,
                        (true, _, false, true) => single.re,
                        (true, _, false, false) => -single.im,
                        (false, true, true, _) => 2.0 * single.re,
                        (false, false, true, _) => -2.0 * single.im,
                        (false, true, false, true) => dif.re + sum.re,
                        (false, true, false, false) => dif.im - sum.im,
                        (false, false, false, true) => -(dif.im + sum.im),
                        (false, false, false, false) => dif.re - sum.re,
                    };
                    if v != 0.0 {
                        let r = h * layout.row_block + layout.row_off + i;
                        let c = g * layout.col_block + layout.col_off + j;
                        target[(r, c)] += scale * v;
                    }
                }
            }
        }
    }
}
