//! The STHB residual (Eq. 116) and exact Jacobian (Eq. 115–125) of the string.
//!
//! Vectors of the wrong length (`a`, `out` not [`StringHb::dim`] long) are not a
//! panic: the residual is NaN, which the Newton solve reports as
//! [`HbError::NonFinite`].

use std::f64::consts::PI;

use faer::Mat;
use realfft::num_complex::Complex;
use rustdct::DctPlanner;

use super::spatial::{Spatial, DIRECT_MAX_MODES};
use super::toeplitz::{add_real_toeplitz, BlockLayout, PeriodicSpectrum};
use super::{Boundary, StringParams};
use ivt_hb::orbit::aft::RealFftPair;
use ivt_hb::HbError;
use ivt_num::NewtonWorkspace;

mod solve;

/// STHB discretization of Eq. 103 for one parameter set: FFT/DCT/DST plans,
/// grid buffers and the Jacobian storage, made once and reused.
///
/// Unknowns `a` are ordered harmonic-major like the thesis's
/// `a = {a_{−M} … a_M}`: index `h · n_q + n` with `h = 0` (constant),
/// `h = 2k − 1` (cos kt), `h = 2k` (sin kt), and coordinate `n` (`n_q = N`, or
/// `N + 1` with the spring's `e(x) = x` coordinate last).
pub struct StringHb {
    p: StringParams,
    nq: usize,
    spatial: Spatial,
    fft: RealFftPair,
    q_t: Vec<f64>,
    wx: Vec<f64>,
    wxx: Vec<f64>,
    g: Vec<f64>,
    g2: Vec<f64>,
    gamma_t: Vec<f64>,
    b_t: Vec<f64>,
    c_t: Vec<f64>,
    b_hat: Vec<Complex<f64>>,
    c_hat: Vec<Complex<f64>>,
    /// `Ŝ_p` of `S(t) = ∂ℒ/∂Q` (Eq. 124–125, `N × n_q`) at the last Jacobian evaluation.
    pub(crate) s_hat: PeriodicSpectrum,
    e_proj: Vec<f64>,
    nl: Vec<f64>,
    toeplitz_scratch: Vec<Complex<f64>>,
    /// Buffers of the Newton solve ([`Self::solve`]).
    newton: NewtonWorkspace,
    /// The assembled Jacobian of the Newton solve.
    jac: Mat<f64>,
}

impl StringHb {
    /// Plan the transforms and allocate all buffers for `params`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] if the parameters fail [`StringParams::validate`].
    pub fn new(params: StringParams) -> Result<Self, HbError> {
        Self::with_spatial(params, None)
    }

