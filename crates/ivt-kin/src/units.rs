//! Unit conversions at the edges (SPEC §4): everything inside the crate is SI
//! (metres, radians, seconds); inch, degree and rpm appear only through these
//! named helpers.

use core::f64::consts::PI;

/// One inch in metres (exact by definition).
pub const INCH: f64 = 0.0254;

/// Inches → metres.
#[inline]
pub fn inch_to_m(inch: f64) -> f64 {
    inch * INCH
}

/// Metres → inches.
#[inline]
pub fn m_to_inch(m: f64) -> f64 {
    m / INCH
}

/// Degrees → radians.
#[inline]
pub fn deg_to_rad(deg: f64) -> f64 {
    deg * (PI / 180.0)
}

/// Radians → degrees.
#[inline]
pub fn rad_to_deg(rad: f64) -> f64 {
    rad * (180.0 / PI)
}

/// Revolutions per minute → rad/s.
#[inline]
pub fn rpm_to_rad_s(rpm: f64) -> f64 {
    rpm * (2.0 * PI / 60.0)
}

/// rad/s → revolutions per minute.
#[inline]
pub fn rad_s_to_rpm(rad_s: f64) -> f64 {
    rad_s * (60.0 / (2.0 * PI))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips() {
        assert_eq!(inch_to_m(1.0), 0.0254);
        assert!((m_to_inch(inch_to_m(5.25)) - 5.25).abs() < 1e-15);
        assert!((deg_to_rad(180.0) - PI).abs() < 1e-15);
        assert!((rad_to_deg(deg_to_rad(3600.0)) - 3600.0).abs() < 1e-12);
        assert!((rpm_to_rad_s(60.0) - 2.0 * PI).abs() < 1e-15);
        assert!((rad_s_to_rpm(rpm_to_rad_s(100.0)) - 100.0).abs() < 1e-12);
    }
}
