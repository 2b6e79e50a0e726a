//! Piecewise-linear input profiles V_m(t), T_U(t) (held constant outside
//! their knots).

use crate::integrate::InputProfile;
use std::cell::Cell;

/// A piecewise-linear function of time through `(t, value)` knots with
/// strictly increasing t.
#[derive(Clone, Debug, PartialEq)]
pub struct Pwl {
    knots: Vec<(f64, f64)>,
    /// Segment of the last lookup: queries come in nearly increasing time,
    /// so the search usually ends at once (the RHS calls this every stage).
    hint: Cell<usize>,
}

impl Pwl {
    /// Profile through `knots`; the caller (scene validation) guarantees at
    /// least one knot, finite values and strictly increasing times (without
    /// knots the profile is NaN everywhere).
    pub fn new(knots: Vec<(f64, f64)>) -> Self {
        Self {
            knots,
            hint: Cell::new(1),
        }
    }

    /// A constant.
    pub fn constant(v: f64) -> Self {
        Self::new(vec![(0.0, v)])
    }

    /// Value at `t`; NaN for a NaN `t` (or a profile without knots), so that
    /// a diverged integration shows as a non-finite state, never a panic.
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        let k = self.knots.as_slice();
        let (Some(&(t_first, v_first)), Some(&(t_last, v_last))) = (k.first(), k.last()) else {
            return f64::NAN;
        };
        if t.is_nan() {
            return f64::NAN;
        }
        if t <= t_first {
            return v_first;
        }
        if t >= t_last {
            return v_last;
        }
        // segment i: knots i−1, i (k[0].0 < t < last.0 so 1 ≤ i ≤ len−1)
        let segment = |i: usize| Some((*k.get(i.checked_sub(1)?)?, *k.get(i)?));
        let ((t0, v0), (t1, v1)) = match segment(self.hint.get()) {
            Some(s) if s.0 .0 <= t && t < s.1 .0 => s,
            _ => {
                let i = k.partition_point(|&(tk, _)| tk <= t);
                self.hint.set(i);
                match segment(i) {
                    Some(s) => s,
                    None => return f64::NAN,
                }
            }
        };
        v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    }

    /// The knots.
    pub fn knots(&self) -> &[(f64, f64)] {
        &self.knots
    }
}

/// V_m(t) and T_U(t) together.
#[derive(Clone, Debug, PartialEq)]
pub struct Drive {
    /// Motor voltage \[V\].
    pub v_m: Pwl,
    /// Brake torque \[N·m\].
    pub t_u: Pwl,
}

impl InputProfile for Drive {
    #[inline]
    fn at(&self, t: f64) -> (f64, f64) {
        (self.v_m.at(t), self.t_u.at(t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pwl_interpolates_and_holds() {
        let p = Pwl::new(vec![(1.0, 2.0), (3.0, 6.0), (4.0, 6.0)]);
        assert_eq!(p.at(0.0), 2.0);
        assert_eq!(p.at(1.0), 2.0);
        assert!((p.at(2.0) - 4.0).abs() < 1e-15);
        assert_eq!(p.at(3.5), 6.0);
        assert_eq!(p.at(10.0), 6.0);
        assert_eq!(Pwl::constant(3.0).at(-5.0), 3.0);
        // a diverged integration's NaN time is NaN, not a panic (issue 30)
        assert!(Pwl::constant(3.0).at(f64::NAN).is_nan());
        assert!(p.at(f64::NAN).is_nan());
        assert!(Pwl::new(Vec::new()).at(1.0).is_nan());
        // the cached segment does not change answers for out-of-order queries
        let ts = [3.7, 1.2, 2.9, 0.5, 3.99, 1.01, 2.0];
        let fresh: Vec<f64> = ts
            .iter()
            .map(|&t| Pwl::new(p.knots().to_vec()).at(t))
            .collect();
        let cached: Vec<f64> = ts.iter().map(|&t| p.at(t)).collect();
        assert_eq!(fresh, cached);
    }
}