    /// As [`StringHb::new`], forcing rustdct (`Some(false)`) or the direct sums
    /// (`Some(true)`) for the spatial balance; `None` picks by `N`.
    ///
    /// # Errors
    /// As [`StringHb::new`].
    pub fn with_spatial(params: StringParams, direct: Option<bool>) -> Result<Self, HbError> {
        params.validate()?;
        let (n, m, ns, ms) = (params.modes, params.harmonics, params.ns, params.ms);
        let nq = match params.boundary {
            Boundary::Fixed => n,
            Boundary::Spring { .. } => n + 1,
        };
        let mut dp = DctPlanner::new();
        let dst = dp.plan_dst1(ns - 1);
        let dct = dp.plan_dct1(ns + 1);
        let p_max = (2 * m).min(ms / 2);
        // Discrete projection of e(x) = x on sin nπx (spring, Eq. 135).
        let mut e = (1..ns).map(|k| k as f64 / ns as f64).collect::<Vec<_>>();
        let mut scr = vec![0.0; dst.get_scratch_len()];
        dst.process_dst1_with_scratch(&mut e, &mut scr);
        let e_proj = e.iter().take(n).map(|v| 2.0 / ns as f64 * v).collect();
        let dim = nq * (2 * m + 1);
        Ok(Self {
            nq,
            spatial: Spatial::new(dst, dct, ns, n, direct.unwrap_or(n <= DIRECT_MAX_MODES)),
            fft: RealFftPair::new(ms),
            q_t: vec![0.0; nq * ms],
            wx: vec![0.0; ns + 1],
            wxx: vec![0.0; ns - 1],
            g: vec![0.0; ns - 1],
            g2: vec![0.0; ns + 1],
            gamma_t: vec![0.0; n * ms],
            b_t: vec![0.0; 2 * n * ms],
            c_t: vec![0.0; (2 * n + 1) * ms],
            b_hat: vec![Complex::new(0.0, 0.0); 2 * n * (p_max + 1)],
            c_hat: vec![Complex::new(0.0, 0.0); (2 * n + 1) * (p_max + 1)],
            s_hat: PeriodicSpectrum::zeros(n, nq, ms, p_max),
            e_proj,
            nl: vec![0.0; dim],
            toeplitz_scratch: Vec::new(),
            newton: NewtonWorkspace::new(dim),
            jac: Mat::zeros(0, 0),
            p: params,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &StringParams {
        &self.p
    }

    /// Number of real unknowns `n_q (2M + 1)`.
    pub fn dim(&self) -> usize {
        self.nq * (2 * self.p.harmonics + 1)
    }

    /// Generalized coordinates per harmonic (`N`, or `N + 1` with the spring).
    pub fn coords(&self) -> usize {
        self.nq
    }

    /// Index of coordinate `n` (0-based) in harmonic slot `h` (0 const, 2k−1 cos, 2k sin).
    pub fn index(&self, h: usize, n: usize) -> usize {
        h * self.nq + n
    }

    /// Euclidean norm of the complex coefficient vector `a` of Eq. 114
    /// (`|a_0|² + Σ_k 2 |(A^c_k − j A^s_k)/2|²`), the ordinate of Figs. 34–36.
    pub fn complex_norm(&self, a: &[f64]) -> f64 {
        let mut s = 0.0;
        for (i, v) in a.iter().enumerate() {
            s += if i < self.nq { v * v } else { 0.5 * v * v };
        }
        s.sqrt()
    }

    /// Coordinate `q_n(t)` of the solution `a` at normalized time `t` (NaN if
    /// `a` has no such coordinate).
    pub fn coordinate_at(&self, a: &[f64], n: usize, t: f64) -> f64 {
        if n >= self.nq {
            return f64::NAN;
        }
        let at = |h: usize| a.get(self.index(h, n)).copied().unwrap_or(f64::NAN);
        let mut q = at(0);
        for k in 1..=self.p.harmonics {
            let kt = k as f64 * t;
            q += at(2 * k - 1) * kt.cos() + at(2 * k) * kt.sin();
        }
        q
    }

    /// Displacement `w(x, t)` of the solution `a` (Eq. 105 / 133).
    pub fn displacement(&self, a: &[f64], x: f64, t: f64) -> f64 {
        let mut w = 0.0;
        for n in 0..self.p.modes {
            w += self.coordinate_at(a, n, t) * ((n + 1) as f64 * PI * x).sin();
        }
        if self.nq > self.p.modes {
            w += x * self.coordinate_at(a, self.p.modes, t);
        }
        w
    }

    /// Apply `J_lin(ω)` (Eq. 115, plus the Tau rows of Eq. 134–135) to `a`,
    /// or its derivative `∂J_lin/∂ω` when `d_omega`.
    /// NaN in `out` unless `a` and `out` are [`Self::dim`] long.
    fn apply_linear(&self, a: &[f64], omega: f64, d_omega: bool, out: &mut [f64]) {
        if a.len() != self.dim() || out.len() != self.dim() {
            return out.fill(f64::NAN);
        }
        out.fill(0.0);
        // Every (row, col) of `J_lin` is below `dim` (`Self::index`).
        self.for_each_linear(omega, d_omega, |r, c, v| {
            if let (Some(o), Some(x)) = (out.get_mut(r), a.get(c)) {
                *o += v * x;
            }
        });
    }

    /// Visit the nonzero entries `(row, col, value)` of `J_lin` or `∂J_lin/∂ω`.
    pub(super) fn for_each_linear(
        &self,
        omega: f64,
        d_omega: bool,
        mut f: impl FnMut(usize, usize, f64),
    ) {
        let (n, m, cd) = (self.p.modes, self.p.harmonics, self.p.cd);
        // Per harmonic k: diagonal `κ − ω²k²` (mass + stiffness), coupling `ω c_d k`.
        let mass = |k: f64| {
            if d_omega {
                -2.0 * omega * k * k
            } else {
                -omega * omega * k * k
            }
        };
        let damp = |k: f64| if d_omega { cd * k } else { omega * cd * k };
        let spring_col = self.nq > n;
        for j in 0..n {
            let kappa = if d_omega {
                0.0
            } else {
                ((j + 1) as f64 * PI).powi(2)
            };
            f(self.index(0, j), self.index(0, j), kappa);
            for k in 1..=m {
                let (rc, rs) = (self.index(2 * k - 1, j), self.index(2 * k, j));
                let kf = k as f64;
                f(rc, rc, kappa + mass(kf));
                f(rs, rs, kappa + mass(kf));
                f(rc, rs, damp(kf));
                f(rs, rc, -damp(kf));
                if spring_col {
                    // ω² e q̈_{N+1} + ω c_d e q̇_{N+1} projected on sin nπx (Eq. 135).
                    let e = self.e_proj.get(j).copied().unwrap_or(f64::NAN);
                    let (cc, cs) = (self.index(2 * k - 1, n), self.index(2 * k, n));
                    f(rc, cc, e * mass(kf));
                    f(rs, cs, e * mass(kf));
                    f(rc, cs, e * damp(kf));
                    f(rs, cc, -e * damp(kf));
                }
            }
        }
        if let (Boundary::Spring { k0 }, false) = (self.p.boundary, d_omega) {
            // Eq. 134: (k0 − 1) q_{N+1} − Σ nπ (−1)^n q_n = 0 for every harmonic.
            // Divided by max(|k0 − 1|, 1) so the row is O(1) like the others
            // (same zeros; keeps Broyden's updates and ‖R‖ balanced for k0 = 1e4).
            let scale = 1.0 / (k0 - 1.0).abs().max(1.0);
            for h in 0..2 * m + 1 {
                let row = self.index(h, n);
                f(row, row, (k0 - 1.0) * scale);
                for j in 0..n {
                    let n1 = (j + 1) as f64;
                    let sign = if (j + 1) % 2 == 0 { 1.0 } else { -1.0 };
                    f(row, self.index(h, j), -n1 * PI * sign * scale);
                }
            }
        }
    }

    /// The Tau method's constant couplings (spring boundary only, `None` when
    /// fixed): `e_j`, the projection of `e(x) = x` on `sin jπx` that multiplies
    /// `q̈_{N+1}` and `q̇_{N+1}` in row `j` (Eq. 135), and `c_j` with
    /// `q_{N+1} = Σ_j c_j q_j`, the boundary row Eq. 134 solved for `q_{N+1}`
    /// (read off the assembled row, so the two cannot disagree).
    pub(crate) fn tau_coupling(&self) -> Option<(Vec<f64>, Vec<f64>)> {
        let n = self.p.modes;
        if self.nq == n {
            return None;
        }
        // Row of the constant harmonic: columns index(0, j) = j, j ≤ N.
        let row = self.index(0, n);
        let mut b = vec![0.0; n + 1];
        self.for_each_linear(1.0, false, |r, c, v| {
            if let Some(bc) = b.get_mut(c).filter(|_| r == row) {
                *bc += v;
            }
        });
        let (b_spring, b_modes) = b.split_last()?;
        let c = b_modes.iter().map(|v| -v / b_spring).collect();
        Some((self.e_proj.clone(), c))
    }

    /// `∂R/∂ω` at `(a, ω)` (the nonlinear term does not depend on ω).
    pub fn d_residual_d_omega(&self, a: &[f64], omega: f64, out: &mut [f64]) {
        self.apply_linear(a, omega, true, out);
    }

    /// Sample the coordinates in time, balance `Γ = k_d w_x² w_xx` in space
    /// (DST-I) and time (FFT) into `self.nl` (= `L(a)`, Eq. 117–118) and, with
    /// `jacobian`, the spectra of `Γ1 = 2 k_d w_x w_xx` (sine basis) and
    /// `Γ2 = k_d w_x²` (cosine basis), assembled into `Ŝ_p` (Eq. 122–125).
    fn balance(&mut self, a: &[f64], jacobian: bool) {
        let (n, m, ns, ms, kd) = (
            self.p.modes,
            self.p.harmonics,
            self.p.ns,
            self.p.ms,
            self.p.kd,
        );
        let nq = self.nq;
        // `ms > 2M + 1`, `ns > 2N + 1` (`StringParams::validate`): every chunk
        // and step below is positive. `a` of the wrong length reads as NaN.
        let coeff = |h: usize, j: usize| a.get(h * nq + j).copied().unwrap_or(f64::NAN);
        let Self {
            spatial,
            fft,
            q_t,
            wx,
            wxx,
            g,
            g2,
            gamma_t,
            b_t,
            c_t,
            b_hat,
            c_hat,
            nl,
            ..
        } = self;
        // 1. q_j(t_i) by inverse real FFT (t_i = 2πi/M_s).
        for (j, q_j) in q_t.chunks_exact_mut(ms).enumerate().take(nq) {
            fft.spectrum.fill(Complex::new(0.0, 0.0));
            let Some((constant, harmonics)) = fft.spectrum.split_first_mut() else {
                q_j.fill(f64::NAN);
                continue;
            };
            *constant = Complex::new(coeff(0, j), 0.0);
            for (k, x) in (1..=m).zip(harmonics) {
                *x = Complex::new(0.5 * coeff(2 * k - 1, j), -0.5 * coeff(2 * k, j));
            }
            fft.inverse_into(q_j);
        }
        // 2. Grid values per time sample, spatial balance by DST-I / DCT-I.
        let scale = 2.0 / ns as f64;
        for i in 0..ms {
            // Sample i of every coordinate: entries i, i + M_s, … of `q_t`.
            let mut q_i = q_t.iter().skip(i).step_by(ms);
            wx.fill(0.0);
            wxx.fill(0.0);
            let modes = wx.iter_mut().skip(1).zip(wxx.iter_mut());
            for (j, ((wx, wxx), q)) in modes.zip(q_i.by_ref().take(n)).enumerate() {
                let k = (j + 1) as f64 * PI;
                *wx = k * q;
                *wxx = -k * k * q;
            }
            // w_x(x_k) = Σ nπ q_n cos(nπk/N_s), k = 0..N_s (DCT-I); w_xx on the interior (DST-I).
            spatial.cosine(wx, n + 1, ns + 1);
            spatial.sine(wxx, n, ns - 1);
            if nq > n {
                // q_{N+1}(t_i), the next after the N modes.
                let qe = q_i.next().copied().unwrap_or(f64::NAN);
                wx.iter_mut().for_each(|v| *v += qe);
            }
            // Interior points k = 1..N_s − 1: w_x at k, w_xx at k − 1.
            let interior = || wx.iter().skip(1).zip(wxx.iter());
            for (g, (wx, wxx)) in g.iter_mut().zip(interior()) {
                *g = kd * wx * wx * wxx;
            }
            spatial.sine(g, ns - 1, n);
            let gamma_i = gamma_t.iter_mut().skip(i).step_by(ms);
            for (gt, g) in gamma_i.zip(g.iter()).take(n) {
                *gt = scale * g;
            }
            if jacobian {
                for (g, (wx, wxx)) in g.iter_mut().zip(interior()) {
                    *g = 2.0 * kd * wx * wxx;
                }
                for (g2, wx) in g2.iter_mut().zip(wx.iter()) {
                    *g2 = kd * wx * wx;
                }
                spatial.sine(g, ns - 1, 2 * n);
                spatial.cosine(g2, ns + 1, 2 * n + 1);
                let b_i = b_t.iter_mut().skip(i).step_by(ms);
                for (b, g) in b_i.zip(g.iter()).take(2 * n) {
                    *b = scale * g;
                }
                let c_i = c_t.iter_mut().skip(i).step_by(ms);
                for (c, g2) in c_i.zip(g2.iter()).take(2 * n + 1) {
                    *c = scale * g2;
                }
            }
        }
        // 3. Temporal balance of Γ: L(a) in the real basis.
        let inv_ms = 1.0 / ms as f64;
        let nan = Complex::new(f64::NAN, f64::NAN);
        for (j, gamma_j) in gamma_t.chunks_exact(ms).enumerate().take(n) {
            fft.forward_from(gamma_j);
            let spectrum = |k: usize| fft.spectrum.get(k).copied().unwrap_or(nan);
            let mut put = |h: usize, v: f64| {
                if let Some(x) = nl.get_mut(h * nq + j) {
                    *x = v;
                }
            };
            put(0, spectrum(0).re * inv_ms);
            for k in 1..=m {
                put(2 * k - 1, 2.0 * spectrum(k).re * inv_ms);
                put(2 * k, -2.0 * spectrum(k).im * inv_ms);
            }
        }
        // The spring coordinate has no nonlinear term (its row is Eq. 134).
        for row in nl.chunks_exact_mut(nq) {
            row.iter_mut().skip(n).for_each(|v| *v = 0.0);
        }
        if !jacobian {
            return;
        }
        let pm = self.s_hat.p_max;
        for (rows, hat) in [(&*b_t, &mut *b_hat), (&*c_t, &mut *c_hat)] {
            for (row, hat_row) in rows.chunks_exact(ms).zip(hat.chunks_exact_mut(pm + 1)) {
                fft.forward_from(row);
                // `p_max ≤ M_s/2`: the spectrum holds every p ≤ p_max.
                for (h, x) in hat_row.iter_mut().zip(&fft.spectrum) {
                    *h = x * inv_ms;
                }
            }
        }
        // 4. Ŝ_p = M1 β1 + M2 β2 G2 (Eq. 122–125) with Γ1 expanded to sine modes 1..2N
        //    and Γ2 to cosine modes 0..2N, which makes the products exact on the grid.
        let (b_hat, c_hat) = (&self.b_hat, &self.c_hat);
        let b = |i: usize, p: usize| -> Complex<f64> {
            match i.checked_sub(1) {
                None => Complex::new(0.0, 0.0),
                Some(i) => b_hat.get(i * (pm + 1) + p).copied().unwrap_or(nan),
            }
        };
        let c = |i: usize, p: usize| c_hat.get(i * (pm + 1) + p).copied().unwrap_or(nan);
        let s = &mut self.s_hat;
        let mut set = |p: usize, i: usize, j: usize, v: Complex<f64>| {
            if let Some(x) = s.at_mut(p, i, j) {
                *x = v;
            }
        };
        for p in 0..=pm {
            for r in 1..=n {
                for j in 1..=n {
                    let (sum, dif) = (r + j, r.abs_diff(j));
                    let sgn = match r.cmp(&j) {
                        std::cmp::Ordering::Greater => 1.0,
                        std::cmp::Ordering::Less => -1.0,
                        std::cmp::Ordering::Equal => 0.0,
                    };
                    let jp = j as f64 * PI;
                    let s1 = (b(sum, p) + b(dif, p) * sgn) * (0.5 * jp);
                    let s2 = (c(dif, p) - c(sum, p)) * (-0.5 * jp * jp);
                    set(p, r - 1, j - 1, s1 + s2);
                }
                if nq > n {
                    // ∂w_x/∂q_{N+1} = e'(x) = 1.
                    set(p, r - 1, n, b(r, p));
                }
            }
        }
    }

    /// Residual `R(a) = J_lin a − L(a) − f̂` (Eq. 116; Tau rows Eq. 134 for the spring).
    pub fn residual(&mut self, a: &[f64], omega: f64, out: &mut [f64]) {
        self.balance(a, false);
        self.finish_residual(a, omega, out);
    }

    fn finish_residual(&self, a: &[f64], omega: f64, out: &mut [f64]) {
        self.apply_linear(a, omega, false, out);
        for (o, l) in out.iter_mut().zip(&self.nl) {
            *o -= l;
        }
        // f̂: y0 cos t on the first sine mode.
        if let Some(o) = out.get_mut(self.index(1, 0)) {
            *o -= self.p.y0;
        }
    }

    /// Residual `R(a)` into `out` with the spectrum `Ŝ_p` of the Jacobian
    /// ([`Self::s_spectrum`]) but without assembling `J`.
    pub(super) fn residual_linearized(&mut self, a: &[f64], omega: f64, out: &mut [f64]) {
        self.balance(a, true);
        self.finish_residual(a, omega, out);
    }

    /// Residual and exact Jacobian `J = J_lin − S_𝒯` (Eq. 115–125) into `jac`
    /// (`dim × dim`, overwritten; resized if it has another shape).
    pub fn residual_jacobian(
        &mut self,
        a: &[f64],
        omega: f64,
        out: &mut [f64],
        jac: &mut Mat<f64>,
    ) {
        self.balance(a, true);
        self.finish_residual(a, omega, out);
        self.fill_jacobian(omega, jac);
    }

    pub(super) fn fill_jacobian(&mut self, omega: f64, jac: &mut Mat<f64>) {
        let dim = self.dim();
        if (jac.nrows(), jac.ncols()) != (dim, dim) {
            *jac = Mat::zeros(dim, dim);
        }
        jac.fill(0.0);
        // Every (row, col) of `J_lin` is below `dim` (`Self::index`).
        self.for_each_linear(omega, false, |r, c, v| jac[(r, c)] += v);
        let layout = BlockLayout {
            row_block: self.nq,
            row_off: 0,
            col_block: self.nq,
            col_off: 0,
        };
        let mut scratch = std::mem::take(&mut self.toeplitz_scratch);
        add_real_toeplitz(
            &self.s_hat,
            self.p.harmonics,
            -1.0,
            layout,
            jac.as_mut(),
            &mut scratch,
        );
        self.toeplitz_scratch = scratch;
    }

    /// The spectrum `Ŝ_p` of `S(t) = ∂ℒ/∂Q` from the last Jacobian evaluation (Eq. 129).
    pub fn s_spectrum(&self) -> &PeriodicSpectrum {
        &self.s_hat
    }

    /// Evaluate the Jacobian at `a` (filling [`Self::s_spectrum`]) without a residual.
    pub fn linearize(&mut self, a: &[f64]) {
        self.balance(a, true);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_of_the_wrong_length_give_nan_and_another_shape_of_jacobian_is_resized() {
        let params = StringParams {
            modes: 2,
            harmonics: 3,
            ns: 16,
            ms: 16,
            boundary: Boundary::Spring { k0: 3.0 },
            ..Default::default()
        };
        let mut hb = StringHb::new(params).unwrap();
        let dim = hb.dim();
        let a: Vec<f64> = (0..dim).map(|i| 0.01 * (i as f64 + 1.0).sin()).collect();
        let mut out = vec![0.0; dim];
        hb.residual(&a[1..], 2.0, &mut out);
        assert!(out.iter().all(|v| v.is_nan()));
        let mut short = vec![0.0; dim - 1];
        hb.residual(&a, 2.0, &mut short);
        assert!(short.iter().all(|v| v.is_nan()));
        // A coordinate beyond N + 1 (the spring's) has no value.
        assert!(hb.coordinate_at(&a, 2, 0.3).is_finite());
        assert!(hb.coordinate_at(&a, 3, 0.3).is_nan());
        // The Jacobian into a 1×1 matrix: resized, and equal to the dim×dim one.
        let (mut small, mut full) = (Mat::zeros(1, 1), Mat::zeros(dim, dim));
        hb.residual_jacobian(&a, 2.0, &mut out, &mut small);
        hb.residual_jacobian(&a, 2.0, &mut out, &mut full);
        assert_eq!((small.nrows(), small.ncols()), (dim, dim));
        assert!(small == full && out.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn spectrum_entries_outside_the_matrix_are_none() {
        let mut s = PeriodicSpectrum::zeros(2, 3, 8, 2);
        assert!(s.at_mut(2, 1, 2).is_some());
        assert!(s.at_mut(3, 0, 0).is_none());
        assert!(s.at_mut(0, 2, 0).is_none());
        assert!(s.at_mut(0, 0, 3).is_none());
    }
}
