//! The alternating frequency–time transforms on the torus (the 2-D AFT of
//! quasi-periodic harmonic balance, Krack & Gross ch. 5): a series of the
//! kept harmonics ([`TorusHarmonics`]) sampled on the `N₁ × N₂` grid
//! `θ₁ = 2πi/N₁`, `θ₂ = 2πj/N₂` and back, by 2-D FFTs (rustfft, planned
//! once). Samples are stored `θ₂`-major: sample `j·N₁ + i` is
//! `(θ₁ᵢ, θ₂ⱼ)`; a spectrum likewise: bin `l₂·N₁ + l₁` holds
//! `S(l) = Σ_{ij} f_{ij} e^{−i(l₁θ₁ᵢ + l₂θ₂ⱼ)}` (`l` modulo the grid).

use super::harmonics::TorusHarmonics;
use crate::error::HbError;
use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// Plans and buffers of the 2-D transforms of one grid.
pub(crate) struct TorusGrid {
    n1: usize,
    n2: usize,
    fwd1: Arc<dyn Fft<f64>>,
    inv1: Arc<dyn Fft<f64>>,
    fwd2: Arc<dyn Fft<f64>>,
    inv2: Arc<dyn Fft<f64>>,
    buf: Vec<Complex<f64>>,
    transposed: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
}

impl std::fmt::Debug for TorusGrid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TorusGrid")
            .field("n1", &self.n1)
            .field("n2", &self.n2)
            .finish()
    }
}

const ZERO: Complex<f64> = Complex::new(0.0, 0.0);

impl TorusGrid {
    /// Plans for `n1 × n2` samples; each must exceed twice the largest
    /// `|k|` of `harmonics` along its axis (so that `k` and `−k` fall in
    /// different bins).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for a grid too coarse for the harmonics or
    /// beyond [`crate::limits::MAX_SAMPLES`].
    pub(crate) fn new(harmonics: &TorusHarmonics, n1: usize, n2: usize) -> Result<Self, HbError> {
        let (e1, e2) = harmonics.truncation().extent();
        let enough = n1 > 2 * e1 && n2 > 2 * e2;
        let total = n1.checked_mul(n2);
        if !enough || total.is_none_or(|t| t > crate::limits::MAX_SAMPLES) {
            return Err(HbError::InvalidInput(format!(
                "torus grid {n1}×{n2}: each side must exceed twice the largest |k| \
                 ({e1}, {e2}) and the grid hold at most {} samples",
                crate::limits::MAX_SAMPLES
            )));
        }
        let mut planner = FftPlanner::new();
        let (fwd1, inv1) = (planner.plan_fft_forward(n1), planner.plan_fft_inverse(n1));
        let (fwd2, inv2) = (planner.plan_fft_forward(n2), planner.plan_fft_inverse(n2));
        let scratch_len = [&fwd1, &inv1, &fwd2, &inv2]
            .iter()
            .map(|f| f.get_inplace_scratch_len())
            .max()
            .unwrap_or(0);
        let n = n1 * n2;
        Ok(Self {
            n1,
            n2,
            fwd1,
            inv1,
            fwd2,
            inv2,
            buf: vec![ZERO; n],
            transposed: vec![ZERO; n],
            scratch: vec![ZERO; scratch_len],
        })
    }

    /// Samples along θ₁ and θ₂.
    pub(crate) fn dims(&self) -> (usize, usize) {
        (self.n1, self.n2)
    }

    /// Number of samples `N₁N₂`.
    pub(crate) fn len(&self) -> usize {
        self.n1 * self.n2
    }

    /// The bin of harmonic `(l1, l2)` (modulo the grid).
    pub(crate) fn bin(&self, l1: i64, l2: i64) -> usize {
        let l1 = l1.rem_euclid(self.n1 as i64) as usize;
        let l2 = l2.rem_euclid(self.n2 as i64) as usize;
        l2 * self.n1 + l1
    }

