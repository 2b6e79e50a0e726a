//! Damped nonlinear modes (EPMC, issue 27 item 5): the vanishing-amplitude
//! limit against the linear modes in closed form, a damped Duffing against
//! the exact (elliptic-integral) frequency of its free oscillation, and the
//! undamped case against `backbone`.
#![allow(clippy::indexing_slicing)]

mod common;
use common::tight_backbone;
use ivt_hb::{
    backbone, damped_modes, linear_mode, BackboneOptions, GeneralProblem, HbError, HbOptions,
    PeriodicProblem, Termination,
};
use std::f64::consts::PI;

/// Two unit masses, springs 1 (ground–0), 1 (0–1), 1 (1–ground) → K = [[2, −1],
/// [−1, 2]], modes ω = 1 (φ = [1, 1]) and √3 (φ = [1, −1]); damping
/// C = αM + βK; a cubic spring k₃x₀³ on DOF 0.
fn chain(alpha: f64, beta: f64, k3: f64) -> impl PeriodicProblem {
    let k = vec![2.0, -1.0, -1.0, 2.0];
    let c = vec![alpha + 2.0 * beta, -beta, -beta, alpha + 2.0 * beta];
    GeneralProblem::new(
        2,
        vec![1.0, 0.0, 0.0, 1.0],
        c,
        k,
        move |x: &[f64], _v: &[f64], _th: f64, out: &mut [f64]| {
            out[0] = k3 * x[0].powi(3);
            out[1] = 0.0;
        },
        |_th: f64, out: &mut [f64]| out.fill(0.0),
    )
    .with_velocity_dependent(false)
}

#[test]
fn vanishing_amplitude_is_the_linear_mode() {
    let (alpha, beta) = (0.05, 0.01);
    let p = chain(alpha, beta, 0.5);
    let hb = HbOptions::new(7, 32);
    for (mode, omega_i) in [(0, 1.0f64), (1, 3.0f64.sqrt())] {
        let opts = BackboneOptions {
            amplitude_from: 1e-7,
            amplitude_to: 1e-3,
            ..BackboneOptions::default()
        };
        let dm = damped_modes(&p, &hb, mode, &opts).unwrap();
        let first = &dm.points[0];
        let zeta = (alpha + beta * omega_i * omega_i) / (2.0 * omega_i);
        eprintln!(
            "mode {mode}: ω {:.15} (linear {omega_i:.15}), ζ {:.15} (linear {zeta:.15})",
            first.omega, first.damping_ratio
        );
        // The cubic term shifts ω by ~(3/8)k₃a²/ω ≈ 2e-15 at a = 1e-7.
        assert!((first.omega - omega_i).abs() < 1e-10 * omega_i);
        assert!((first.damping_ratio - zeta).abs() < 1e-10 * zeta);
        assert!((dm.linear_omega - omega_i).abs() < 1e-12);
        assert_eq!(first.amplitude, 1e-7);
    }
}

/// Exact frequency of `ẍ + x + εx³ = 0` with amplitude A:
/// `ω = π√(1 + εA²) / (2K(m))`, `m = εA²/(2(1 + εA²))`, K by the AGM.
fn duffing_free_omega(eps: f64, a: f64) -> f64 {
    let m = eps * a * a / (2.0 * (1.0 + eps * a * a));
    let (mut x, mut y) = (1.0f64, (1.0 - m).sqrt());
    for _ in 0..40 {
        (x, y) = (0.5 * (x + y), (x * y).sqrt());
    }
    let k = PI / (2.0 * x);
    PI * (1.0 + eps * a * a).sqrt() / (2.0 * k)
}

fn duffing(c: f64) -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![c],
        vec![1.0],
        |x: &[f64], _v: &[f64], _th: f64, out: &mut [f64]| out[0] = x[0].powi(3),
        |_th: f64, out: &mut [f64]| out[0] = 0.0,
    )
    .with_velocity_dependent(false)
}

#[test]
fn damped_duffing_has_the_exact_free_frequency_and_damping_c_over_2_omega() {
    // One DOF: κ = −c cancels the damping exactly, so ω(A) is the conservative
    // frequency and ζ = c/(2ω) at every amplitude.
    let c = 0.04;
    let n = 21;
    let hb = HbOptions::new(n, 4 * n);
    let opts = tight_backbone(0.01, 1.5, 0.1, 0.2);
    let dm = damped_modes(&duffing(c), &hb, 0, &opts).unwrap();
    assert_eq!(dm.termination, Termination::LeftInterval);
    assert!(dm.points.len() >= 5, "{} points", dm.points.len());
    for p in &dm.points {
        // b₁ = 0 and the orbit is even in τ: its peak is x(0) = a0/2 + Σ a_k.
        let peak: f64 = 0.5 * p.coeffs[0] + p.coeffs[1..=n].iter().sum::<f64>();
        let exact = duffing_free_omega(1.0, peak);
        assert!(
            (p.omega - exact).abs() < 1e-9 * exact,
            "A = {peak}: {} vs {exact}",
            p.omega
        );
        let zeta_err = (p.damping_ratio - c / (2.0 * p.omega)).abs();
        eprintln!(
            "a₁ = {:.4}: ω {:.12} (exact {exact:.12}), ζ error {zeta_err:.1e}",
            p.amplitude, p.omega
        );
        assert!(zeta_err < 1e-9 * c);
    }
}

#[test]
fn undamped_damped_mode_is_the_backbone() {
    let p = chain(0.0, 0.0, 0.5);
    let hb = HbOptions::new(9, 40);
    let opts = BackboneOptions {
        amplitude_from: 0.01,
        amplitude_to: 1.0,
        ..BackboneOptions::default()
    };
    let dm = damped_modes(&p, &hb, 1, &opts).unwrap();
    let (omega0, shape) = linear_mode(&p, 1).unwrap();
    assert!((omega0 - 3.0f64.sqrt()).abs() < 1e-12);
    assert!((shape[0] - 1.0).abs() < 1e-12 && (shape[1] + 1.0).abs() < 1e-12);
    let bb = backbone(&p, &hb, omega0, &shape, &opts).unwrap();
    assert_eq!(dm.points.len(), bb.points.len());
    for (d, b) in dm.points.iter().zip(&bb.points) {
        assert!((d.amplitude - b.amplitude).abs() < 1e-12);
        assert!((d.omega - b.omega).abs() < 1e-9 * b.omega);
        assert!(d.damping_ratio.abs() < 1e-9);
    }
}

#[test]
fn a_missing_mode_or_a_node_is_invalid_input() {
    let p = chain(0.01, 0.0, 0.5);
    let hb = HbOptions::new(5, 16);
    assert!(matches!(
        damped_modes(&p, &hb, 2, &BackboneOptions::default()),
        Err(HbError::InvalidInput(_))
    ));
}
