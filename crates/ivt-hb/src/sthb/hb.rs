//! The STHB residual (Eq. 116) and exact Jacobian (Eq. 115–125) of the string.

use std::f64::consts::PI;

use faer::Mat;
use realfft::num_complex::Complex;
use rustdct::DctPlanner;

use super::spatial::{Spatial, DIRECT_MAX_MODES};
use super::toeplitz::{add_real_toeplitz, BlockLayout, PeriodicSpectrum};
use super::{Boundary, StringParams};
use crate::aft::RealFftPair;
use crate::error::HbError;
use ivt_num::{newton, NewtonError, NewtonOptions, NewtonSystem, NewtonWorkspace};
use std::convert::Infallible;

/// Newton–Raphson statistics of one converged solve.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveStats {
    /// Newton iterations (Jacobian factorizations).
    pub iterations: usize,
    /// Residual norm at each iteration, the last one converged.
    pub history: Vec<f64>,
}

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
        let e_proj = e[..n].iter().map(|v| 2.0 / ns as f64 * v).collect();
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

    /// Coordinate `q_n(t)` of the solution `a` at normalized time `t`.
    pub fn coordinate_at(&self, a: &[f64], n: usize, t: f64) -> f64 {
        let mut q = a[self.index(0, n)];
        for k in 1..=self.p.harmonics {
            let kt = k as f64 * t;
            q += a[self.index(2 * k - 1, n)] * kt.cos() + a[self.index(2 * k, n)] * kt.sin();
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
    fn apply_linear(&self, a: &[f64], omega: f64, d_omega: bool, out: &mut [f64]) {
        out.fill(0.0);
        self.for_each_linear(omega, d_omega, |r, c, v| out[r] += v * a[c]);
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
                    let e = self.e_proj[j];
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
            if r == row {
                b[c] += v;
            }
        });
        let c = b[..n].iter().map(|v| -v / b[n]).collect();
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
        // 1. q_j(t_i) by inverse real FFT (t_i = 2πi/M_s).
        for j in 0..nq {
            self.fft.spectrum.fill(Complex::new(0.0, 0.0));
            self.fft.spectrum[0] = Complex::new(a[j], 0.0);
            for k in 1..=m {
                self.fft.spectrum[k] =
                    Complex::new(0.5 * a[(2 * k - 1) * nq + j], -0.5 * a[2 * k * nq + j]);
            }
            self.fft.inverse_into(&mut self.q_t[j * ms..(j + 1) * ms]);
        }
        // 2. Grid values per time sample, spatial balance by DST-I / DCT-I.
        let scale = 2.0 / ns as f64;
        for i in 0..ms {
            self.wx.fill(0.0);
            self.wxx.fill(0.0);
            for j in 0..n {
                let q = self.q_t[j * ms + i];
                let k = (j + 1) as f64 * PI;
                self.wx[j + 1] = k * q;
                self.wxx[j] = -k * k * q;
            }
            // w_x(x_k) = Σ nπ q_n cos(nπk/N_s), k = 0..N_s (DCT-I); w_xx on the interior (DST-I).
            self.spatial.cosine(&mut self.wx, n + 1, ns + 1);
            self.spatial.sine(&mut self.wxx, n, ns - 1);
            if nq > n {
                let qe = self.q_t[n * ms + i];
                self.wx.iter_mut().for_each(|v| *v += qe);
            }
            for k in 1..ns {
                self.g[k - 1] = kd * self.wx[k] * self.wx[k] * self.wxx[k - 1];
            }
            self.spatial.sine(&mut self.g, ns - 1, n);
            for j in 0..n {
                self.gamma_t[j * ms + i] = scale * self.g[j];
            }
            if jacobian {
                for k in 1..ns {
                    self.g[k - 1] = 2.0 * kd * self.wx[k] * self.wxx[k - 1];
                }
                for k in 0..=ns {
                    self.g2[k] = kd * self.wx[k] * self.wx[k];
                }
                self.spatial.sine(&mut self.g, ns - 1, 2 * n);
                self.spatial.cosine(&mut self.g2, ns + 1, 2 * n + 1);
                for r in 0..2 * n {
                    self.b_t[r * ms + i] = scale * self.g[r];
                }
                for r in 0..=2 * n {
                    self.c_t[r * ms + i] = scale * self.g2[r];
                }
            }
        }
        // 3. Temporal balance of Γ: L(a) in the real basis.
        let inv_ms = 1.0 / ms as f64;
        for j in 0..n {
            self.fft.forward_from(&self.gamma_t[j * ms..(j + 1) * ms]);
            self.nl[j] = self.fft.spectrum[0].re * inv_ms;
            for k in 1..=m {
                self.nl[(2 * k - 1) * nq + j] = 2.0 * self.fft.spectrum[k].re * inv_ms;
                self.nl[2 * k * nq + j] = -2.0 * self.fft.spectrum[k].im * inv_ms;
            }
        }
        for j in 0..nq - n {
            for h in 0..2 * m + 1 {
                self.nl[h * nq + n + j] = 0.0;
            }
        }
        if !jacobian {
            return;
        }
        let pm = self.s_hat.p_max;
        for (rows, hat) in [(&self.b_t, &mut self.b_hat), (&self.c_t, &mut self.c_hat)] {
            for (r, row) in rows.chunks_exact(ms).enumerate() {
                self.fft.forward_from(row);
                for p in 0..=pm {
                    hat[r * (pm + 1) + p] = self.fft.spectrum[p] * inv_ms;
                }
            }
        }
        // 4. Ŝ_p = M1 β1 + M2 β2 G2 (Eq. 122–125) with Γ1 expanded to sine modes 1..2N
        //    and Γ2 to cosine modes 0..2N, which makes the products exact on the grid.
        let b = |i: usize, p: usize| -> Complex<f64> {
            if i == 0 {
                Complex::new(0.0, 0.0)
            } else {
                self.b_hat[(i - 1) * (pm + 1) + p]
            }
        };
        let c = |i: usize, p: usize| self.c_hat[i * (pm + 1) + p];
        let mut s = std::mem::replace(&mut self.s_hat, PeriodicSpectrum::zeros(0, 0, 1, 0));
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
                    *s.at_mut(p, r - 1, j - 1) = s1 + s2;
                }
                if nq > n {
                    // ∂w_x/∂q_{N+1} = e'(x) = 1.
                    *s.at_mut(p, r - 1, n) = b(r, p);
                }
            }
        }
        self.s_hat = s;
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
        out[self.index(1, 0)] -= self.p.y0;
    }

    /// Residual `R(a)` into `out` with the spectrum `Ŝ_p` of the Jacobian
    /// ([`Self::s_spectrum`]) but without assembling `J`.
    pub(super) fn residual_linearized(&mut self, a: &[f64], omega: f64, out: &mut [f64]) {
        self.balance(a, true);
        self.finish_residual(a, omega, out);
    }

    /// Residual and exact Jacobian `J = J_lin − S_𝒯` (Eq. 115–125) into `jac`
    /// (`dim × dim`, overwritten).
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
        jac.fill(0.0);
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

    /// Newton–Raphson (step a6, [`ivt_num::newton()`]) with step halving on
    /// `‖R‖` (the full step is kept if no halving helps; the history shows
    /// it), from the guess in `a`, overwritten by the solution.
    /// Converged when `‖R‖ ≤ tol (1 + y0)`; [`Self::s_spectrum`] is then
    /// that of the solution.
    ///
    /// # Errors
    /// [`HbError::NoConvergence`] with the residual history after `max_iter`
    /// iterations, [`HbError::Singular`] or [`HbError::NonFinite`].
    pub fn solve(
        &mut self,
        omega: f64,
        a: &mut [f64],
        tol: f64,
        max_iter: usize,
    ) -> Result<SolveStats, HbError> {
        let dim = self.dim();
        let opts = NewtonOptions {
            ftol: tol * (1.0 + self.p.y0.abs()),
            max_iter,
            max_halvings: 7,
            accept_no_descent: true,
            full_step_without_descent: true,
            ..NewtonOptions::default()
        };
        let mut ws = std::mem::replace(&mut self.newton, NewtonWorkspace::new(0));
        let mut jac = std::mem::replace(&mut self.jac, Mat::zeros(0, 0));
        if jac.nrows() != dim {
            jac = Mat::zeros(dim, dim);
        }
        let mut system = FixedOmega {
            hb: self,
            omega,
            jac: &mut jac,
        };
        let result = newton(&mut system, a, &mut ws, &opts);
        let history = ws.history().to_vec();
        self.newton = ws;
        self.jac = jac;
        match result {
            Ok(stats) => {
                // Leave Ŝ_p at the solution (the last residual was a trial's,
                // without it): the stability functions read it.
                self.balance(a, true);
                Ok(SolveStats {
                    iterations: stats.iterations,
                    history,
                })
            }
            Err(NewtonError::SingularJacobian { .. } | NewtonError::BorderSize { .. }) => {
                Err(HbError::Singular { omega })
            }
            Err(NewtonError::NonFinite { .. }) => Err(HbError::NonFinite { omega }),
            Err(NewtonError::NonConvergence { .. } | NewtonError::NoDescent { .. }) => {
                Err(HbError::NoConvergence {
                    method: "Newton",
                    omega,
                    history,
                })
            }
            Err(NewtonError::Eval(never)) => match never {},
        }
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

/// The string's residual at fixed ω as a [`NewtonSystem`]: trial residuals
/// skip the Jacobian's spectrum; the Jacobian re-balances with it at the
/// accepted point (`J = J_lin − S_𝒯`, Eq. 115–125).
struct FixedOmega<'a> {
    hb: &'a mut StringHb,
    omega: f64,
    jac: &'a mut Mat<f64>,
}

impl NewtonSystem for FixedOmega<'_> {
    type Error = Infallible;

    fn residual(&mut self, a: &[f64], r: &mut [f64]) -> Result<(), Infallible> {
        self.hb.balance(a, false);
        self.hb.finish_residual(a, self.omega, r);
        Ok(())
    }

    fn jacobian(&mut self, a: &[f64], out: &mut [f64]) -> Result<(), Infallible> {
        self.hb.balance(a, true);
        self.hb.fill_jacobian(self.omega, self.jac);
        let dim = self.jac.ncols();
        for (i, row) in out.chunks_exact_mut(dim.max(1)).enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = self.jac[(i, j)];
            }
        }
        Ok(())
    }
}
