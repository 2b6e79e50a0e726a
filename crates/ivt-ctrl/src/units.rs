//! Unit conversions at the edges, and the **one place** where the thesis's
//! gain units are interpreted (SPEC §5).
//!
//! # Gain units
//! Eq. 171/180 write `dr_d/dθ = k(ω_a − ω0) + k2(ω − ω_T)` with r in metres,
//! θ in rad and ω in rad/s, so k and k2 carry `m·s/rad²` ("metres of
//! eccentricity per radian of θ, per rad/s of speed error"). The thesis prints
//! them as "mm·rad⁻¹" (k = 0.01, k2 = 0.02; 0.06/0.12; 0.04/0.15 for Eq. 181).
//! **Interpretation chosen:** the printed number is millimetres of r per radian
//! of θ per rad/s of error, i.e. `k_SI = 1e-3 · k_printed` with speeds in
//! rad/s (not rpm). [`gain_from_mm_per_rad`] is the only conversion; every
//! other part of the crate works in SI.
//!
//! The experimental law Eq. 189 uses `K = 50` in degrees of stepper angle per
//! rpm of speed error and per sample; [`prop_gain_from_deg_per_rpm`] turns it
//! into metres of eccentricity per rad/s through the SGIVT map Eq. 185.

use core::f32::consts::PI;

/// Metres per inch.
pub const M_PER_INCH: f32 = 0.0254;

/// rad/s per rpm.
pub const RAD_S_PER_RPM: f32 = 2.0 * PI / 60.0;

/// Eq. 185: crank length per stepper angle of the SGIVT prototype,
/// `e = 7π/51840 · θ_CT` with e in inch and θ_CT in degrees.
pub const SGIVT_INCH_PER_DEG: f32 = 7.0 * PI / 51840.0;

/// Eq. 185 in SI: metres of eccentricity per degree of stepper angle.
pub const SGIVT_M_PER_DEG: f32 = SGIVT_INCH_PER_DEG * M_PER_INCH;

/// The gain K of the driving test, Eq. 189 (§4.4.3: "K = 50 was finally used").
pub const THESIS_PROP_K_DEG_PER_RPM: f32 = 50.0;

/// rpm → rad/s.
#[must_use]
pub fn rpm_to_rad_s(rpm: f32) -> f32 {
    rpm * RAD_S_PER_RPM
}

/// rad/s → rpm.
#[must_use]
pub fn rad_s_to_rpm(omega: f32) -> f32 {
    omega / RAD_S_PER_RPM
}

/// A thesis gain printed in "mm·rad⁻¹" (Eq. 180/181, §4.3) → SI `m·s/rad²`.
/// See the module doc for the interpretation.
#[must_use]
pub fn gain_from_mm_per_rad(k_printed: f32) -> f32 {
    k_printed * 1e-3
}

/// Eq. 189 gain K \[deg of stepper per rpm of error\] → metres of eccentricity
/// per rad/s of error, through the SGIVT map Eq. 185.
#[must_use]
pub fn prop_gain_from_deg_per_rpm(k_deg_per_rpm: f32) -> f32 {
    k_deg_per_rpm * SGIVT_M_PER_DEG / RAD_S_PER_RPM
}
