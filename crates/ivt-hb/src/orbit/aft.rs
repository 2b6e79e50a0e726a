//! Alternating frequency–time (AFT) machinery, Eq. 61–65.
//!
//! Coefficient convention (SPEC §6): a real 2π-periodic signal with `n` harmonics is
//! `u(τ) = a0/2 + Σ_{k=1..n} (a_k cos kτ + b_k sin kτ)`, stored as
//! `[a0, a1..an, b1..bn]` (length `2n+1`, the vector `A` of §3.2.1). Samples are taken
//! at `τ_i = 2π i / (2N)`, `i = 0..2N−1`, with `N > n` (Eq. 62). FFT plans (realfft)
//! and buffers are made once in [`Aft::new`]; the transforms allocate nothing.
//!
//! The *Galerkin* residual of Eq. 55/61, `r = (1/π)∫ C_s f dτ` with
//! `C_s = {1/2, cos τ…, sin τ…}`, equals the Fourier coefficients of `f` except that
//! its first entry is `a0/2` (the mean): see [`Aft::galerkin`].
//!
//! Slice lengths are the callers' contract (checked by `debug_assert` in tests). A
//! slice of the wrong length in a release build is not a panic: the output is
//! filled with NaN, which the solvers report as [`HbError::NonFinite`].

use crate::error::HbError;
use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use std::sync::Arc;

/// Reusable forward/inverse real FFT plans and buffers for `2N` samples, `n` harmonics.
pub struct Aft {
    n: usize,
    n_half: usize,
    fft: RealFftPair,
}

thread_local! {
    /// The plans of [`RealFftPair::new`] on this thread.
    static PLANNER: std::cell::RefCell<RealFftPlanner<f64>> =
        std::cell::RefCell::new(RealFftPlanner::new());
}

/// Forward and inverse real FFT plans of one length with one scratch, the
/// spectrum (`len/2 + 1` bins) and a sample buffer: the transforms of [`Aft`] and of
/// the string's time axis (ivt-sthb's `StringHb`). They allocate nothing.
pub struct RealFftPair {
    fwd: Arc<dyn RealToComplex<f64>>,
    inv: Arc<dyn ComplexToReal<f64>>,
    scratch: Vec<Complex<f64>>,
    samples: Vec<f64>,
    /// The spectrum: input of [`Self::inverse_into`] (overwritten), output of
    /// [`Self::forward_from`].
    pub spectrum: Vec<Complex<f64>>,
}

impl RealFftPair {
    /// Plans for `len` real samples, from this thread's planner: it keeps
    /// every plan it made, so the solves after the first of a length reuse
    /// its twiddles (planning the 128-point pair of Fig. 28 costs ~1.2·10⁵
    /// instructions, more than half the solve; measured, not asserted).
    pub fn new(len: usize) -> Self {
        let plan = |planner: &mut RealFftPlanner<f64>| {
            (planner.plan_fft_forward(len), planner.plan_fft_inverse(len))
        };
        let (fwd, inv) = PLANNER.with(|cell| match cell.try_borrow_mut() {
            Ok(mut planner) => plan(&mut planner),
            Err(_) => plan(&mut RealFftPlanner::new()),
        });
        let scratch_len = fwd.get_scratch_len().max(inv.get_scratch_len());
        Self {
            scratch: vec![Complex::new(0.0, 0.0); scratch_len],
            samples: vec![0.0; len],
            spectrum: fwd.make_output_vec(),
            fwd,
            inv,
        }
    }

    /// Unnormalised DFT of `samples` (`len`) into [`Self::spectrum`] (NaN if
    /// `samples` is not `len` long).
    pub fn forward_from(&mut self, samples: &[f64]) {
        debug_assert_eq!(samples.len(), self.samples.len());
        if samples.len() != self.samples.len() {
            self.spectrum.fill(Complex::new(f64::NAN, f64::NAN));
            return;
        }
        self.samples.copy_from_slice(samples);
        // The buffers were made by the plan itself and `samples` was checked, so
        // realfft's only errors (buffer lengths) cannot occur; NaN if they did.
        if self
            .fwd
            .process_with_scratch(&mut self.samples, &mut self.spectrum, &mut self.scratch)
            .is_err()
        {
            self.spectrum.fill(Complex::new(f64::NAN, f64::NAN));
        }
    }