    /// `(θ₁, θ₂)` of sample `s`.
    pub(crate) fn angles(&self, s: usize) -> (f64, f64) {
        let tau = 2.0 * std::f64::consts::PI;
        let (i, j) = (s % self.n1, s / self.n1);
        (
            tau * i as f64 / self.n1 as f64,
            tau * j as f64 / self.n2 as f64,
        )
    }

    /// The 2-D transform of `buf` in place: along θ₁ (rows), then along θ₂
    /// (columns, through the transposed copy).
    fn transform(&mut self, inverse: bool) {
        let (n1, n2) = (self.n1, self.n2);
        let (rows, cols) = if inverse {
            (&self.inv1, &self.inv2)
        } else {
            (&self.fwd1, &self.fwd2)
        };
        rows.process_with_scratch(&mut self.buf, &mut self.scratch);
        for (j, row) in self.buf.chunks_exact(n1).enumerate() {
            for (i, v) in row.iter().enumerate() {
                if let Some(t) = self.transposed.get_mut(i * n2 + j) {
                    *t = *v;
                }
            }
        }
        cols.process_with_scratch(&mut self.transposed, &mut self.scratch);
        for (i, col) in self.transposed.chunks_exact(n2).enumerate() {
            for (j, v) in col.iter().enumerate() {
                if let Some(b) = self.buf.get_mut(j * n1 + i) {
                    *b = *v;
                }
            }
        }
    }

    /// The spectrum `S(l)` of the real samples `samples` (`N₁N₂`; NaN if
    /// not): bin `l₂·N₁ + l₁` (see the module docs).
    pub(crate) fn spectrum(&mut self, samples: &[f64]) -> &[Complex<f64>] {
        if samples.len() != self.len() {
            self.buf.fill(Complex::new(f64::NAN, f64::NAN));
            return &self.buf;
        }
        for (b, s) in self.buf.iter_mut().zip(samples) {
            *b = Complex::new(*s, 0.0);
        }
        self.transform(false);
        &self.buf
    }

    /// Samples of the series `coeffs` (`[a₀, a_1..a_H, b_1..b_H]` of
    /// `harmonics`) into `out` (`N₁N₂`), or of its derivative
    /// `w₁∂/∂θ₁ + w₂∂/∂θ₂` when `derivative` is `Some((w₁, w₂))`. NaN in
    /// `out` for wrong lengths.
    pub(crate) fn synthesize(
        &mut self,
        harmonics: &TorusHarmonics,
        coeffs: &[f64],
        derivative: Option<(f64, f64)>,
        out: &mut [f64],
    ) {
        let h = harmonics.len();
        if coeffs.len() != 2 * h + 1 || out.len() != self.len() {
            return out.fill(f64::NAN);
        }
        self.buf.fill(ZERO);
        let Some((&a0, rest)) = coeffs.split_first() else {
            return out.fill(f64::NAN);
        };
        let (cos, sin) = rest.split_at(h);
        if derivative.is_none() {
            if let Some(b) = self.buf.first_mut() {
                *b = Complex::new(0.5 * a0, 0.0);
            }
        }
        for ((k1, k2), (&a, &b)) in harmonics.iter().zip(cos.iter().zip(sin)) {
            let (a, b) = match derivative {
                // d/dθ (a cos + b sin)(k·θ) along w: ν (b cos − a sin), ν = k·w.
                Some((w1, w2)) => {
                    let nu = k1 as f64 * w1 + k2 as f64 * w2;
                    (nu * b, -nu * a)
                }
                None => (a, b),
            };
            let plus = self.bin(k1, k2);
            let minus = self.bin(-k1, -k2);
            if let Some(x) = self.buf.get_mut(plus) {
                *x += Complex::new(0.5 * a, -0.5 * b);
            }
            if let Some(x) = self.buf.get_mut(minus) {
                *x += Complex::new(0.5 * a, 0.5 * b);
            }
        }
        self.transform(true);
        for (o, b) in out.iter_mut().zip(&self.buf) {
            *o = b.re;
        }
    }

