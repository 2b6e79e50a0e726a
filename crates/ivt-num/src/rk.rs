//! The one explicit Runge–Kutta stepper: any [`Tableau`], fixed steps or
//! tentative steps with an embedded error estimate, dense output, and the
//! step-size controller of an adaptive driver (Hairer–Nørsett–Wanner I, §II.4).
//!
//! The right-hand side is `rhs(x, y, dy)` writing `dy = F(x, y)`. Stage
//! storage is owned by the stepper and sized once, so stepping never
//! allocates: fixed-size arrays (`[f64; N]`, no heap at all) or vectors of
//! one dimension. Combinations are accumulated term by term in stage order
//! with zero coefficients skipped, `y + (h a_i1) k_1 + (h a_i2) k_2 + …`.
//!
//! Adaptive drivers stay with their callers because they differ in what
//! must not be stepped over (the simulator lands on gear corners and encoder
//! pulses); they share this stepper, [`Tolerance`], [`step_factor`] and
//! [`ExplicitRk::initial_step`].

use crate::tableau::Tableau;

/// Stage storage: a fixed-size array or a vector.
pub trait Storage: Clone + AsRef<[f64]> + AsMut<[f64]> {}
impl<T: Clone + AsRef<[f64]> + AsMut<[f64]>> Storage for T {}

/// Error tolerances of an adaptive method: the scaled error of component i
/// is `err_i / (atol + rtol · max(|y0_i|, |y1_i|))`, and a step is accepted
/// when the RMS of the scaled errors is at most 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
}

impl Tolerance {
    /// The same relative and absolute tolerance `tol`.
    #[must_use]
    pub const fn uniform(tol: f64) -> Self {
        Self {
            rtol: tol,
            atol: tol,
        }
    }
}

/// An explicit Runge–Kutta method with its stage storage.
#[derive(Clone, Debug)]
pub struct ExplicitRk<const S: usize, V> {
    tab: &'static Tableau<S>,
    k: [V; S],
    tmp: V,
}

impl<const S: usize, const N: usize> ExplicitRk<S, [f64; N]> {
    /// Stepper for states of the fixed dimension `N`.
    pub fn new(tab: &'static Tableau<S>) -> Self {
        Self {
            tab,
            k: [[0.0; N]; S],
            tmp: [0.0; N],
        }
    }
}

impl<const S: usize> ExplicitRk<S, Vec<f64>> {
    /// Stepper for states of dimension `dim`.
    pub fn with_dim(tab: &'static Tableau<S>, dim: usize) -> Self {
        Self {
            tab,
            k: core::array::from_fn(|_| vec![0.0; dim]),
            tmp: vec![0.0; dim],
        }
    }
}

