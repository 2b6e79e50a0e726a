//! The time-integration reference of a quasi-periodic response (no HB): a
//! one-DOF forced oscillator `x″ = a(t, x, x′)` integrated by fixed-step RK6
//! (ivt-num's tableau) past its transient, then over `periods` forcing
//! periods:
//!
//! - the rotation number from the stroboscopic (Poincaré) map: the angles of
//!   successive points about their centre, the increments averaged with the
//!   smooth weights of a weighted Birkhoff average (Das, Sander & Yorke 2017:
//!   super-polynomial convergence for a smooth quasi-periodic observable);
//! - the mean of `|x|` over the torus as the same weighted time average of
//!   `|x|`, integrated with the state (`I′ = w(t)·σx`) and every step split
//!   at the zeros of `x` (σ its sign), so the kinks of `|x|` cost no order;
//! - the maximum of `|x|` at the zeros of `x′` (each located in its step).
#![allow(clippy::indexing_slicing)]

use ivt_num::{ExplicitRk, RK6};
use std::f64::consts::PI;

/// What the reference measures.
#[derive(Debug, Clone, Copy)]
pub struct Reference {
    /// `|Δθ|/2π` per forcing period, in `[0, ½]`.
    pub rotation_number: f64,
    /// Weighted time average of `|x|`.
    pub amplitude_mean: f64,
    /// Largest `|x|` at a turning point.
    pub amplitude_max: f64,
}

/// The weight `exp(−1/(s(1 − s)))` on `(0, 1)`.
fn bump(s: f64) -> f64 {
    if s <= 0.0 || s >= 1.0 {
        0.0
    } else {
        (-1.0 / (s * (1.0 - s))).exp()
    }
}

/// The integration: the acceleration, the measured window and the sign of
/// `x` on the current piece.
struct Flow<A> {
    accel: A,
    rk: ExplicitRk<7, [f64; 4]>,
    t_start: f64,
    total: f64,
    sigma: f64,
}

impl<A: Fn(f64, f64, f64) -> f64> Flow<A> {
    /// One RK6 step of `s` from `(t, y)` of `[x, v, ∫wσx, ∫w]`.
    fn advance(&mut self, t: f64, y: &[f64; 4], s: f64) -> [f64; 4] {
        let (accel, t_start, total, sigma) = (&self.accel, self.t_start, self.total, self.sigma);
        let mut rhs = |t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = y[1];
            dy[1] = accel(t, y[0], y[1]);
            let w = bump((t - t_start) / total);
            dy[2] = w * sigma * y[0];
            dy[3] = w;
        };
        let mut z = *y;
        self.rk.step(&mut rhs, t, s, &mut z);
        z
    }

    /// The root in `(0, h)` of component `c` along the step from `(t, y)`
    /// (`end` its value at `h`): bisection safeguarding the secant.
    fn root(&mut self, t: f64, y: &[f64; 4], h: f64, c: usize, end: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, h);
        let (mut f_lo, mut f_hi) = (y[c], end);
        for _ in 0..80 {
            let secant = lo - f_lo * (hi - lo) / (f_hi - f_lo);
            let s = if secant > lo && secant < hi {
                secant
            } else {
                0.5 * (lo + hi)
            };
            let z = self.advance(t, y, s);
            if z[c] == 0.0 {
                return s;
            }
            if (z[c] > 0.0) == (f_lo > 0.0) {
                lo = s;
                f_lo = z[c];
            } else {
                hi = s;
                f_hi = z[c];
            }
            if hi - lo < 1e-15 * h {
                break;
            }
        }
        0.5 * (lo + hi)
    }
}

/// The reference of `x″ = accel(t, x, v)` forced at ω from `y0`: `transient`
/// periods discarded, `periods` measured, `steps` RK6 steps per period.
pub fn reference(
    accel: impl Fn(f64, f64, f64) -> f64,
    omega: f64,
    y0: [f64; 2],
    transient: usize,
    periods: usize,
    steps: usize,
) -> Reference {
    let period = 2.0 * PI / omega;
    let h = period / steps as f64;
    let mut flow = Flow {
        accel,
        rk: ExplicitRk::new(&RK6),
        t_start: f64::INFINITY,
        total: periods as f64 * period,
        sigma: 1.0,
    };
    let mut y = [y0[0], y0[1], 0.0, 0.0];
    let mut t = 0.0;
    for _ in 0..transient * steps {
        y = flow.advance(t, &y, h);
        t += h;
    }
    flow.t_start = t;
    y[2] = 0.0;
    y[3] = 0.0;
    let mut section = vec![[y[0], y[1]]];
    let mut max_abs = 0.0f64;
    for _ in 0..periods {
        for _ in 0..steps {
            flow.sigma = if y[0] >= 0.0 { 1.0 } else { -1.0 };
            let trial = flow.advance(t, &y, h);
            if trial[1] * y[1] < 0.0 {
                let s = flow.root(t, &y, h, 1, trial[1]);
                max_abs = max_abs.max(flow.advance(t, &y, s)[0].abs());
            }
            if trial[0] * y[0] < 0.0 {
                let s = flow.root(t, &y, h, 0, trial[0]);
                let mid = flow.advance(t, &y, s);
                flow.sigma = -flow.sigma;
                y = flow.advance(t + s, &mid, h - s);
            } else {
                y = trial;
            }
            t += h;
        }
        section.push([y[0], y[1]]);
    }
    let n = periods;
    let weights: Vec<f64> = (0..n).map(|k| bump((k as f64 + 0.5) / n as f64)).collect();
    let norm: f64 = weights.iter().sum();
    let mut centre = [0.0; 2];
    for (p, w) in section.iter().zip(&weights) {
        centre[0] += w * p[0] / norm;
        centre[1] += w * p[1] / norm;
    }
    let angle = |p: &[f64; 2]| (p[1] - centre[1]).atan2(p[0] - centre[0]);
    let mut turn = 0.0;
    for (pair, w) in section.windows(2).zip(&weights) {
        let mut d = angle(&pair[1]) - angle(&pair[0]);
        d -= 2.0 * PI * (d / (2.0 * PI)).round();
        turn += w * d / norm;
    }
    Reference {
        rotation_number: (turn / (2.0 * PI)).abs(),
        amplitude_mean: y[2] / y[3],
        amplitude_max: max_abs,
    }
}