    /// `x_i = Σ_K X_K e^{+jKτ_i}` over the Hermitian extension of
    /// [`Self::spectrum`] into `samples` (`len`; NaN if it is not `len` long).
    pub fn inverse_into(&mut self, samples: &mut [f64]) {
        debug_assert_eq!(samples.len(), self.samples.len());
        match self
            .inv
            .process_with_scratch(&mut self.spectrum, samples, &mut self.scratch)
        {
            // A real signal's spectrum has no imaginary part at DC and Nyquist:
            // realfft drops one there and still transforms (its InputValues).
            Ok(()) | Err(realfft::FftError::InputValues(..)) => {}
            Err(_) => poison(samples),
        }
    }
}

/// Marks an output whose input broke the length contract: NaN, so the solvers
/// stop with [`HbError::NonFinite`] instead of using a wrong number.
fn poison(out: &mut [f64]) {
    out.fill(f64::NAN);
}

/// The parts `(a0, [a1..an], [b1..bn])` of a series `[a0, a.., b..]` (`None` if
/// empty). An even length leaves one extra trailing entry in the `b` part.
pub(crate) fn split_series(coeffs: &[f64]) -> Option<(f64, &[f64], &[f64])> {
    let (&a0, rest) = coeffs.split_first()?;
    let (a, b) = rest.split_at(rest.len() / 2);
    Some((a0, a, b))
}

/// [`split_series`] for writing.
pub(crate) fn split_series_mut(coeffs: &mut [f64]) -> Option<(&mut f64, &mut [f64], &mut [f64])> {
    let (a0, rest) = coeffs.split_first_mut()?;
    let half = rest.len() / 2;
    let (a, b) = rest.split_at_mut(half);
    Some((a0, a, b))
}

impl std::fmt::Debug for Aft {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Aft")
            .field("harmonics", &self.n)
            .field("n_half", &self.n_half)
            .finish()
    }
}

impl Clone for Aft {
    fn clone(&self) -> Self {
        // The sizes were validated by `new`.
        Self {
            n: self.n,
            n_half: self.n_half,
            fft: RealFftPair::new(2 * self.n_half),
        }
    }
}

impl Aft {
    /// Plans for `n` harmonics and `2N` samples.
    ///
    /// # Errors
    /// [`HbError::AftTooFewSamples`] unless `N > n`, [`HbError::AftTooManySamples`]
    /// beyond [`crate::limits::MAX_SAMPLES`].
    pub fn new(harmonics: usize, n_half: usize) -> Result<Self, HbError> {
        if n_half <= harmonics {
            return Err(HbError::AftTooFewSamples { harmonics, n_half });
        }
        if crate::limits::samples_error(n_half).is_some() {
            return Err(HbError::AftTooManySamples { n_half });
        }
        Ok(Self {
            n: harmonics,
            n_half,
            fft: RealFftPair::new(2 * n_half),
        })
    }

    /// Harmonics n.
    pub fn harmonics(&self) -> usize {
        self.n
    }

    /// Number of samples 2N.
    pub fn n_samples(&self) -> usize {
        2 * self.n_half
    }

    /// Length of a coefficient vector, 2n+1.
    pub fn coeff_len(&self) -> usize {
        2 * self.n + 1
    }

    /// Sample abscissa τ_i = 2π i/(2N).
    pub fn tau(&self, i: usize) -> f64 {
        std::f64::consts::PI * i as f64 / self.n_half as f64
    }

    /// Samples of `u = a0/2 + Σ a_k cos kτ + b_k sin kτ` at the 2N points.
    pub fn synthesize(&mut self, coeffs: &[f64], samples: &mut [f64]) {
        self.synthesize_derivative(coeffs, 0, samples);
    }

    /// Samples of the `order`-th τ-derivative of the series `coeffs`.
    pub fn synthesize_derivative(&mut self, coeffs: &[f64], order: u32, samples: &mut [f64]) {
        let n = self.n;
        debug_assert_eq!(coeffs.len(), 2 * n + 1);
        debug_assert_eq!(samples.len(), 2 * self.n_half);
        let Some((a0, cos, sin)) = split_series(coeffs).filter(|(_, c, _)| c.len() == n) else {
            return poison(samples);
        };
        let spectrum = &mut self.fft.spectrum;
        spectrum.fill(Complex::new(0.0, 0.0));
        // realfft's inverse gives x_i = Σ_K X_K e^{+jKτ_i} over the full Hermitian
        // spectrum, so a_k cos + b_k sin needs X_k = (a_k − j b_k)/2, X_0 = a0/2.
        let Some((x0, xk)) = spectrum.split_first_mut() else {
            return poison(samples);
        };
        *x0 = Complex::new(if order == 0 { 0.5 * a0 } else { 0.0 }, 0.0);
        // N > n, so the N spectrum bins after X_0 hold all n harmonics.
        for (k, ((x, &a), &b)) in xk.iter_mut().zip(cos).zip(sin).enumerate() {
            let (a, b) = derivative_pair(a, b, k + 1, order);
            *x = Complex::new(0.5 * a, -0.5 * b);
        }
        self.fft.inverse_into(samples);
    }