impl<const S: usize, V: Storage> ExplicitRk<S, V> {
    /// The method.
    pub fn tableau(&self) -> &'static Tableau<S> {
        self.tab
    }

    /// Evaluate the stages k_i = F(x + c_i h, y + h Σ_j a_ij k_j), from
    /// stage `first` on (stage 0 may already hold F(x, y)).
    #[inline(always)]
    fn stages<F>(&mut self, rhs: &mut F, x: f64, y: &[f64], h: f64, first: usize)
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        let tab = self.tab;
        // An index loop over the S stages: with S known at compile time the
        // `get`s below cost no check (an iterator chain here did not
        // optimize as well: ~1 % of a closed-loop scene).
        for s in first..S {
            let (done, rest) = self.k.split_at_mut(s);
            let (Some(k_s), Some(a_s), Some(c_s)) = (rest.first_mut(), tab.a.get(s), tab.c.get(s))
            else {
                break;
            };
            let tmp = self.tmp.as_mut();
            tmp.copy_from_slice(y);
            for (a, kj) in a_s.iter().zip(done.iter()) {
                if *a != 0.0 {
                    let ha = h * a;
                    for (t, kj) in tmp.iter_mut().zip(kj.as_ref()) {
                        *t += ha * kj;
                    }
                }
            }
            rhs(x + c_s * h, tmp, k_s.as_mut());
        }
    }

    /// One fixed step of size `h` from `(x, y)`, in place: `y ← y + h Σ b_i k_i`.
    #[inline(always)]
    pub fn step<F>(&mut self, rhs: &mut F, x: f64, h: f64, y: &mut [f64])
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        self.stages(rhs, x, y, h, 0);
        for (b, ks) in self.tab.b.iter().zip(&self.k) {
            if *b != 0.0 {
                let hb = h * b;
                for (yi, ki) in y.iter_mut().zip(ks.as_ref()) {
                    *yi += hb * ki;
                }
            }
        }
    }

    /// `steps` fixed steps of size `h` from `x0` (step i starts at `x0 + i h`).
    pub fn fixed_steps<F>(&mut self, rhs: &mut F, x0: f64, h: f64, steps: usize, y: &mut [f64])
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        for i in 0..steps {
            self.step(rhs, x0 + i as f64 * h, h, y);
        }
    }

    /// Integrate over [a, b] in `steps` (at least one) equal steps.
    pub fn integrate<F>(&mut self, rhs: &mut F, a: f64, b: f64, steps: usize, y: &mut [f64])
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        let n = steps.max(1);
        self.fixed_steps(rhs, a, (b - a) / n as f64, n, y);
    }

    /// A tentative step of an embedded pair: writes the propagated solution
    /// at `x + h` into `y1` and returns the RMS of the scaled error (infinite
    /// if it is NaN); the step is acceptable when it is at most 1. `k1` is
    /// F(x, y) when the caller has it (first same as last), else it is
    /// evaluated.
    ///
    /// # Errors
    /// A tableau without error weights has no error estimate: the result is
    /// infinite (no step is acceptable, so an adaptive driver stops with its
    /// step-size error) instead of a panic.
    // The inputs of one step (x, y, F(x, y), h, tolerances, output) are
    // distinct; bundling them would only rename them.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub fn try_step<F>(
        &mut self,
        rhs: &mut F,
        x: f64,
        y: &[f64],
        k1: Option<&[f64]>,
        h: f64,
        tol: &Tolerance,
        y1: &mut [f64],
    ) -> f64
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        let Some(e) = self.tab.e else {
            return f64::INFINITY;
        };
        let first = match k1 {
            Some(k1) => {
                self.k[0].as_mut().copy_from_slice(k1);
                1
            }
            None => 0,
        };
        self.stages(rhs, x, y, h, first);
        if self.tab.fsal {
            // The last stage was evaluated at y + h Σ b_j k_j, the new state.
            y1.copy_from_slice(self.tmp.as_ref());
        } else {
            y1.copy_from_slice(y);
            for (b, ks) in self.tab.b.iter().zip(&self.k) {
                if *b != 0.0 {
                    let hb = h * b;
                    for (yi, ki) in y1.iter_mut().zip(ks.as_ref()) {
                        *yi += hb * ki;
                    }
                }
            }
        }
        let n = y.len();
        let mut sum = 0.0;
        for (i, (y0i, y1i)) in y.iter().zip(y1.iter()).enumerate() {
            let err = h * self.weighted(&e, i);
            let sc = tol.atol + tol.rtol * y0i.abs().max(y1i.abs());
            sum += (err / sc) * (err / sc);
        }
        let err = (sum / n as f64).sqrt();
        if err.is_nan() {
            f64::INFINITY
        } else {
            err
        }
    }

    /// Σ_j w_j k_j[i] over the nonzero weights, in stage order (NaN if `i`
    /// is beyond the state's dimension).
    #[inline(always)]
    fn weighted(&self, w: &[f64; S], i: usize) -> f64 {
        let mut s = 0.0;
        for (wj, kj) in w.iter().zip(&self.k) {
            if *wj != 0.0 {
                s += wj * kj.as_ref().get(i).copied().unwrap_or(f64::NAN);
            }
        }
        s
    }

    /// Stage `i` of the last step (stage 0 is F at its start); `None` if the
    /// method has not `i + 1` stages.
    pub fn stage(&self, i: usize) -> Option<&[f64]> {
        self.k.get(i).map(AsRef::as_ref)
    }

    /// The last stage of the last step: F(x + h, y1) for an FSAL method, the
    /// first stage of the next step (empty only for a method without stages).
    pub fn last_stage(&self) -> &[f64] {
        self.k.last().map_or(&[], AsRef::as_ref)
    }

    /// Dense output of the last step from `y0` (start) to `y1` (end) of size
    /// `h`, at `x0 + s h`, `s ∈ [0, 1]`: Hairer's continuous extension
    /// `y0 + s(Δ + (1−s)(β + s(Δ − h k_S − β + (1−s) h Σ d_i k_i)))` with
    /// `Δ = y1 − y0`, `β = h k_1 − Δ` (4th order and C¹ for DP5; HNW I, §II.6).
    ///
    /// # Errors
    /// A tableau without dense-output weights (or states shorter than `out`)
    /// gives NaN in `out` instead of a panic.
    pub fn dense(&self, y0: &[f64], y1: &[f64], h: f64, s: f64, out: &mut [f64]) {
        let (Some(d), Some(k1)) = (self.tab.d, self.k.first()) else {
            out.fill(f64::NAN);
            return;
        };
        out.fill(f64::NAN);
        let s1 = 1.0 - s;
        let (k1, ks) = (k1.as_ref(), self.last_stage());
        let ends = y0.iter().zip(y1);
        let stages = k1.iter().zip(ks);
        for (i, (o, ((y0i, y1i), (k1i, ksi)))) in out.iter_mut().zip(ends.zip(stages)).enumerate() {
            let ydiff = y1i - y0i;
            let bspl = h * k1i - ydiff;
            let c3 = ydiff - h * ksi - bspl;
            let c4 = h * self.weighted(&d, i);
            *o = y0i + s * (ydiff + s1 * (bspl + s * (c3 + s1 * c4)));
        }
    }

    /// Initial step guess for `(x, y)` with `k1 = F(x, y)` (Hairer's HINIT,
    /// simplified; HNW I §II.4): h0 from ‖y‖/‖k1‖, then from the change of F
    /// over one explicit Euler step, for the method's order.
    pub fn initial_step<F>(
        &mut self,
        rhs: &mut F,
        x: f64,
        y: &[f64],
        k1: &[f64],
        tol: &Tolerance,
    ) -> f64
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        let n = y.len() as f64;
        let sc = |yi: f64| tol.atol + tol.rtol * yi.abs();
        let (mut d0, mut d1) = (0.0, 0.0);
        for (yi, ki) in y.iter().zip(k1) {
            d0 += (yi / sc(*yi)).powi(2);
            d1 += (ki / sc(*yi)).powi(2);
        }
        let (d0, d1) = ((d0 / n).sqrt(), (d1 / n).sqrt());
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        let y1 = self.tmp.as_mut();
        for ((y1i, yi), ki) in y1.iter_mut().zip(y).zip(k1) {
            *y1i = yi + h0 * ki;
        }
        // Stage 1 is scratch here (stage 0 of a one-stage method).
        let Some(k2) = self.k.get_mut(1.min(S.saturating_sub(1))) else {
            return h0;
        };
        let k2 = k2.as_mut();
        rhs(x + h0, self.tmp.as_ref(), k2);
        let mut d2 = 0.0;
        for ((k2i, k1i), yi) in k2.iter().zip(k1).zip(y) {
            d2 += ((k2i - k1i) / sc(*yi)).powi(2);
        }
        let d2 = (d2 / n).sqrt() / h0;
        let h1 = if d1.max(d2) <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / self.tab.order as f64)
        };
        (100.0 * h0).min(h1)
    }
}

