//! Tangent circular arcs (§2.2.4): one arc through two points with a given
//! start tangent, the equal-tangent biarc between two points with their
//! tangents, and the angle wrapping they share with the fitter.

use core::f64::consts::PI;

/// 2π.
pub(super) const TWO_PI: f64 = 2.0 * PI;

/// ψ mod 2π in [0, 2π).
pub(super) fn wrap_2pi(psi: f64) -> f64 {
    let w = psi - TWO_PI * libm::floor(psi / TWO_PI);
    if w >= TWO_PI {
        0.0
    } else {
        w
    }
}

/// Angle wrapped to (−π, π].
pub(super) fn wrap_pi(a: f64) -> f64 {
    let w = wrap_2pi(a + PI) - PI;
    if w <= -PI {
        w + TWO_PI
    } else {
        w
    }
}

/// A circular arc given by its start point, start heading, signed curvature
/// (positive = turning counter-clockwise) and length. Curvature 0 is a
/// straight segment (an arc of infinite radius).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Arc {
    /// Start point (x, y) \[m\].
    pub start: [f64; 2],
    /// Direction of the tangent at the start \[rad\].
    pub heading: f64,
    /// Signed curvature 1/ρ \[1/m\].
    pub curvature: f64,
    /// Arc length \[m\].
    pub length: f64,
    /// Whether this arc rounds a sharp corner (the 1 % bound does not apply).
    pub fillet: bool,
}

impl Arc {
    /// The arc from `p` with heading `h` to `q` (the unique circle through both
    /// points tangent to `h` at `p`). The chord angle γ gives the half-turn
    /// α = γ − h; then κ = 2 sin α/|q − p| and L = |q − p|·α/sin α.
    fn through(p: [f64; 2], h: f64, q: [f64; 2], fillet: bool) -> Arc {
        let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
        let chord = libm::hypot(dx, dy);
        let alpha = wrap_pi(libm::atan2(dy, dx) - h);
        Arc {
            start: p,
            heading: h,
            curvature: 2.0 * libm::sin(alpha) / chord,
            length: chord / sinc(alpha),
            fillet,
        }
    }

    /// Point at arc length s from the start: start + s·sinc(κs/2)·(cos, sin)(h + κs/2).
    pub fn point_at(&self, s: f64) -> [f64; 2] {
        let half = 0.5 * self.curvature * s;
        let a = self.heading + half;
        let m = s * sinc(half);
        [
            self.start[0] + m * libm::cos(a),
            self.start[1] + m * libm::sin(a),
        ]
    }

    /// End point.
    pub fn end(&self) -> [f64; 2] {
        self.point_at(self.length)
    }

    /// Tangent heading at the end \[rad\] (not wrapped).
    pub fn end_heading(&self) -> f64 {
        self.heading + self.curvature * self.length
    }

    /// Radius 1/|κ| \[m\] (infinite for a straight segment).
    pub fn radius(&self) -> f64 {
        1.0 / libm::fabs(self.curvature)
    }

    /// Centre of the circle (None for a straight segment).
    pub fn center(&self) -> Option<[f64; 2]> {
        if self.curvature == 0.0 {
            return None;
        }
        let rho = 1.0 / self.curvature;
        Some([
            self.start[0] - rho * libm::sin(self.heading),
            self.start[1] + rho * libm::cos(self.heading),
        ])
    }

    /// Signed swept angle κL \[rad\].
    pub fn sweep(&self) -> f64 {
        self.curvature * self.length
    }
}

/// sin x / x with the limit 1 at 0.
fn sinc(x: f64) -> f64 {
    if libm::fabs(x) < 1e-8 {
        1.0 - x * x / 6.0
    } else {
        libm::sin(x) / x
    }
}

/// The biarc with equal tangent lengths from (p0, h0) to (p1, h1):
/// d solves 2(1 − t0·t1) d² + 2 v·(t0 + t1) d − v·v = 0 with v = p1 − p0,
/// and the joint is (p0 + p1 + d(t0 − t1))/2.
pub(super) fn biarc(p0: [f64; 2], h0: f64, p1: [f64; 2], h1: f64, fillet: bool) -> [Arc; 2] {
    let t0 = [libm::cos(h0), libm::sin(h0)];
    let t1 = [libm::cos(h1), libm::sin(h1)];
    let v = [p1[0] - p0[0], p1[1] - p0[1]];
    let vv = v[0] * v[0] + v[1] * v[1];
    let vt = v[0] * (t0[0] + t1[0]) + v[1] * (t0[1] + t1[1]);
    let denom = 2.0 * (1.0 - (t0[0] * t1[0] + t0[1] * t1[1]));
    let d = if denom.abs() < 1e-12 {
        // parallel tangents: the linear equation 2 v·t d = v·v
        vv / (2.0 * vt)
    } else {
        (-vt + libm::sqrt(vt * vt + denom * vv)) / denom
    };
    let pm = [
        0.5 * (p0[0] + p1[0] + d * (t0[0] - t1[0])),
        0.5 * (p0[1] + p1[1] + d * (t0[1] - t1[1])),
    ];
    let a = Arc::through(p0, h0, pm, fillet);
    let b = Arc::through(pm, a.end_heading(), p1, fillet);
    [a, b]
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::FRAC_PI_2;

    #[test]
    fn arc_geometry() {
        let a = Arc::through([1.0, 0.0], FRAC_PI_2, [0.0, 1.0], false);
        assert!((a.radius() - 1.0).abs() < 1e-15);
        let c = a.center().unwrap();
        assert!(c[0].abs() < 1e-15 && c[1].abs() < 1e-15);
        assert!((a.sweep() - FRAC_PI_2).abs() < 1e-15);
        let e = a.end();
        assert!(e[0].abs() < 1e-15 && (e[1] - 1.0).abs() < 1e-15);
        let line = Arc::through([0.0, 0.0], 0.0, [2.0, 0.0], false);
        assert_eq!(line.curvature, 0.0);
        assert!(line.center().is_none() && (line.length - 2.0).abs() < 1e-15);
    }
}
