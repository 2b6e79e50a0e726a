//! The variant of the SGIVT (§2.3): the noncircular-gear modulation `f(θ)` and
//! the speed chain of Eq. 43–47.

use crate::NCG_AMPLITUDE;
use core::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, SQRT_2};

/// Noncircular-gear speed ratio ω_m/ω = f(θ) = π/(2√2)·max(|sin θ|, |cos θ|), Eq. 43.
///
/// θ is the angle of the driven noncircular gear. The mean of `f` over 2π is 1.
#[inline]
pub fn f(theta: f64) -> f64 {
    NCG_AMPLITUDE * libm::fmax(libm::fabs(libm::sin(theta)), libm::fabs(libm::cos(theta)))
}

/// [`f`] with its domain checked: θ must be finite (a NaN angle gives an
/// error, not a NaN ratio). The unchecked [`f`] stays for the plant's inner loop.
///
/// # Errors
/// `NotFinite` for NaN/inf θ.
pub fn f_checked(theta: f64) -> Result<f64, crate::KinError> {
    Ok(f(crate::error::finite("theta", theta)?))
}

/// [`output_to_motor_ratio`] with its domain checked: r ≥ 0, r_u > 0, finite.
///
/// # Errors
/// `NotFinite` or `OutOfDomain` naming the offending input.
pub fn output_to_motor_ratio_checked(r: f64, r_u: f64) -> Result<f64, crate::KinError> {
    let r = crate::error::in_range("r", r, 0.0, f64::INFINITY, "eccentricity r >= 0")?;
    let r_u = crate::error::positive("r_u", r_u)?;
    Ok(output_to_motor_ratio(r, r_u))
}

/// df/dθ, Eq. 139: −π/(2√2)·sin(mod(θ + π/4, π/2) − π/4).
///
/// Discontinuous at θ = π/4 + kπ/2 (the sharp corners of the gear ratio);
/// there the value of the segment starting at the corner is returned.
#[inline]
pub fn f_theta(theta: f64) -> f64 {
    f_and_f_theta(theta).1
}

/// f and df/dθ from one phase reduction (cheaper in the plant right-hand side).
#[inline]
pub fn f_and_f_theta(theta: f64) -> (f64, f64) {
    f_on_segment(theta, segment_of(theta))
}

/// Index k of the gear segment that contains θ: θ − kπ/2 ∈ [−π/4, π/4).
///
/// The segments are the smooth pieces of f: f = A cos(θ − kπ/2) on segment k
/// (the max of |sin θ|, |cos θ| of Eq. 43), with corners at π/4 + kπ/2 where
/// f_θ jumps (Eq. 139). Every integrator that must keep its order across the
/// corners steps segment by segment with [`f_on_segment`].
#[inline]
pub fn segment_of(theta: f64) -> i64 {
    libm::floor((theta + FRAC_PI_4) / FRAC_PI_2) as i64
}

/// The corner (kink of f) that ends segment `k` going forward: π/4 + kπ/2.
#[inline]
pub fn segment_end(k: i64) -> f64 {
    FRAC_PI_4 + k as f64 * FRAC_PI_2
}

/// f and f_θ on the analytic branch of segment `k` (Eq. 43 and Eq. 139 inside
/// the segment, their smooth continuation just outside it, so a stage
/// evaluated exactly at a corner uses the one-sided value of its own piece).
#[inline]
pub fn f_on_segment(theta: f64, k: i64) -> (f64, f64) {
    let (s, c) = libm::sincos(theta - k as f64 * FRAC_PI_2);
    (NCG_AMPLITUDE * c, -NCG_AMPLITUDE * s)
}

/// [`f_on_segment`] from sin θ and cos θ (no trig call): the branch of
/// segment k rotates (sin θ, cos θ) by k quarter turns.
#[inline]
pub fn f_on_segment_from_trig(sin_theta: f64, cos_theta: f64, k: i64) -> (f64, f64) {
    // (sin φ, cos φ) with φ = θ − kπ/2.
    let (s, c) = match k.rem_euclid(4) {
        0 => (sin_theta, cos_theta),
        1 => (-cos_theta, sin_theta),
        2 => (-sin_theta, -cos_theta),
        _ => (cos_theta, -sin_theta),
    };
    (NCG_AMPLITUDE * c, -NCG_AMPLITUDE * s)
}

/// Exact mean of f² over a period: (π²/8)(1/2 + 1/π) ≈ 1.0095 (SPEC §5).
pub fn mean_f_squared() -> f64 {
    PI * PI / 8.0 * (0.5 + 1.0 / PI)
}

/// Ring-gear speeds of the input-control module, Eq. 44:
/// ω_ri = (2(d_S + d_P)ω ± d_S ω_c)/(d_S + 2 d_P). Returns (ω_r1, ω_r2).
pub fn ring_speeds(omega: f64, omega_c: f64, d_s: f64, d_p: f64) -> (f64, f64) {
    let base = 2.0 * (d_s + d_p) * omega;
    let den = d_s + 2.0 * d_p;
    ((base + d_s * omega_c) / den, (base - d_s * omega_c) / den)
}

