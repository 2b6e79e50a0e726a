//! The Neimark–Sacker boundary of the forced Van der Pol oscillator
//! `ẍ − 0.2(1 − x²)ẋ + x = F cos ω_f t` in (ω_f, F) (issue 27, item 1),
//! sampled at F = 0.2, 0.25, 0.3 and continued from the point
//! (0.94525643, 0.2): each point against shooting on RK4 (no HB): a fixed
//! point of the period map whose Jacobian has determinant 1 (the product of
//! a complex pair on the unit circle) and half trace cos θ.
#![allow(clippy::indexing_slicing)]

use ivt_hb::branches::codim2::{bifurcation_curve, CurveStart};
use ivt_hb::problem::boxed_family;
use ivt_hb::{
    BifurcationKind, ContinuationOptions, Corrector, FrcOptions, GeneralProblem, HbError,
    HbOptions, PeriodicProblem, Termination,
};
use ivt_jobs::neimark_sacker_points;

#[path = "../../ivt-hb/tests/common/mod.rs"]
mod common;
use common::shooting::{
    assert_omega_matches_shooting, central_jacobian, flow, newton3, orbit_state,
};

/// The FRC over ω_f ∈ [0.5, 1.6] with the Newton–chord corrector.
fn newton_sweep() -> FrcOptions {
    FrcOptions::sweep(0.5, 1.6, Corrector::Newton)
}

/// The family in F.
fn van_der_pol(force: f64) -> Result<impl PeriodicProblem, HbError> {
    Ok(GeneralProblem::new(
        1,
        vec![1.0],
        vec![-0.2],
        vec![1.0],
        |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| g[0] = 0.2 * x[0] * x[0] * v[0],
        move |t: f64, out: &mut [f64]| out[0] = force * t.cos(),
    ))
}

/// The period map's fixed-point defect `P(y) − y` and Jacobian `∂P/∂y` at
/// `u = (x0, v0, ω)` for the forcing F.
fn period_map(force: f64, u: [f64; 3]) -> ([f64; 2], [[f64; 2]; 2]) {
    let (y, w) = ([u[0], u[1]], u[2]);
    let rhs = |t: f64, y: [f64; 2]| {
        [
            y[1],
            0.2 * (1.0 - y[0] * y[0]) * y[1] - y[0] + force * (w * t).cos(),
        ]
    };
    let period = std::f64::consts::TAU / w;
    let p = flow(rhs, y, period, 4000);
    let j = central_jacobian(|y| flow(rhs, y, period, 4000), y, [1e-6; 2]);
    ([p[0] - y[0], p[1] - y[1]], j)
}

/// `[P(y) − y, det ∂P/∂y − 1]` at ω of the forcing F.
fn ns_residual(force: f64, u: [f64; 3]) -> [f64; 3] {
    let (d, j) = period_map(force, u);
    [d[0], d[1], j[0][0] * j[1][1] - j[0][1] * j[1][0] - 1.0]
}

#[test]
fn neimark_sacker_boundary_points_match_shooting() {
    let forces = [0.2, 0.25, 0.3];
    let points = neimark_sacker_points(
        van_der_pol,
        &HbOptions::new(9, 32),
        &newton_sweep(),
        &forces,
    )
    .unwrap();
    eprintln!(
        "{:?}",
        points.iter().map(|p| (p.p, p.omega)).collect::<Vec<_>>()
    );
    // Lock-in and unlock at F = 0.25 and 0.3; at F = 0.2 the trace locates
    // the lock-in point only (measured; the sample is not a continuation).
    for (force, least) in forces.iter().zip([1, 2, 2]) {
        let found = points.iter().filter(|p| p.p == *force).count();
        assert!(found >= least, "F = {force}: {found}");
    }
    for pt in &points {
        let y = orbit_state(&pt.coeffs, pt.omega);
        let u = newton3(|u| ns_residual(pt.p, u), [y[0], y[1], pt.omega]);
        assert_omega_matches_shooting("NS", pt.p, pt.omega, u[2]);
        assert!((pt.multipliers[0].norm() - 1.0).abs() < 1e-9 && pt.multipliers[0].im.abs() > 0.0);
    }
    // The point (0.94525643, 0.2) is on the boundary.
    assert!(points
        .iter()
        .any(|p| p.p == 0.2 && (p.omega - 0.94525643).abs() < 1e-8));
}

