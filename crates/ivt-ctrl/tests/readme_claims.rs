//! Numbers of ivt-ctrl that no behavioural test covers, each checked against
//! its closed form: the guide's "Gain units" and "Per pulse" sections
//! (docs/guide/src/controller/inside.md; the crate README's units paragraph).

use ivt_ctrl::units;

/// Eq. 189's K = 50 deg of stepper per rpm, through the SGIVT map Eq. 185
/// (7π/51840 in per deg), is 50 · (60/2π) · 7π/51840 · 0.0254 =
/// 50·60·7·0.0254/(2·51840) = 5.1447e-3 m per rad/s. The f32 conversion
/// rounds three constants and two products (≤ 4 ε relative); the guide
/// prints 5.14e-3, so half a printed unit is 5e-6.
#[test]
fn prop_gain_k50_is_5_14e_3_m_per_rad_s() {
    let exact = 50.0 * 60.0 * 7.0 * 0.0254 / (2.0 * 51840.0);
    let k = f64::from(units::prop_gain_from_deg_per_rpm(
        units::THESIS_PROP_K_DEG_PER_RPM,
    ));
    assert!(
        (k - exact).abs() <= 4.0 * f64::from(f32::EPSILON) * exact,
        "{k} vs {exact}"
    );
    assert!((k - 5.14e-3).abs() < 5e-6, "{k}");
}

/// ω0 = 100 rpm = 10.472 rad/s lies in [8, 16), where the f32 spacing is
/// 2⁻²⁰; rounding ω_a there errs by at most half of it, 2⁻²¹ = 4.77e-7
/// rad/s, printed as 4.8e-7 (half a printed unit: 5e-9).
#[test]
fn f32_rounding_of_omega_a_at_100_rpm_is_half_an_ulp() {
    let w = units::rpm_to_rad_s(100.0);
    let half_ulp = 0.5 * f64::from(f32::from_bits(w.to_bits() + 1) - w);
    assert_eq!(half_ulp, 2f64.powi(-21));
    assert!((half_ulp - 4.8e-7).abs() < 5e-9, "{half_ulp:e}");
}

/// The API section lists the supported resolutions; this is that list.
#[test]
fn supported_ppr_is_the_listed_set() {
    assert_eq!(
        ivt_ctrl::SUPPORTED_PPR,
        &[
            16, 32, 64, 80, 100, 128, 200, 256, 360, 400, 500, 512, 1000, 1024, 1200, 2000, 2048,
            2400, 4096
        ]
    );
}