    /// Samples of the `order`-th τ-derivative of `n_dof` series (`q`: `n_dof` blocks
    /// `[a0, a.., b..]`) times `scale`, sample-major into `out` (`2N·n_dof`, sample
    /// i's values at `i·n_dof`: the layout of `PeriodicProblem::nonlinear_samples`).
    /// `column` (2N) is scratch.
    pub fn synthesize_states(
        &mut self,
        q: &[f64],
        n_dof: usize,
        order: u32,
        scale: f64,
        out: &mut [f64],
        column: &mut [f64],
    ) {
        let l = self.coeff_len();
        if q.len() != n_dof * l {
            debug_assert_eq!(q.len(), n_dof * l);
            return poison(out);
        }
        for (d, qd) in q.chunks_exact(l).enumerate() {
            if n_dof == 1 {
                self.synthesize_derivative(qd, order, out);
                out.iter_mut().for_each(|u| *u *= scale);
            } else {
                self.synthesize_derivative(qd, order, column);
                for (o, c) in out.iter_mut().skip(d).step_by(n_dof).zip(column.iter()) {
                    *o = scale * c;
                }
            }
        }
    }

    /// [`Self::galerkin`] of DOF `d` of sample-major states (layout of
    /// [`Self::synthesize_states`]); `column` (2N) is scratch.
    pub fn galerkin_state(
        &mut self,
        samples: &[f64],
        n_dof: usize,
        d: usize,
        out: &mut [f64],
        column: &mut [f64],
    ) {
        if n_dof == 1 {
            self.galerkin(samples, out);
        } else {
            for (c, s) in column.iter_mut().zip(samples.iter().skip(d).step_by(n_dof)) {
                *c = *s;
            }
            self.galerkin(column, out);
        }
    }

    /// Fourier coefficients `[a0, a1..an, b1..bn]` of the 2N samples (DFT, Eq. 62–65;
    /// exact for trigonometric polynomials of degree < N).
    pub fn analyze(&mut self, samples: &[f64], coeffs: &mut [f64]) {
        let n = self.n;
        debug_assert_eq!(coeffs.len(), 2 * n + 1);
        self.fft.forward_from(samples);
        let scale = 1.0 / self.n_half as f64;
        let Some((c0, cos, sin)) = split_series_mut(coeffs).filter(|(_, c, _)| c.len() == n) else {
            return poison(coeffs);
        };
        let Some((x0, xk)) = self.fft.spectrum.split_first() else {
            return poison(coeffs);
        };
        *c0 = x0.re * scale;
        for ((x, a), b) in xk.iter().zip(cos).zip(sin) {
            *a = x.re * scale;
            *b = -x.im * scale;
        }
    }

    /// The unnormalised DFT `X_l = Σ_i u_i e^{−ilτ_i}`, `l = 0..=N`, of the 2N
    /// samples: `Re X_l = Σ u cos lτ_i`, `Im X_l = −Σ u sin lτ_i`.
    pub(crate) fn spectrum(&mut self, samples: &[f64]) -> &[Complex<f64>] {
        self.fft.forward_from(samples);
        &self.fft.spectrum
    }

    /// Galerkin projection `(1/π)∫ C_s f dτ` of the samples (Eq. 61): like
    /// [`Self::analyze`] but the first entry is the mean `a0/2`.
    pub fn galerkin(&mut self, samples: &[f64], out: &mut [f64]) {
        self.analyze(samples, out);
        if let Some(mean) = out.first_mut() {
            *mean *= 0.5;
        }
    }
}

/// Coefficients `(a, b)` of the `order`-th τ-derivative of `a cos kτ + b sin kτ`.
pub fn derivative_pair(a: f64, b: f64, k: usize, order: u32) -> (f64, f64) {
    let kf = k as f64;
    let (mut a, mut b) = (a, b);
    for _ in 0..order {
        // d/dτ (a cos + b sin) = k b cos − k a sin.
        (a, b) = (kf * b, -kf * a);
    }
    (a, b)
}