/// Driver speeds v_d1 = ω r sin θ, v_d2 = ω r cos θ, Eq. 45–46.
pub fn driver_speeds(theta: f64, omega: f64, r: f64) -> (f64, f64) {
    (omega * r * libm::sin(theta), omega * r * libm::cos(theta))
}

/// Output-shaft speed ω_U = max(|v_d1|, |v_d2|)/r_u, Eq. 47 (first form).
pub fn output_speed(theta: f64, omega: f64, r: f64, r_u: f64) -> f64 {
    let (v1, v2) = driver_speeds(theta, omega, r);
    libm::fmax(libm::fabs(v1), libm::fabs(v2)) / r_u
}

/// The constant output-to-motor speed ratio ω_U/ω_m = 2√2 r/(π r_u), Eq. 47.
pub fn output_to_motor_ratio(r: f64, r_u: f64) -> f64 {
    2.0 * SQRT_2 * r / (PI * r_u)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. 47: ω_U/ω_m is the same at every θ, because f cancels the
    /// rectified-sine shape of the drivers. ω_m = f(θ)ω by Eq. 43.
    #[test]
    fn eq47_output_ratio_constant_over_theta() {
        let (r, r_u, omega) = (0.0067, 0.0222, 10.0);
        let expected = output_to_motor_ratio(r, r_u);
        for k in 0..10_000 {
            let theta = -7.0 + 14.0 * k as f64 / 10_000.0;
            let omega_m = f(theta) * omega;
            let ratio = output_speed(theta, omega, r, r_u) / omega_m;
            assert!(
                (ratio - expected).abs() <= 1e-12 * expected,
                "θ={theta}: {ratio} vs {expected}"
            );
        }
    }

    /// Mean of f over 2π is exactly 1 (text under Eq. 43), and the mean of f²
    /// is the closed form of SPEC §5. Trapezoid rule with the corners on grid
    /// points: error ≤ h²/12 · max|g''| per unit length, i.e. 8.6e-10 for f
    /// (max|f''| = 1.11) and 1.9e-9 for f² (max|(f²)''| = 2·1.11²).
    #[test]
    fn mean_of_f_is_one() {
        let n = 1 << 16;
        let h = 2.0 * PI / n as f64;
        let bound = |g2: f64| h * h / 12.0 * g2;
        let mean: f64 = (0..n).map(|k| f(h * k as f64)).sum::<f64>() / n as f64;
        assert!((mean - 1.0).abs() <= bound(NCG_AMPLITUDE), "{mean}");
        let mean_sq: f64 = (0..n).map(|k| f(h * k as f64).powi(2)).sum::<f64>() / n as f64;
        let g2 = 2.0 * NCG_AMPLITUDE * NCG_AMPLITUDE;
        assert!((mean_sq - mean_f_squared()).abs() <= bound(g2), "{mean_sq}");
    }

    /// Eq. 139 is the derivative of Eq. 43 away from the corners (central differences).
    #[test]
    fn f_theta_is_derivative_of_f() {
        let h = 1e-6;
        for k in 0..1000 {
            let theta = 0.0123 + 2.0 * PI * k as f64 / 1000.0;
            let phi = theta - segment_of(theta) as f64 * FRAC_PI_2;
            if (phi.abs() - FRAC_PI_4).abs() < 1e-4 {
                continue; // within h of a corner
            }
            let fd = (f(theta + h) - f(theta - h)) / (2.0 * h);
            assert!((fd - f_theta(theta)).abs() < 1e-8, "θ={theta}");
            let (fv, ft) = f_and_f_theta(theta);
            assert!((fv - f(theta)).abs() < 1e-15 && (ft - f_theta(theta)).abs() < 1e-15);
        }
    }

    /// The segments tile the axis between the corners π/4 + kπ/2; inside
    /// each, the analytic branch is Eq. 43 (the max form of [`f`]), and the
    /// trig-free rotation gives the same branch.
    #[test]
    fn segment_branches_match_eq43() {
        assert_eq!(segment_of(segment_end(3) + 1e-12), 4);
        assert_eq!(segment_of(segment_end(3) - 1e-12), 3);
        assert_eq!(segment_of(-FRAC_PI_4), 0);
        for k in 0..4000 {
            let th = -20.0 + k as f64 * 0.01037;
            let seg = segment_of(th);
            let (fv, ft) = f_on_segment(th, seg);
            assert!((fv - f(th)).abs() < 1e-14, "θ={th}");
            let (f2, ft2) = f_on_segment_from_trig(libm::sin(th), libm::cos(th), seg);
            assert!(
                (f2 - fv).abs() < 1e-14 && (ft2 - ft).abs() < 1e-14,
                "θ={th}"
            );
        }
    }

    /// Eq. 44 with ω_c = 0 and d_S = d_P gives ω_r = 4ω/3 (Eq. 141).
    #[test]
    fn ring_speeds_without_control() {
        let (a, b) = ring_speeds(3.0, 0.0, 1.0, 1.0);
        assert!((a - 4.0).abs() < 1e-15 && (b - 4.0).abs() < 1e-15);
        let (a, b) = ring_speeds(0.0, 3.0, 1.0, 1.0);
        assert!((a + b).abs() < 1e-15 && (a - 1.0).abs() < 1e-15);
    }
}
