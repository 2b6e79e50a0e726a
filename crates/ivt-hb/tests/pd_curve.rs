//! The period-doubling curve of the thesis Mathieu–Duffing oscillator
//! (Eq. 81, ξ̂ = 0.125, α̂ = γ = 1) in (Ω, β), continued from the first
//! doubling of the cascade at Ω = 2 (issue 27, item 1). References by
//! shooting on RK4 (no HB): a fixed point of the period map whose Jacobian
//! has the multiplier −1, det(∂P/∂y + I) = 0.

use ivt_hb::branches::codim2::{bifurcation_curve, CurveStart};
use ivt_hb::problem::boxed_family;
use ivt_hb::{
    period_doubling_cascade, BifurcationKind, CascadeOptions, HbError, HbOptions, MathieuDuffing,
    Termination,
};

mod common;
use common::shooting::{central_jacobian, flow, newton3, orbit_state};

/// `[P(y) − y, det(∂P/∂y + I)]` at `u = (x0, v0, Ω)` for β.
fn pd_residual(beta: f64, u: [f64; 3]) -> [f64; 3] {
    let (y, w) = ([u[0], u[1]], u[2]);
    let rhs = |t: f64, y: [f64; 2]| {
        [
            y[1],
            -0.25 * y[1] + (1.0 + beta * (w * t).sin()) * y[0] - y[0].powi(3),
        ]
    };
    let period = std::f64::consts::TAU / w;
    let p = flow(rhs, y, period, 4000);
    let mut j = central_jacobian(|y| flow(rhs, y, period, 4000), y, [1e-6; 2]);
    j[0][0] += 1.0;
    j[1][1] += 1.0;
    [
        p[0] - y[0],
        p[1] - y[1],
        j[0][0] * j[1][1] - j[0][1] * j[1][0],
    ]
}

#[test]
fn mathieu_duffing_period_doubling_curve_matches_shooting() {
    let n = 20;
    let cascade = period_doubling_cascade(&CascadeOptions {
        harmonics: n,
        doublings: 1,
        ..CascadeOptions::default()
    })
    .unwrap();
    let pd = &cascade[0];
    let start = CurveStart {
        kind: BifurcationKind::PeriodDoubling,
        coeffs: pd.solution.coeffs.clone(),
        omega: 2.0,
        p: pd.beta,
    };
    let family =
        |beta: f64| -> Result<MathieuDuffing, HbError> { Ok(MathieuDuffing::thesis(beta)) };
    let opts = common::curve_steps(400);
    let hb = HbOptions::new(n, 4 * n);
    let curve = bifurcation_curve(
        &boxed_family(family),
        &hb,
        &start,
        4.0,
        6.0,
        &[4.5, 5.0, 5.5],
        &opts,
    )
    .unwrap();
    assert_eq!(curve.termination, Termination::LeftInterval);
    let ps: Vec<f64> = curve.at.iter().map(|a| a.p).collect();
    assert_eq!(ps, [4.5, 5.0, 5.5]);
    let ends = (
        curve.points.first().unwrap().p,
        curve.points.last().unwrap().p,
    );
    assert_eq!(ends, (4.0, 6.0));
    assert!(curve.resonances.is_empty());
    // The start: the cascade's β₁ (thesis 4.825) at Ω = 2, corrected in Ω.
    assert!(curve
        .points
        .iter()
        .any(|p| (p.omega - 2.0).abs() < 1e-4 && (p.p - 4.825).abs() < 1e-3));
    // The `at` points and every fourth point of the path against shooting.
    for pt in curve.at.iter().chain(curve.points.iter().step_by(4)) {
        assert_eq!(pt.angle, std::f64::consts::PI);
        let y = orbit_state(&pt.coeffs, pt.omega);
        // Measured: |ΔΩ| ≤ 2.5e-8.
        let u = newton3(|u| pd_residual(pt.p, u), [y[0], y[1], pt.omega]);
        let d = pt.omega - u[2];
        assert!(
            d.abs() < 1e-7,
            "β = {}: {} vs {}, {d:e}",
            pt.p,
            pt.omega,
            u[2]
        );
    }
}
