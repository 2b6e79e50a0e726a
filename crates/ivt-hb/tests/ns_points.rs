//! The Neimark–Sacker boundary of the forced Van der Pol oscillator
//! `ẍ − 0.2(1 − x²)ẋ + x = F cos ω_f t` in (ω_f, F), sampled at F = 0.2,
//! 0.25, 0.3 (issue 27, item 1): each point against shooting on RK4 (no HB):
//! a fixed point of the period map whose Jacobian has determinant 1 (the
//! product of a complex pair on the unit circle).

use ivt_hb::{neimark_sacker_points, GeneralProblem, HbError, HbOptions, PeriodicProblem};

mod common;
use common::shooting::{central_jacobian, flow, newton3, orbit_state};

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

/// `[P(y) − y, det ∂P/∂y − 1]` at ω of the forcing F.
fn ns_residual(force: f64, u: [f64; 3]) -> [f64; 3] {
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
    [
        p[0] - y[0],
        p[1] - y[1],
        j[0][0] * j[1][1] - j[0][1] * j[1][0] - 1.0,
    ]
}

#[test]
fn neimark_sacker_boundary_points_match_shooting() {
    let forces = [0.2, 0.25, 0.3];
    let points =
        neimark_sacker_points(van_der_pol, &HbOptions::new(9, 32), 0.5, 1.6, &forces).unwrap();
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
        eprintln!(
            "F = {}: NS ω {:.10} (shooting {:.10}), |Δω| {:.1e}",
            pt.p,
            pt.omega,
            u[2],
            (pt.omega - u[2]).abs()
        );
        assert!(
            (pt.omega - u[2]).abs() < 1e-7,
            "F = {}: {} vs {}",
            pt.p,
            pt.omega,
            u[2]
        );
        assert!((pt.multipliers[0].norm() - 1.0).abs() < 1e-9 && pt.multipliers[0].im.abs() > 0.0);
    }
    // The point (0.94525643, 0.2) is on the boundary.
    assert!(points
        .iter()
        .any(|p| p.p == 0.2 && (p.omega - 0.94525643).abs() < 1e-8));
}