/// Coefficients of the `order`-th τ-derivative of a series (`[a0, a.., b..]`).
/// `out` has the length of `coeffs` (NaN otherwise).
pub fn derivative_coeffs(coeffs: &[f64], order: u32, out: &mut [f64]) {
    debug_assert_eq!(coeffs.len(), out.len());
    if coeffs.len() != out.len() {
        return poison(out);
    }
    let (Some((a0, cos, sin)), Some((o0, out_cos, out_sin))) =
        (split_series(coeffs), split_series_mut(out))
    else {
        return;
    };
    *o0 = if order == 0 { a0 } else { 0.0 };
    for (k, (((&a, &b), oa), ob)) in cos.iter().zip(sin).zip(out_cos).zip(out_sin).enumerate() {
        (*oa, *ob) = derivative_pair(a, b, k + 1, order);
    }
}

/// Evaluates the series `[a0, a.., b..]` (or its `order`-th derivative) at τ directly
/// (O(n), for off-grid points such as Hsu's quadrature nodes). NaN for an empty
/// `coeffs`.
pub fn eval_series(coeffs: &[f64], tau: f64, order: u32) -> f64 {
    let Some((a0, cos, sin)) = split_series(coeffs) else {
        return f64::NAN;
    };
    let mut s = if order == 0 { 0.5 * a0 } else { 0.0 };
    for (k, (&a, &b)) in cos.iter().zip(sin).enumerate() {
        let k = k + 1;
        let (a, b) = derivative_pair(a, b, k, order);
        let (sn, cs) = (k as f64 * tau).sin_cos();
        s += a * cs + b * sn;
    }
    s
}

/// `max_τ |x(τ)|` of the series `[a0, a.., b..]`, sampled at 512 points of
/// one period (NaN for an empty `coeffs`): the amplitude of a solution's DOF
/// ([`crate::HbSolution::amplitude`]) and the `peak` of a backbone's points.
pub fn peak(coeffs: &[f64]) -> f64 {
    if coeffs.is_empty() {
        return f64::NAN;
    }
    (0..512)
        .map(|i| eval_series(coeffs, 2.0 * std::f64::consts::PI * f64::from(i) / 512.0, 0).abs())
        .fold(0.0, f64::max)
}

/// The series `[a0, a1..an, b1..bn]` with `n_to` harmonics (truncated or
/// zero-padded), e.g. to seed a solve at another n from a converged solution.
/// An empty `coeffs` is the zero series.
pub fn resize_harmonics(coeffs: &[f64], n_to: usize) -> Vec<f64> {
    let mut out = vec![0.0; 2 * n_to + 1];
    if let (Some((a0, cos, sin)), Some((o0, out_cos, out_sin))) =
        (split_series(coeffs), split_series_mut(&mut out))
    {
        *o0 = a0;
        for (o, &a) in out_cos.iter_mut().zip(cos) {
            *o = a;
        }
        for (o, &b) in out_sin.iter_mut().zip(sin.iter().take(cos.len())) {
            *o = b;
        }
    }
    out
}

/// Replaces the series `[a0, a.., b..]` of `u(τ)` by that of `u(τ + φ)`:
/// harmonic k turns by kφ.
pub fn shift_time(coeffs: &mut [f64], phi: f64) {
    if let Some((_, cos, sin)) = split_series_mut(coeffs) {
        for (k, (a, b)) in cos.iter_mut().zip(sin.iter_mut()).enumerate() {
            let (s, c) = ((k + 1) as f64 * phi).sin_cos();
            (*a, *b) = (*a * c + *b * s, *b * c - *a * s);
        }
    }
}

