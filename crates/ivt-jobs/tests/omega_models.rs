//! Models that read the excitation frequency (issue 27, item 7): the Duffing
//! oscillator ξ = 0.02, α = ε = 1 driven by a rotating unbalance
//! `0.03 ω_f² cos θ`. The FRC's folds (traced with ∂R/∂ω_f including the
//! force's ω-dependence) against shooting on RK4 (no HB): a fold is a fixed
//! point of the period map with det(∂P/∂y − I) = 0, the force at each trial
//! ω being `0.03 ω²`.
#![allow(clippy::indexing_slicing)]

use ivt_hb::{
    frequency_response, Corrector, Duffing, FrcOptions, FrequencyExcitation, GeneralProblem,
    HbOptions, ModifiedIhb, PeriodicProblem,
};
use ivt_jobs::{self as jobs, FrcRequest};

#[path = "../../ivt-hb/tests/common/mod.rs"]
mod common;
use common::shooting::{newton3, orbit_state, period_map, period_map_jacobian};

/// `ü + 0.04 u̇ + u + u³ = 0.03 ω_f² cos θ` with `f(θ, ω_f)` a closure.
fn unbalanced() -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![0.04],
        vec![1.0],
        |x: &[f64], _v: &[f64], _th: f64, g: &mut [f64]| g[0] = x[0] * x[0] * x[0],
        |_: f64, f: &mut [f64]| f.fill(0.0),
    )
    .with_velocity_dependent(false)
    .with_excitation(FrequencyExcitation(|th: f64, w: f64, f: &mut [f64]| {
        f[0] = 0.03 * w * w * th.cos()
    }))
}

/// The fold's ω by shooting from the HB fold's state `y` and `omega`.
fn shooting_fold(y: [f64; 2], omega: f64) -> f64 {
    let u = newton3(
        |u| {
            let d = Duffing::new(0.02, 1.0, 1.0, 0.03 * u[2] * u[2]);
            let (y, w) = ([u[0], u[1]], u[2]);
            let p = period_map(&d, w, y);
            let j = period_map_jacobian(&d, w, y);
            [
                p[0] - y[0],
                p[1] - y[1],
                j[0][0] * j[1][1] - j[0][1] * j[1][0],
            ]
        },
        [y[0], y[1], omega],
    );
    u[2]
}

/// Each `(ω, coeffs)` fold within 1e-7 of shooting.
fn assert_folds_match_shooting(folds: &[(f64, Vec<f64>)]) {
    assert_eq!(
        folds.len(),
        2,
        "{:?}",
        folds.iter().map(|f| f.0).collect::<Vec<_>>()
    );
    for (omega, coeffs) in folds {
        let reference = shooting_fold(orbit_state(coeffs, *omega), *omega);
        eprintln!(
            "fold ω {omega:.10} (shooting {reference:.10}), |Δω| {:.1e}",
            (omega - reference).abs()
        );
        assert!((omega - reference).abs() < 1e-7, "{omega} vs {reference}");
    }
}

#[test]
fn rotating_unbalance_folds_match_shooting() {
    let problem = unbalanced();
    let hb = HbOptions::new(15, 64);
    let mut sweep = FrcOptions::default();
    (sweep.from, sweep.to) = (0.5, 2.5);
    let frc = frequency_response(&problem, &hb, &sweep).unwrap();
    assert!(frc.events.iter().all(|f| f.located));
    let folds: Vec<_> = frc
        .events
        .iter()
        .map(|f| (f.omega_f, f.coeffs.clone()))
        .collect();
    assert_folds_match_shooting(&folds);
    // The job with events (the path `ivt.hb.frc` takes) finds the same folds.
    let req = FrcRequest {
        options: FrcOptions::sweep(0.5, 2.5, Corrector::Newton),
        events: true,
    };
    let curve = jobs::frc(&problem, &hb, &req).unwrap();
    assert!(curve.folds.iter().all(|f| f.located));
    let folds: Vec<_> = curve
        .folds
        .iter()
        .map(|f| (f.omega, f.coeffs.0.clone()))
        .collect();
    assert_folds_match_shooting(&folds);
}

#[test]
fn unbound_frequency_dependent_model_is_refused() {
    // Without an ω_f the force is NaN: a solver handed the model itself
    // (not bound to its frequency) fails cleanly instead of solving another.
    let problem = unbalanced();
    assert!(problem.frequency_dependent());
    let err = ModifiedIhb::new(&problem, HbOptions::new(5, 16)).err();
    assert!(err.is_some_and(|e| e.to_string().contains("not finite")));
}
