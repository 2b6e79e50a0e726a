//! The smooth pieces of the θ axis for the fixed-step order-6 Runge–Kutta
//! ([`ivt_num::RK6`]).
//!
//! The coefficients of Eq. 151 contain `f_θ` (Eq. 139), which jumps at the
//! corners of the noncircular gears, θ = π/4 + kπ/2. A high-order method keeps
//! its order only on pieces where the right-hand side is smooth, so every
//! integration of this crate is split at those corners ([`pieces`]), and the
//! right-hand side is told which gear segment it is on
//! ([`ivt_kin::variant::f_on_segment`]) so that a stage evaluated exactly at
//! a corner uses the one-sided value of its own piece.

use core::f64::consts::FRAC_PI_2;
use ivt_kin::variant::{segment_end, segment_of};
use ivt_num::{ExplicitRk, RK6};

/// The order-6 stepper on states of a runtime dimension.
pub type Rk6 = ExplicitRk<7, Vec<f64>>;

/// Order-6 stepper for states of dimension `dim`.
pub fn rk6(dim: usize) -> Rk6 {
    ExplicitRk::with_dim(&RK6, dim)
}

/// Split [a, b] (a < b) at the gear corners: (start, end, segment) triples.
pub fn pieces(a: f64, b: f64) -> impl Iterator<Item = (f64, f64, i64)> {
    let mut start = a;
    core::iter::from_fn(move || {
        if start >= b {
            return None;
        }
        let seg = segment_of(start);
        let end = segment_end(seg).min(b);
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

/// Number of RK6 steps for a piece of length `len` when a full gear
/// segment (π/2) gets `per_segment` steps (at least one).
pub fn steps_for(len: f64, per_segment: usize) -> usize {
    ((len / FRAC_PI_2) * per_segment as f64).ceil().max(1.0) as usize
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::FRAC_PI_4;
    use ivt_kin::variant::f_on_segment;

    /// The pieces of [0, 2π] are the five stretches between the corners
    /// π/4, 3π/4, 5π/4, 7π/4, and the segment branches follow Eq. 43.
    #[test]
    fn pieces_split_at_corners() {
        let p: Vec<_> = pieces(0.0, 2.0 * core::f64::consts::PI).collect();
        assert_eq!(p.len(), 5);
        assert!((p[0].1 - FRAC_PI_4).abs() < 1e-15);
        assert!((p[1].1 - 3.0 * FRAC_PI_4).abs() < 1e-15);
        for (a, b, s) in p {
            let m = 0.5 * (a + b);
            let (f, ft) = f_on_segment(m, s);
            assert!((f - ivt_kin::variant::f(m)).abs() < 1e-14);
            assert!((ft - ivt_kin::variant::f_theta(m)).abs() < 1e-14);
        }
    }
}