/// Step-size factor after a step with scaled error `err` of a method of
/// order `order` (embedded order one less): the standard controller
/// `0.9·err^(−1/order)` clamped to [0.2, 5].
#[inline]
pub fn step_factor(err: f64, order: u32) -> f64 {
    if err == 0.0 {
        5.0
    } else {
        (0.9 * err.powf(-1.0 / order as f64)).clamp(0.2, 5.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tableau::{DP5, RK4};

    /// Misuse is an answer, not a panic: RK4 has no error weights (an
    /// infinite error: no step acceptable) nor dense weights (NaN), and it
    /// has stages 0–3 only.
    #[test]
    fn missing_weights_and_stages_are_reported() {
        let mut rk = ExplicitRk::<4, [f64; 1]>::new(&RK4);
        let mut decay = |_: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0];
        let mut y1 = [0.0];
        let tol = Tolerance::uniform(1e-6);
        let err = rk.try_step(&mut decay, 0.0, &[1.0], None, 0.1, &tol, &mut y1);
        assert_eq!(err, f64::INFINITY);
        let mut out = [0.0];
        rk.dense(&[1.0], &[0.9], 0.1, 0.5, &mut out);
        assert!(out[0].is_nan());
        assert!(rk.stage(3).is_some() && rk.stage(4).is_none());
    }

    /// DP5 dense output on y' = −y over h = 0.1 from y = 1: the midpoint
    /// matches e^(−0.05) to 1e-8 (4th-order interpolant, error O(h⁵)), and an
    /// output longer than the state gets NaN beyond it.
    #[test]
    fn dense_output_matches_the_exponential() {
        let mut rk = ExplicitRk::<7, Vec<f64>>::with_dim(&DP5, 1);
        let mut decay = |_: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0];
        let mut y1 = [0.0];
        let tol = Tolerance::uniform(1e-6);
        let err = rk.try_step(&mut decay, 0.0, &[1.0], None, 0.1, &tol, &mut y1);
        assert!(err < 1.0);
        let mut out = [0.0; 2];
        rk.dense(&[1.0], &y1, 0.1, 0.5, &mut out);
        assert!((out[0] - (-0.05f64).exp()).abs() < 1e-8, "{out:?}");
        assert!(out[1].is_nan());
    }
}
