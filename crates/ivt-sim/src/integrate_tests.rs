//! Tests of [`super`]: the time and angle domains of the one integrator.

use super::*;
use ivt_kin::plant::PlantParams;
use std::f64::consts::PI;

fn dp5(rtol: f64) -> Method {
    Method::Dp5(Tolerance::uniform(rtol))
}

/// The angle cache returns exactly `AngleTerms::new` for every (θ, segment)
/// in an RK4-like access pattern, including θ = 0 on segment 0 first (an
/// empty slot must not match) and the same θ on another segment.
#[test]
fn angle_cache_is_exact() {
    let cache = AngleCache::default();
    let h = 2.0 * PI / 1200.0;
    let mut theta = 0.0;
    for n in 0..2000 {
        let seg = crate::plant::segment_of(theta);
        for (x, s) in [
            (theta, seg),
            (theta + 0.5 * h, seg),
            (theta + 0.5 * h, seg),
            (theta + h, seg),
            (theta + h, seg + 1),
        ] {
            let want = AngleTerms::new(x, s);
            let got = cache.get(x, s);
            assert_eq!(got, want, "step {n}, θ = {x}, segment {s}");
            assert!(got.f.is_finite());
        }
        theta += h;
    }
}

/// The same 10 s run at rtol = atol = 1e-12, once forced to stay in the
/// time domain and once in the angle domain: ω at the same final angle
/// agrees to 1e-9 rad/s (acceptance, issue 6). Both land on every corner.
#[test]
fn time_and_angle_domain_agree() {
    let plant = Plant::new(PlantParams::printed());
    let prof = ConstantInputs { v_m: 8.0, t_u: 6.0 };
    let r = 0.006;
    let theta_end = 60.0; // ≈ 6 s at ~10 rad/s
    let mut a = PlantIntegrator::new(plant, dp5(1e-12), 0.0, 0.0, 8.0, 0.0);
    a.omega_handover = f64::INFINITY; // time domain only
    assert_eq!(a.advance(&prof, r, theta_end, 1e9).unwrap(), Reached::Angle);
    let mut b = PlantIntegrator::new(plant, dp5(1e-12), 0.0, 0.0, 8.0, 0.0);
    assert_eq!(b.advance(&prof, r, theta_end, 1e9).unwrap(), Reached::Angle);
    assert!(a.stats.angle_steps == 0 && b.stats.time_steps == 0);
    let dw = (a.omega() - b.omega()).abs();
    let dt = (a.t - b.t).abs();
    assert!(dw <= 1e-9, "Δω = {dw:e}");
    assert!(dt <= 1e-9, "Δt = {dt:e}");
}

/// From rest: the time domain hands over to the angle domain once
/// ω > ω_handover and the run reaches its target.
#[test]
fn start_up_from_rest_hands_over() {
    let plant = Plant::new(PlantParams::printed());
    let prof = ConstantInputs { v_m: 8.0, t_u: 4.0 };
    let mut it = PlantIntegrator::new(plant, dp5(1e-9), 0.0, 0.0, 0.0, 0.0);
    it.advance(&prof, 0.005, 20.0 * PI, 1e9).unwrap();
    assert!(it.stats.time_steps > 0 && it.stats.angle_steps > 0);
    assert!(it.omega() > 5.0, "ω = {}", it.omega());
}

/// A stalled plant (load larger than drive) stays at ω = 0 instead of
/// spinning backwards, and stops at the time limit.
#[test]
fn overload_holds_at_rest() {
    let plant = Plant::new(PlantParams::printed());
    let prof = ConstantInputs { v_m: 1.0, t_u: 9.0 };
    let mut it = PlantIntegrator::new(plant, dp5(1e-9), 0.0, 0.1, 0.0, 0.0);
    assert_eq!(it.advance(&prof, 0.012, 10.0, 2.0).unwrap(), Reached::Time);
    assert!(it.omega() >= 0.0 && it.theta() <= 10.0);
}