/// Re-expresses a series in τ as one in τ/`factor` (period `factor·2π`): harmonic k
/// moves to `factor·k`, keeping `n_to` harmonics. Used to start period-2p solutions
/// from period-p ones (§3.2.5: `a_{2j}^{(2)} = a_j^{(1)}`).
/// An empty `coeffs` is the zero series.
pub fn embed_subharmonic(coeffs: &[f64], factor: usize, n_to: usize) -> Vec<f64> {
    let mut out = vec![0.0; 2 * n_to + 1];
    if let (Some((a0, cos, sin)), Some((o0, out_cos, out_sin))) =
        (split_series(coeffs), split_series_mut(&mut out))
    {
        *o0 = a0;
        // Harmonic k lands on harmonic factor·k (index factor·k − 1 of a part).
        let moved = out_cos.iter_mut().zip(out_sin.iter_mut());
        for ((oa, ob), (&a, &b)) in moved
            .skip(factor.saturating_sub(1))
            .step_by(factor.max(1))
            .zip(cos.iter().zip(sin))
        {
            (*oa, *ob) = (a, b);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_derivative_against_direct_sums() {
        let n = 5;
        let mut aft = Aft::new(n, 8).unwrap();
        let coeffs = [0.4, 1.0, -0.5, 0.25, 0.1, 0.05, 0.3, 0.2, -0.7, 0.01, 0.02];
        let mut s = vec![0.0; 16];
        let mut back = vec![0.0; 11];
        aft.synthesize(&coeffs, &mut s);
        for (i, v) in s.iter().enumerate() {
            assert!((v - eval_series(&coeffs, aft.tau(i), 0)).abs() < 1e-14);
        }
        aft.analyze(&s, &mut back);
        for (a, b) in coeffs.iter().zip(&back) {
            assert!((a - b).abs() < 1e-14);
        }
        aft.synthesize_derivative(&coeffs, 2, &mut s);
        for (i, v) in s.iter().enumerate() {
            assert!((v - eval_series(&coeffs, aft.tau(i), 2)).abs() < 1e-12);
        }
    }

    #[test]
    fn galerkin_of_cube_matches_closed_form() {
        // cos³τ = 3/4 cos τ + 1/4 cos 3τ.
        let mut aft = Aft::new(4, 8).unwrap();
        let mut s = vec![0.0; 16];
        for (i, v) in s.iter_mut().enumerate() {
            *v = aft.tau(i).cos().powi(3);
        }
        let mut r = vec![0.0; 9];
        aft.galerkin(&s, &mut r);
        assert!((r[1] - 0.75).abs() < 1e-15 && (r[3] - 0.25).abs() < 1e-15 && r[0].abs() < 1e-15);
    }

    #[test]
    fn too_few_samples_is_an_error() {
        assert!(Aft::new(8, 8).is_err());
    }

    #[test]
    fn resize_embed_and_shift_move_the_right_harmonics() {
        // [a0, a1, a2, b1, b2].
        let c = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(resize_harmonics(&c, 1), [1.0, 2.0, 4.0]);
        assert_eq!(resize_harmonics(&c, 3), [1.0, 2.0, 3.0, 0.0, 4.0, 5.0, 0.0]);
        // Harmonic k → 2k; a2 → harmonic 4 is dropped at n_to = 3.
        assert_eq!(
            embed_subharmonic(&c, 2, 4),
            [1.0, 0.0, 2.0, 0.0, 3.0, 0.0, 4.0, 0.0, 5.0]
        );
        assert_eq!(
            embed_subharmonic(&c, 2, 3),
            [1.0, 0.0, 2.0, 0.0, 0.0, 4.0, 0.0]
        );
        assert_eq!(embed_subharmonic(&c, 3, 6)[3], 2.0);
        // u(τ + φ) against the direct sum.
        let mut shifted = c;
        shift_time(&mut shifted, 0.7);
        for tau in [0.0, 0.3, 2.0, 4.5] {
            let want = eval_series(&c, tau + 0.7, 0);
            assert!((eval_series(&shifted, tau, 0) - want).abs() < 1e-14);
        }
        assert!(eval_series(&[], 0.0, 0).is_nan());
        assert_eq!(resize_harmonics(&[], 1), [0.0; 3]);
    }

    /// A slice of the wrong length is NaN in a release build (a
    /// `debug_assert` stops a debug build first).
    #[cfg(not(debug_assertions))]
    #[test]
    fn wrong_lengths_give_nan_not_a_panic() {
        let mut aft = Aft::new(2, 4).unwrap();
        let mut s = vec![0.0; 8];
        aft.synthesize(&[1.0, 2.0], &mut s);
        assert!(s.iter().all(|v| v.is_nan()));
        let mut c = vec![0.0; 5];
        aft.analyze(&[1.0; 7], &mut c);
        assert!(c.iter().all(|v| v.is_nan()));
        let mut short = vec![0.0; 3];
        aft.analyze(&[1.0; 8], &mut short);
        assert!(short.iter().all(|v| v.is_nan()));
        let mut out = vec![0.0; 4];
        derivative_coeffs(&[1.0; 5], 1, &mut out);
        assert!(out.iter().all(|v| v.is_nan()));
    }
}
