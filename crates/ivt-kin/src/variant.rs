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
    -NCG_AMPLITUDE * libm::sin(wrapped_phase(theta))
}

/// f and df/dθ from one phase reduction (cheaper in the plant right-hand side).
#[inline]
pub fn f_and_f_theta(theta: f64) -> (f64, f64) {
    let phi = wrapped_phase(theta);
    // On each segment f = A·cos(φ) with φ ∈ [−π/4, π/4): the max of |sin|, |cos|.
    (
        NCG_AMPLITUDE * libm::cos(phi),
        -NCG_AMPLITUDE * libm::sin(phi),
    )
}

/// φ = mod(θ + π/4, π/2) − π/4 ∈ [−π/4, π/4), the phase inside one gear segment.
#[inline]
fn wrapped_phase(theta: f64) -> f64 {
    let x = theta + FRAC_PI_4;
    let m = x - FRAC_PI_2 * libm::floor(x / FRAC_PI_2);
    m - FRAC_PI_4
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
            let phi = wrapped_phase(theta);
            if (phi.abs() - FRAC_PI_4).abs() < 1e-4 {
                continue; // within h of a corner
            }
            let fd = (f(theta + h) - f(theta - h)) / (2.0 * h);
            assert!((fd - f_theta(theta)).abs() < 1e-8, "θ={theta}");
            let (fv, ft) = f_and_f_theta(theta);
            assert!((fv - f(theta)).abs() < 1e-15 && (ft - f_theta(theta)).abs() < 1e-15);
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
