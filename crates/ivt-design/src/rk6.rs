//! Fixed-step sixth-order Runge–Kutta (Butcher 1964, 7 stages) on the smooth
//! pieces of the θ axis.
//!
//! The coefficients of Eq. 151 contain `f_θ` (Eq. 139), which jumps at the
//! corners of the noncircular gears, θ = π/4 + kπ/2. A high-order method keeps
//! its order only on pieces where the right-hand side is smooth, so every
//! integration in this module is split at those corners ([`pieces`]), and the
//! right-hand side is told which gear segment it is on ([`Segment`]) so that a
//! stage evaluated exactly at a corner uses the one-sided value of its own
//! piece.

use core::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use ivt_kin::NCG_AMPLITUDE;

/// One smooth piece of the modulation: θ ∈ [centre − π/4, centre + π/4] with
/// `f = A cos(θ − centre)`, `f_θ = −A sin(θ − centre)` (Eq. 43, 139).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Centre kπ/2 of the gear segment.
    pub centre: f64,
}

impl Segment {
    /// The segment whose interior contains θ (ties go to the segment that
    /// starts at θ).
    pub fn containing(theta: f64) -> Self {
        let k = ((theta + FRAC_PI_4) / FRAC_PI_2).floor();
        Self {
            centre: k * FRAC_PI_2,
        }
    }

    /// (f, f_θ) on this segment from sin θ and cos θ (no trig call): the
    /// segment centred at kπ/2 rotates (sin, cos) by k quarter turns.
    #[inline]
    pub fn f_and_f_theta_from(&self, sin_theta: f64, cos_theta: f64) -> (f64, f64) {
        let k = (self.centre / FRAC_PI_2).round() as i64;
        // (sin φ, cos φ) with φ = θ − kπ/2.
        let (s, c) = match k.rem_euclid(4) {
            0 => (sin_theta, cos_theta),
            1 => (-cos_theta, sin_theta),
            2 => (-sin_theta, -cos_theta),
            _ => (cos_theta, -sin_theta),
        };
        (NCG_AMPLITUDE * c, -NCG_AMPLITUDE * s)
    }

    /// (f, f_θ) on this segment, valid up to and including both ends.
    #[inline]
    pub fn f_and_f_theta(&self, theta: f64) -> (f64, f64) {
        let (s, c) = (theta - self.centre).sin_cos();
        (NCG_AMPLITUDE * c, -NCG_AMPLITUDE * s)
    }
}

/// Split [a, b] (a < b) at the gear corners: (start, end, segment) triples.
pub fn pieces(a: f64, b: f64) -> impl Iterator<Item = (f64, f64, Segment)> {
    let mut start = a;
    core::iter::from_fn(move || {
        if start >= b {
            return None;
        }
        let seg = Segment::containing(start);
        let end = (seg.centre + FRAC_PI_4).min(b);
        let piece = (start, end, seg);
        // Guard against a start that rounding put a hair below a corner.
        start = if end - start < 1e-14 {
            end + 1e-14
        } else {
            end
        };
        Some(piece)
    })
}

/// Butcher's 7-stage, order-6 tableau (Butcher 1964; Hairer–Nørsett–Wanner I, §II.5).
const C: [f64; 7] = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0 / 3.0, 0.5, 0.5, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [0.0, 2.0 / 3.0, 0.0, 0.0, 0.0, 0.0],
    [1.0 / 12.0, 1.0 / 3.0, -1.0 / 12.0, 0.0, 0.0, 0.0],
    [-1.0 / 16.0, 9.0 / 8.0, -3.0 / 16.0, -3.0 / 8.0, 0.0, 0.0],
    [0.0, 9.0 / 8.0, -3.0 / 8.0, -3.0 / 4.0, 0.5, 0.0],
    [
        9.0 / 44.0,
        -9.0 / 11.0,
        63.0 / 44.0,
        18.0 / 11.0,
        0.0,
        -16.0 / 11.0,
    ],
];
const B: [f64; 7] = [
    11.0 / 120.0,
    0.0,
    27.0 / 40.0,
    27.0 / 40.0,
    -4.0 / 15.0,
    -4.0 / 15.0,
    11.0 / 120.0,
];

