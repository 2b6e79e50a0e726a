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
        for s in first..S {
            let (done, rest) = self.k.split_at_mut(s);
            let tmp = self.tmp.as_mut();
            tmp.copy_from_slice(y);
            for (a, kj) in self.tab.a[s].iter().zip(done.iter()) {
                if *a != 0.0 {
                    let ha = h * a;
                    for (t, kj) in tmp.iter_mut().zip(kj.as_ref()) {
                        *t += ha * kj;
                    }
                }
            }
            rhs(x + self.tab.c[s] * h, tmp, rest[0].as_mut());
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
    /// # Panics
    /// If the tableau has no error weights.
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
        let e = self.tab.e.expect("try_step needs an embedded pair");
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
        for i in 0..n {
            let err = h * self.weighted(&e, i);
            let sc = tol.atol + tol.rtol * y[i].abs().max(y1[i].abs());
            sum += (err / sc) * (err / sc);
        }
        let err = (sum / n as f64).sqrt();
        if err.is_nan() {
            f64::INFINITY
        } else {
            err
        }
    }

    /// Σ_j w_j k_j[i] over the nonzero weights, in stage order.
    #[inline(always)]
    fn weighted(&self, w: &[f64; S], i: usize) -> f64 {
        let mut s = 0.0;
        for (wj, kj) in w.iter().zip(&self.k) {
            if *wj != 0.0 {
                s += wj * kj.as_ref()[i];
            }
        }
        s
    }

    /// Stage `i` of the last step (stage 0 is F at its start).
    pub fn stage(&self, i: usize) -> &[f64] {
        self.k[i].as_ref()
    }

    /// The last stage of the last step: F(x + h, y1) for an FSAL method, the
    /// first stage of the next step.
    pub fn last_stage(&self) -> &[f64] {
        self.k[S - 1].as_ref()
    }

    /// Dense output of the last step from `y0` (start) to `y1` (end) of size
    /// `h`, at `x0 + s h`, `s ∈ [0, 1]`: Hairer's continuous extension
    /// `y0 + s(Δ + (1−s)(β + s(Δ − h k_S − β + (1−s) h Σ d_i k_i)))` with
    /// `Δ = y1 − y0`, `β = h k_1 − Δ` (4th order and C¹ for DP5; HNW I, §II.6).
    ///
    /// # Panics
    /// If the tableau has no dense-output weights.
    pub fn dense(&self, y0: &[f64], y1: &[f64], h: f64, s: f64, out: &mut [f64]) {
        let d = self.tab.d.expect("dense output needs dense weights");
        let s1 = 1.0 - s;
        let (k1, ks) = (self.k[0].as_ref(), self.k[S - 1].as_ref());
        for i in 0..out.len() {
            let ydiff = y1[i] - y0[i];
            let bspl = h * k1[i] - ydiff;
            let c3 = ydiff - h * ks[i] - bspl;
            let c4 = h * self.weighted(&d, i);
            out[i] = y0[i] + s * (ydiff + s1 * (bspl + s * (c3 + s1 * c4)));
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
        let sc = |i: usize| tol.atol + tol.rtol * y[i].abs();
        let (mut d0, mut d1) = (0.0, 0.0);
        for i in 0..y.len() {
            d0 += (y[i] / sc(i)).powi(2);
            d1 += (k1[i] / sc(i)).powi(2);
        }
        let (d0, d1) = ((d0 / n).sqrt(), (d1 / n).sqrt());
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        let y1 = self.tmp.as_mut();
        for i in 0..y1.len() {
            y1[i] = y[i] + h0 * k1[i];
        }
        let k2 = self.k[1].as_mut();
        rhs(x + h0, self.tmp.as_ref(), k2);
        let mut d2 = 0.0;
        for i in 0..y.len() {
            d2 += ((k2[i] - k1[i]) / sc(i)).powi(2);
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
