//! The accuracy of defaults, each against a converged reference computed
//! the same way with a much finer setting (the guide's Limits and errors,
//! docs/guide/src/limits.md, "Accuracy of the defaults"; the error-controlled
//! Floquet multipliers of `hb duffing` are checked against their estimate in
//! crates/ivt-hb/tests/hsu_steps.rs):
//!
//! - Floquet multipliers of the default Duffing orbit by Hsu's method with
//!   Magnus-4 over 256 fixed sub-intervals (the guide's Rust example of
//!   `StabilityAnalyzer`) against 8192;
//! - `hb string` STHB truncation: N = 5 sine modes and M = 19 harmonics
//!   against M = 39 (harmonic truncation) and N = 15 (modal truncation),
//!   compared on the mid-span displacement w(½, t) over one period;
//! - `stability` Chebyshev Tau order N = 16 of the delay loop against N = 64,
//!   on the max |multiplier| at the default gains.
// A test may unwrap (the package's panic lints guard library code).
#![allow(clippy::unwrap_used)]

use ivt_design::delay::{delay_stability, DelayOptions, FeedbackGains};
use ivt_design::OperatingPoint;
use ivt_hb::problem::Duffing;
use ivt_hb::{c64, HbOptions, HsuRule, ModifiedIhb, StabilityAnalyzer};
use ivt_kin::plant::PlantParams;
use ivt_sthb::{StringHb, StringParams};
use std::f64::consts::PI;

/// Floquet multipliers of the default Duffing orbit (Fig. 28 parameters,
/// n = 20, 2·64 AFT samples) at `omega_f`, by Hsu over `steps` sub-intervals.
fn duffing_multipliers(omega_f: f64, steps: usize) -> Vec<c64> {
    let problem = Duffing::new(0.02, 1.0, 1.0, 0.1);
    let opts = HbOptions::new(20, 64).with_tol(1e-10);
    let sol = ModifiedIhb::new(problem.clone(), opts)
        .and_then(|mut s| s.solve(omega_f, None))
        .unwrap();
    StabilityAnalyzer::new(&problem, 20, steps)
        .unwrap()
        .hsu(&problem, &sol, HsuRule::Magnus4)
        .multipliers
}

/// Largest |μ_i − ν_i| with both sets sorted by (Im, Re): a conjugate pair
/// is split by the sign of Im, a real pair by Re, and the two step counts
/// agree far more closely than any two multipliers of one set differ.
fn multiplier_distance(a: &[c64], b: &[c64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let sorted = |m: &[c64]| {
        let mut v = m.to_vec();
        v.sort_by(|x, y| x.im.total_cmp(&y.im).then(x.re.total_cmp(&y.re)));
        v
    };
    sorted(a)
        .iter()
        .zip(&sorted(b))
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

#[test]
fn floquet_multipliers_of_256_hsu_steps_are_accurate_to_1e_9() {
    // ω_f = 0.4 (the default), 1.2 (upper branch near the resonance peak),
    // 2.0 (above it). Measured 4.7e-11, 4.0e-10, 3.0e-13.
    for omega_f in [0.4, 1.2, 2.0] {
        let default = duffing_multipliers(omega_f, 256);
        let reference = duffing_multipliers(omega_f, 8192);
        let err = multiplier_distance(&default, &reference);
        eprintln!("Floquet, ω_f = {omega_f}: |μ(256) − μ(8192)| = {err:.2e}");
        assert!(err <= 1e-9, "ω_f = {omega_f}: {err:e}");
    }
}

/// max over one period of |w(½, t)| difference between two STHB solutions.
fn midspan_difference(a: (&StringHb, &[f64]), b: (&StringHb, &[f64]), omega: f64) -> f64 {
    let period = 2.0 * PI / omega;
    (0..256)
        .map(|i| {
            let t = period * f64::from(i) / 256.0;
            (a.0.displacement(a.1, 0.5, t) - b.0.displacement(b.1, 0.5, t)).abs()
        })
        .fold(0.0, f64::max)
}

/// Largest |w(½, t)| over one period.
fn midspan_amplitude(hb: &StringHb, a: &[f64], omega: f64) -> f64 {
    let period = 2.0 * PI / omega;
    (0..256)
        .map(|i| hb.displacement(a, 0.5, period * f64::from(i) / 256.0).abs())
        .fold(0.0, f64::max)
}

fn string_solution(p: StringParams, omega: f64) -> (StringHb, Vec<f64>) {
    let mut hb = StringHb::new(p).unwrap();
    let mut a = vec![0.0; hb.dim()];
    hb.solve(omega, &mut a, 1e-11, 60).unwrap();
    (hb, a)
}

#[test]
fn default_sthb_truncation_errors() {
    let default = StringParams::default();
    assert_eq!((default.modes, default.harmonics), (5, 19));
    for omega in [2.0, 5.5] {
        let (hb, a) = string_solution(default.clone(), omega);
        let amplitude = midspan_amplitude(&hb, &a, omega);
        let (hb_m, a_m) = string_solution(
            StringParams {
                harmonics: 39,
                ms: 256,
                ..default.clone()
            },
            omega,
        );
        let (hb_n, a_n) = string_solution(
            StringParams {
                modes: 15,
                ..default.clone()
            },
            omega,
        );
        let harmonic = midspan_difference((&hb, &a), (&hb_m, &a_m), omega) / amplitude;
        let modal = midspan_difference((&hb, &a), (&hb_n, &a_n), omega) / amplitude;
        eprintln!(
            "STHB ω = {omega}: |w(½)| = {amplitude:.4}, M = 19 vs 39: {harmonic:.2e}, N = 5 vs 15: {modal:.2e} (relative)"
        );
        assert!(
            harmonic <= 1e-10,
            "ω = {omega}: harmonic truncation {harmonic:e}"
        );
        assert!(modal <= 1e-3, "ω = {omega}: modal truncation {modal:e}");
    }
}

/// max |multiplier| of the delay loop (Eq. 174–179) at the CLI's default
/// gains (k = 0.01, k2 = 0.02 mm·rad⁻¹) and 100 rpm with Chebyshev order `n`.
fn delay_max_multiplier(v_m: f64, t_u: f64, n: usize) -> f64 {
    let opts = DelayOptions {
        chebyshev_order: n,
        ..Default::default()
    };
    delay_stability(
        &PlantParams::printed(),
        &OperatingPoint::at_100_rpm(v_m, t_u),
        FeedbackGains::from_thesis_mm_per_rad(0.01, 0.02),
        &opts,
    )
    .unwrap()
    .max_abs_multiplier
}

#[test]
fn default_chebyshev_order_error() {
    assert_eq!(DelayOptions::default().chebyshev_order, 16);
    for (v_m, t_u) in [(8.0, 1.5), (11.0, 9.0)] {
        let default = delay_max_multiplier(v_m, t_u, 16);
        let fine = delay_max_multiplier(v_m, t_u, 48);
        let reference = delay_max_multiplier(v_m, t_u, 64);
        let err = (default - reference).abs();
        let converged = (fine - reference).abs();
        eprintln!(
            "Chebyshev ({v_m} V, {t_u} N·m): max |μ| = {reference:.8}, |N16 − N64| = {err:.2e}, |N48 − N64| = {converged:.2e}"
        );
        assert!(err <= 2e-5, "({v_m}, {t_u}): N = 16 off by {err:e}");
        // The reference is converging: N = 48 lies closer to it than N = 16.
        assert!(
            converged < err,
            "({v_m}, {t_u}): N = 48 off by {converged:e}"
        );
    }
}