/// The shooting NS point at F from the HB point's state and ω: `(x0, v0, ω)`
/// and the half trace of the period map's Jacobian (cos θ).
fn shoot(force: f64, coeffs: &[f64], omega: f64) -> ([f64; 3], f64) {
    let y = orbit_state(coeffs, omega);
    let u = newton3(|u| ns_residual(force, u), [y[0], y[1], omega]);
    let (_, j) = period_map(force, u);
    (u, 0.5 * (j[0][0] + j[1][1]))
}

#[test]
fn van_der_pol_neimark_sacker_curve_matches_shooting() {
    let hb = HbOptions::new(9, 32);
    let ns = neimark_sacker_points(van_der_pol, &hb, &newton_sweep(), &[0.2]).unwrap();
    let first = ns
        .iter()
        .find(|p| (p.omega - 0.94525643).abs() < 1e-6)
        .unwrap();
    let start = CurveStart {
        kind: BifurcationKind::NeimarkSacker,
        coeffs: first.coeffs.clone(),
        omega: first.omega,
        p: 0.2,
    };
    // First towards F = 0: the curve ends at the 1:1 resonance (θ = 0, on
    // the fold curve) near F = 0.1924, then runs from the start up to 0.4.
    let steps = ContinuationOptions {
        max_points: 400,
        ds: 0.01,
        ds_max: 0.02,
        ..Default::default()
    };
    let at = [0.2, 0.3, 0.4];
    let curve = bifurcation_curve(
        &boxed_family(van_der_pol),
        &hb,
        &start,
        0.0,
        0.4,
        &at,
        &steps,
    )
    .unwrap();
    assert_eq!(curve.termination, Termination::LeftInterval);
    let ps: Vec<f64> = curve.at.iter().map(|a| a.p).collect();
    assert_eq!(ps, [0.2, 0.3, 0.4]);
    assert!(curve.points.windows(2).all(|w| w[0].p < w[1].p));
    assert!(curve.points.iter().all(|p| p.angle > 0.0 && p.angle < 1.1));
    // The `at` points and every eighth point of the path against shooting.
    for pt in curve.at.iter().chain(curve.points.iter().step_by(8)) {
        // Measured: |Δω| ≤ 3e-10, |Δθ| ≤ 6e-7 (θ → 0 at the 1:1 end).
        let (u, cos_theta) = shoot(pt.p, &pt.coeffs, pt.omega);
        let (dw, dt) = (pt.omega - u[2], pt.angle - cos_theta.acos());
        assert!(
            dw.abs() < 1e-7 && dt.abs() < 1e-5,
            "F = {}: {dw:e}, {dt:e}",
            pt.p
        );
    }
    // The point is on the curve (the start, located again at 0.2).
    assert!((curve.at[0].omega - 0.94525643).abs() < 1e-8);
    // The 1:1 resonance: by shooting, the F where the half trace of the
    // period map's Jacobian on the det = 1 curve (NS, then neutral saddle)
    // reaches 1, by the secant method.
    let [(1, r11)] = curve.resonances.as_slice() else {
        panic!("{:?}", curve.resonances);
    };
    let excess = |f: f64| shoot(f, &r11.coeffs, r11.omega).1 - 1.0;
    let (mut a, mut b) = (r11.p - 1e-4, r11.p + 1e-4);
    let (mut fa, mut fb) = (excess(a), excess(b));
    while (b - a).abs() > 1e-13 {
        (a, fa, b) = (b, fb, b - fb * (b - a) / (fb - fa));
        fb = excess(b);
    }
    let (u, _) = shoot(b, &r11.coeffs, r11.omega);
    eprintln!(
        "1:1 at F {:.10} ω {:.10}; shooting F {b:.10} ω {:.10}",
        r11.p, r11.omega, u[2]
    );
    assert!((r11.p - b).abs() < 1e-7 && (r11.omega - u[2]).abs() < 1e-7);
    assert_eq!(r11.angle, 0.0);
}
