//! STHB at scale (issue 28, item 4): the refined monodromy's error estimate
//! against a 8×-step RK4, and
//! the scaling driver of `bench/sthb_scaling.sh` (ignored; prints JSON lines).
#![allow(clippy::unwrap_used)]

use faer::Mat;
use ivt_sthb::frc::{frequency_response, StringFrcOptions};
use ivt_sthb::stability::{
    default_steps, monodromy, monodromy_matrix, monodromy_refined, StabilityMethod,
};
use ivt_sthb::{StringHb, StringParams};
use std::time::Instant;

#[path = "common/string.rs"]
mod string;
use string::solved;

/// Critical multiplier modulus of an RK4 monodromy with `steps` steps.
fn critical(hb: &StringHb, omega: f64, steps: usize) -> f64 {
    let phi: Mat<f64> = monodromy_matrix(hb, omega, steps).unwrap();
    phi.eigenvalues()
        .unwrap()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

#[test]
fn refined_monodromy_error_estimate_covers_its_error() {
    // Against RK4 with 8× the default steps (error 4096× below the default's):
    // the Richardson estimate |μ_h − μ_{h/2}| bounds the refined |μ|'s error.
    for (modes, omega) in [(5, 2.0), (5, 3.8), (10, 5.5)] {
        let (hb, _) = solved(modes, 19, 10.0, omega, 1e-12);
        let coarse = monodromy(&hb, omega).unwrap();
        let (fine, estimate) = monodromy_refined(&hb, omega, &coarse).unwrap();
        assert_eq!(fine.method, StabilityMethod::MonodromyRefined);
        let truth = critical(&hb, omega, 8 * default_steps(&hb, omega));
        let error = (fine.critical().norm() - truth).abs();
        assert!(
            error <= estimate,
            "N = {modes}, ω = {omega}: error {error:e} > estimate {estimate:e}"
        );
        assert!(estimate < 1e-3, "estimate {estimate:e}");
    }
}

/// CPU seconds of this process (utime + stime from /proc, 10 ms ticks).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .map(|s| s.parse().unwrap_or(0.0))
        .collect();
    (f.get(11).copied().unwrap_or(0.0) + f.get(12).copied().unwrap_or(0.0)) / 100.0
}

#[test]
#[ignore = "scaling driver of bench/sthb_scaling.sh (minutes)"]
fn scaling() {
    // SIZES="5x19 10x39 ..." (default: the grid of the table in docs/guide/src/accuracy-speed.md).
    let sizes = std::env::var("SIZES")
        .unwrap_or_else(|_| "5x9 5x19 5x39 10x9 10x19 10x39 20x9 20x19 20x39".to_string());
    for size in sizes.split_whitespace() {
        let (n, m) = size.split_once('x').unwrap();
        let (modes, harmonics): (usize, usize) = (n.parse().unwrap(), m.parse().unwrap());
        let mut hb = StringHb::new(StringParams {
            modes,
            harmonics,
            ..Default::default()
        })
        .unwrap();
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let curve = frequency_response(&mut hb, 1.0, 6.0, &StringFrcOptions::default()).unwrap();
        let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
        let points = curve.frc.points.len();
        println!(
            "{{\"modes\": {modes}, \"harmonics\": {harmonics}, \"unknowns\": {}, \"points\": {points}, \"jacobians\": {}, \"folds\": {}, \"wall_s\": {wall:.4}, \"cpu_s\": {cpu:.3}}}",
            hb.dim(),
            curve.jacobians,
            curve.frc.events.len()
        );
    }
}

#[test]
fn split_monodromy_has_the_full_matrix_multipliers() {
    // The curve's multipliers come from the odd/even-mode blocks; the public
    // monodromy_matrix integrates all modes together.
    for (modes, omega) in [(6, 3.8), (7, 2.0)] {
        let (hb, _) = solved(modes, 9, 30.0, omega, 1e-12);
        let split = ivt_sthb::stability::monodromy_multipliers(&hb, omega).unwrap();
        let phi = monodromy_matrix(&hb, omega, default_steps(&hb, omega)).unwrap();
        let mut full: Vec<f64> = phi
            .eigenvalues()
            .unwrap()
            .iter()
            .map(|z| z.norm())
            .collect();
        full.sort_by(|a, b| b.total_cmp(a));
        assert_eq!(split.len(), full.len());
        for (s, f) in split.iter().zip(&full) {
            assert!((s.norm() - f).abs() <= 1e-12, "{} vs {f}", s.norm());
        }
    }
}

#[test]
fn twenty_modes_thirty_nine_harmonics_whole_curve_with_stability() {
    // Issue 28's case that did not finish in 15 minutes (1580 unknowns): the
    // whole curve, every point a solution of the full system, every turn
    // located, every point with a verdict (no time is asserted here; see the
    // guide's docs/guide/src/accuracy-speed.md and bench/sthb_scaling.sh).
    let mut hb = StringHb::new(StringParams {
        modes: 20,
        harmonics: 39,
        ..Default::default()
    })
    .unwrap();
    assert_eq!(ivt_sthb::stability::HILL_MAX_DIM, 800);
    let curve = frequency_response(&mut hb, 1.0, 6.0, &StringFrcOptions::default()).unwrap();
    let frc = &curve.frc;
    assert!((frc.points.last().unwrap().omega_f - 6.0).abs() < 1e-12);
    let n = hb.dim();
    let mut r = vec![0.0; n];
    for p in &frc.points {
        hb.residual(&p.coeffs, p.omega_f, &mut r);
        let norm = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!(norm <= 1.5e-10 * 1.01, "ω = {}: ‖R‖ = {norm:e}", p.omega_f);
    }
    assert!(!frc.events.is_empty());
    for f in &frc.events {
        assert!(f.located, "fold near ω = {}", f.omega_f);
        hb.residual(&f.coeffs, f.omega_f, &mut r);
        assert!(r.iter().map(|x| x * x).sum::<f64>().sqrt() <= 1e-8);
    }
    // Hill's 3160-row matrix is never built; the confirmations carry an estimate.
    assert_eq!(curve.hill_calls, 0);
    for (p, m) in frc.points.iter().zip(&curve.methods) {
        assert_eq!(
            p.multiplier_error.is_some(),
            *m == StabilityMethod::MonodromyRefined
        );
    }
    // Unstable exactly between turns is Fig. 35's pattern; here: some of each.
    assert!(frc.points.iter().any(|p| !p.stable()));
    assert!(frc.points.iter().filter(|p| p.stable()).count() > 150);
}