/// Caller-owned stage storage, sized once per state dimension.
#[derive(Clone, Debug)]
pub struct Rk6 {
    k: [Vec<f64>; 7],
    tmp: Vec<f64>,
}

impl Rk6 {
    /// Scratch for states of dimension `dim`.
    pub fn new(dim: usize) -> Self {
        Self {
            k: core::array::from_fn(|_| vec![0.0; dim]),
            tmp: vec![0.0; dim],
        }
    }

    /// One step of size `h` from `x`: `y ← y + h Σ b_i k_i` with
    /// `rhs(x, y, dy)` writing dy/dx into `dy`.
    pub fn step<F>(&mut self, rhs: &mut F, x: f64, h: f64, y: &mut [f64])
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        for s in 0..7 {
            self.tmp.copy_from_slice(y);
            for (j, a) in A[s].iter().enumerate().take(s) {
                if *a != 0.0 {
                    let ha = h * a;
                    for (t, kj) in self.tmp.iter_mut().zip(&self.k[j]) {
                        *t += ha * kj;
                    }
                }
            }
            let (k_s, _) = self.k.split_at_mut(s + 1);
            rhs(x + C[s] * h, &self.tmp, &mut k_s[s]);
        }
        for (s, b) in B.iter().enumerate() {
            if *b != 0.0 {
                let hb = h * b;
                for (yi, ks) in y.iter_mut().zip(&self.k[s]) {
                    *yi += hb * ks;
                }
            }
        }
    }

    /// Integrate over [a, b] in `steps` equal steps.
    pub fn integrate<F>(&mut self, rhs: &mut F, a: f64, b: f64, steps: usize, y: &mut [f64])
    where
        F: FnMut(f64, &[f64], &mut [f64]),
    {
        let n = steps.max(1);
        let h = (b - a) / n as f64;
        for i in 0..n {
            self.step(rhs, a + i as f64 * h, h, y);
        }
    }
}

/// Number of RK6 steps for a piece of length `len` when a full gear
/// segment (π/2) gets `per_segment` steps (at least one).
pub fn steps_for(len: f64, per_segment: usize) -> usize {
    ((len / FRAC_PI_2) * per_segment as f64).ceil().max(1.0) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y' = cos(x) y, y(0) = 1 → y = exp(sin x). Halving h must cut the error
    /// by ≈ 2⁶ = 64 (order 6); we accept a ratio above 50, since the
    /// asymptotic constant is reached only approximately at these step sizes.
    #[test]
    fn order_six_on_smooth_problem() {
        let mut rk = Rk6::new(1);
        let exact = 3.0f64.sin().exp();
        let mut err = |n: usize| {
            let mut y = [1.0];
            let mut rhs = |x: f64, y: &[f64], dy: &mut [f64]| dy[0] = x.cos() * y[0];
            rk.integrate(&mut rhs, 0.0, 3.0, n, &mut y);
            (y[0] - exact).abs()
        };
        let e1 = err(10);
        let e2 = err(20);
        assert!(e1 / e2 > 50.0, "ratio {}", e1 / e2);
    }

    /// The pieces of [0, 2π] are the five stretches between the corners
    /// π/4, 3π/4, 5π/4, 7π/4, and the segment signs follow Eq. 43.
    #[test]
    fn pieces_split_at_corners() {
        let p: Vec<_> = pieces(0.0, 2.0 * core::f64::consts::PI).collect();
        assert_eq!(p.len(), 5);
        assert!((p[0].1 - FRAC_PI_4).abs() < 1e-15);
        assert!((p[1].1 - 3.0 * FRAC_PI_4).abs() < 1e-15);
        for (a, b, s) in p {
            let m = 0.5 * (a + b);
            let (f, ft) = s.f_and_f_theta(m);
            assert!((f - ivt_kin::variant::f(m)).abs() < 1e-14);
            assert!((ft - ivt_kin::variant::f_theta(m)).abs() < 1e-14);
            let (f2, ft2) = s.f_and_f_theta_from(m.sin(), m.cos());
            assert!((f2 - f).abs() < 1e-14 && (ft2 - ft).abs() < 1e-14);
        }
    }
}
