//! Folds of limit cycles in two parameters (issue 27, item 1) of
//! `ẍ − (μ + νx² − x⁴)ẋ + x = 0`: the fold of the cycle branch at ν = 1
//! (μ = −0.124993216903, tests/cycle_branch.rs) followed in ν down to 0.3 and
//! up to 1.5, its μ at several ν against time integration (RK4, no HB): a
//! cycle through `(x₀, 0)` of period T solves `y(T; x₀, μ) = (x₀, 0)`, and a
//! fold of cycles adds `det ∂(y(T) − y₀)/∂(x₀, T) = 0`, solved by Newton in
//! `(x₀, T, μ)`. Averaging gives the fold near `μ = −ν²/8` (a loose check of
//! the curve's shape).
#![allow(clippy::indexing_slicing)]

use ivt_hb::branches::codim2::cycle_fold_curve;
use ivt_hb::problem::{bautin, boxed_family};
use ivt_hb::{cycle_branch, HbError, HbOptions, PeriodicProblem};

mod common;
use common::shooting::{central_jacobian, flow, newton3, turning_state};

/// The family `ẍ − (μ + νx² − x⁴)ẋ + x = 0` (`bautin`).
fn family(mu: f64, nu: f64) -> Result<impl PeriodicProblem, HbError> {
    Ok(bautin(mu, nu))
}

/// `y(T; (x₀, 0)) − (x₀, 0)` at (μ, ν) (RK4, 4000 steps).
fn gap(mu: f64, nu: f64, x0: f64, period: f64) -> [f64; 2] {
    let rhs = |_t: f64, y: [f64; 2]| [y[1], (mu + nu * y[0] * y[0] - y[0].powi(4)) * y[1] - y[0]];
    let y = flow(rhs, [x0, 0.0], period, 4000);
    [y[0] - x0, y[1]]
}

/// The fold of cycles at ν by shooting on `(x₀, T, μ)` from a guess.
fn fold_by_shooting(nu: f64, guess: [f64; 3]) -> [f64; 3] {
    newton3(
        |u| {
            let r = gap(u[2], nu, u[0], u[1]);
            let j = central_jacobian(|w| gap(u[2], nu, w[0], w[1]), [u[0], u[1]], [1e-6; 2]);
            [r[0], r[1], j[0][0] * j[1][1] - j[0][1] * j[1][0]]
        },
        guess,
    )
}

#[test]
fn cycle_fold_curve_matches_shooting_in_nu() {
    let hb = HbOptions::new(25, 128);
    let branch = cycle_branch(
        &boxed_family(|mu| family(mu, 1.0)),
        &hb,
        -0.2,
        0.1,
        &Default::default(),
    )
    .unwrap();
    assert_eq!(branch.folds.len(), 1);
    let (mu0, start) = &branch.folds[0];
    let opts = common::curve_steps(2000);
    let down = cycle_fold_curve(
        family,
        &hb,
        start,
        (*mu0, 1.0),
        (0.3, 1.5),
        &[0.35, 0.5, 0.7, 0.9, 1.0],
        &opts,
    )
    .unwrap();
    let up = cycle_fold_curve(
        family,
        &hb,
        start,
        (*mu0, 1.0),
        (1.5, 0.3),
        &[1.2, 1.45],
        &opts,
    )
    .unwrap();
    let nus = |c: &ivt_hb::branches::codim2::CycleFoldCurve| {
        c.at.iter().map(|p| p.fold.p).collect::<Vec<_>>()
    };
    assert_eq!(
        nus(&down),
        [0.35, 0.5, 0.7, 0.9, 1.0],
        "{:?}",
        down.termination
    );
    assert_eq!(nus(&up), [1.2, 1.45], "{:?}", up.termination);
    // The curve reaches both ends and has no turning point in ν there.
    for curve in [&down, &up] {
        assert!(curve.cusps.is_empty());
        let last = curve.points.last().unwrap();
        assert!(
            last.fold.p <= 0.3 + 1e-9 || last.fold.p >= 1.5 - 1e-9,
            "{}",
            last.fold.p
        );
    }
    for cycle_fold in down.at.iter().chain(&up.at) {
        let point = &cycle_fold.fold;
        let mu = cycle_fold.mu;
        let guess = [
            turning_state(&point.coeffs),
            std::f64::consts::TAU / point.omega,
            mu,
        ];
        let [_, _, mu_ref] = fold_by_shooting(point.p, guess);
        let averaging = -point.p * point.p / 8.0;
        eprintln!(
            "ν = {:.2}: HB μ = {:.12}, shooting {mu_ref:.12}, |Δ| {:.1e}, averaging {averaging:.6}",
            point.p,
            mu,
            (mu - mu_ref).abs()
        );
        assert!((mu - mu_ref).abs() < 1e-8, "{} vs {mu_ref}", mu);
        assert!((mu - averaging).abs() < 0.05 * averaging.abs());
    }
    let at_one = down.at.iter().find(|p| p.fold.p == 1.0).unwrap();
    assert!((at_one.mu - -0.124993216903).abs() < 1e-8, "{}", at_one.mu);
}