    /// The Galerkin projection of the samples onto the series of
    /// `harmonics` (`(2/N)Σ f cos`, `(2/N)Σ f sin`, and the mean first,
    /// Eq. 61 on the torus) into `out` (`2H + 1`; NaN for wrong lengths).
    pub(crate) fn galerkin(
        &mut self,
        harmonics: &TorusHarmonics,
        samples: &[f64],
        out: &mut [f64],
    ) {
        let h = harmonics.len();
        if out.len() != 2 * h + 1 {
            return out.fill(f64::NAN);
        }
        let n = self.len() as f64;
        let bins: Vec<usize> = harmonics.iter().map(|(k1, k2)| self.bin(k1, k2)).collect();
        let spectrum = self.spectrum(samples);
        let Some((mean, rest)) = out.split_first_mut() else {
            return;
        };
        *mean = spectrum.first().map_or(f64::NAN, |s| s.re / n);
        let (cos, sin) = rest.split_at_mut(h);
        for ((a, b), bin) in cos.iter_mut().zip(sin.iter_mut()).zip(bins) {
            let s = spectrum
                .get(bin)
                .copied()
                .unwrap_or(Complex::new(f64::NAN, f64::NAN));
            *a = 2.0 * s.re / n;
            *b = -2.0 * s.im / n;
        }
    }
}

/// The value of the series `coeffs` of `harmonics` at `(θ₁, θ₂)` and its
/// first and second derivatives: `(x, [x₁, x₂], [x₁₁, x₁₂, x₂₂])`.
pub(crate) fn eval_torus(
    harmonics: &TorusHarmonics,
    coeffs: &[f64],
    theta: (f64, f64),
) -> (f64, [f64; 2], [f64; 3]) {
    let h = harmonics.len();
    let Some((&a0, rest)) = coeffs.split_first().filter(|(_, r)| r.len() == 2 * h) else {
        return (f64::NAN, [f64::NAN; 2], [f64::NAN; 3]);
    };
    let (cos, sin) = rest.split_at(h);
    let (mut x, mut g, mut hess) = (0.5 * a0, [0.0; 2], [0.0; 3]);
    for ((k1, k2), (&a, &b)) in harmonics.iter().zip(cos.iter().zip(sin)) {
        let (k1, k2) = (k1 as f64, k2 as f64);
        let (s, c) = (k1 * theta.0 + k2 * theta.1).sin_cos();
        let value = a * c + b * s;
        let slope = b * c - a * s;
        x += value;
        g[0] += k1 * slope;
        g[1] += k2 * slope;
        hess[0] -= k1 * k1 * value;
        hess[1] -= k1 * k2 * value;
        hess[2] -= k2 * k2 * value;
    }
    (x, g, hess)
}

#[cfg(test)]
mod tests {
    use super::super::harmonics::Truncation;
    use super::*;

    #[test]
    fn synthesis_galerkin_and_derivative_against_direct_sums() {
        let harmonics = TorusHarmonics::new(Truncation::Diamond { h: 3 }).unwrap();
        let l = harmonics.coeff_len();
        let coeffs: Vec<f64> = (0..l)
            .map(|i| 0.3 * ((i as f64) * 0.7).sin() + 0.1)
            .collect();
        let mut grid = TorusGrid::new(&harmonics, 8, 10).unwrap();
        let mut x = vec![0.0; 80];
        grid.synthesize(&harmonics, &coeffs, None, &mut x);
        let mut dx = vec![0.0; 80];
        grid.synthesize(&harmonics, &coeffs, Some((0.9, 0.35)), &mut dx);
        for s in 0..80 {
            let (value, g, _) = eval_torus(&harmonics, &coeffs, grid.angles(s));
            assert!((x[s] - value).abs() < 1e-13, "{s}");
            assert!((dx[s] - 0.9 * g[0] - 0.35 * g[1]).abs() < 1e-13, "{s}");
        }
        let mut back = vec![0.0; l];
        grid.galerkin(&harmonics, &x, &mut back);
        // The Galerkin mean entry is a₀/2.
        assert!((back[0] - 0.5 * coeffs[0]).abs() < 1e-14);
        for (a, b) in back.iter().zip(&coeffs).skip(1) {
            assert!((a - b).abs() < 1e-14);
        }
        assert!(TorusGrid::new(&harmonics, 6, 10).is_err());
    }
}
