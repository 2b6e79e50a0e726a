//! Shooting, the references without HB: Newton in the plane with a
//! central-difference Jacobian, and the RK4 period map of the thesis Duffing
//! (Eq. 49) for the fold-curve and all-solutions tests.
#![allow(clippy::indexing_slicing)]

use ivt_hb::orbit::aft::eval_series;
use ivt_hb::problem::ode::{first_order, rk4};
use ivt_hb::Duffing;
use std::f64::consts::PI;

/// RK4 steps per period of the period map.
pub const STEPS: usize = 4000;

/// The period map of `duffing` at ω: the state `y = (x, ẋ)` at t = 0 carried
/// over 2π/ω (RK4, [`STEPS`] steps).
pub fn period_map(duffing: &Duffing, omega: f64, y: [f64; 2]) -> [f64; 2] {
    let mut y = y;
    rk4(
        first_order(duffing, omega),
        0.0,
        &mut y,
        2.0 * PI / omega / STEPS as f64,
        STEPS,
    );
    y
}

/// ∂P/∂y − I of [`period_map`] at `y` by central differences (step 1e-6).
pub fn period_map_jacobian(duffing: &Duffing, omega: f64, y: [f64; 2]) -> [[f64; 2]; 2] {
    let mut j = central_jacobian(|y| period_map(duffing, omega, y), y, [1e-6; 2]);
    j[0][0] -= 1.0;
    j[1][1] -= 1.0;
    j
}

/// `J[i][k] = ∂f_i/∂u_k` at `u` by central differences with steps `h[k]`.
pub fn central_jacobian(
    f: impl Fn([f64; 2]) -> [f64; 2],
    u: [f64; 2],
    h: [f64; 2],
) -> [[f64; 2]; 2] {
    let mut j = [[0.0; 2]; 2];
    for k in 0..2 {
        let (mut up, mut um) = (u, u);
        up[k] += h[k];
        um[k] -= h[k];
        let (a, b) = (f(up), f(um));
        for i in 0..2 {
            j[i][k] = (a[i] - b[i]) / (2.0 * h[k]);
        }
    }
    j
}

/// Newton in the plane on `residual` from `u`, the Jacobian by central
/// differences with steps `h(u)`, until both components of a step are below
/// `tol`: the root, or None after 40 steps.
pub fn newton_plane(
    residual: impl Fn([f64; 2]) -> [f64; 2],
    mut u: [f64; 2],
    h: impl Fn([f64; 2]) -> [f64; 2],
    tol: [f64; 2],
) -> Option<[f64; 2]> {
    for _ in 0..40 {
        let r = residual(u);
        let step = newton_step(central_jacobian(&residual, u, h(u)), r);
        u[0] += step[0];
        u[1] += step[1];
        if step[0].abs() < tol[0] && step[1].abs() < tol[1] {
            return Some(u);
        }
    }
    None
}

/// The Newton step `−J⁻¹ r` in the plane (Cramer's rule).
pub fn newton_step(j: [[f64; 2]; 2], r: [f64; 2]) -> [f64; 2] {
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    [
        -(j[1][1] * r[0] - j[0][1] * r[1]) / det,
        -(j[0][0] * r[1] - j[1][0] * r[0]) / det,
    ]
}

/// Newton with a central-difference Jacobian on three unknowns `u` of
/// `residual(u) = 0`.
pub fn newton3(residual: impl Fn([f64; 3]) -> [f64; 3], mut u: [f64; 3]) -> [f64; 3] {
    for _ in 0..30 {
        let r = residual(u);
        let mut j = [[0.0; 3]; 3];
        for k in 0..3 {
            let h = 1e-5 * u[k].abs().max(0.1);
            let (mut up, mut um) = (u, u);
            up[k] += h;
            um[k] -= h;
            let (a, b) = (residual(up), residual(um));
            for i in 0..3 {
                j[i][k] = (a[i] - b[i]) / (2.0 * h);
            }
        }
        let d = solve3(j, [-r[0], -r[1], -r[2]]);
        for k in 0..3 {
            u[k] += d[k];
        }
        if d.iter().all(|x| x.abs() < 1e-12) {
            return u;
        }
    }
    u
}

/// Cramer's rule for a 3×3 system.
pub fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    let mut x = [0.0; 3];
    for k in 0..3 {
        let mut m = a;
        for i in 0..3 {
            m[i][k] = b[i];
        }
        x[k] = det(m) / d;
    }
    x
}

/// The orbit's state (x(0), ẋ(0)) from its coefficients at ω.
pub fn orbit_state(coeffs: &[f64], omega: f64) -> [f64; 2] {
    [
        eval_series(coeffs, 0.0, 0),
        omega * eval_series(coeffs, 0.0, 1),
    ]
}

/// `x₀` of the turning state `(x₀, 0)` of an HB orbit: its maximum of x
/// over τ on 20000 samples (the phase of an autonomous cycle is free).
pub fn turning_state(coeffs: &[f64]) -> f64 {
    (0..20000)
        .map(|i| eval_series(coeffs, std::f64::consts::TAU * i as f64 / 20000.0, 0))
        .fold(f64::MIN, f64::max)
}

/// Asserts that the HB frequency `omega` of a located `what` point at `F = p`
/// is shooting's `shooting` within 1e-7 (both printed).
pub fn assert_omega_matches_shooting(what: &str, p: f64, omega: f64, shooting: f64) {
    eprintln!(
        "F = {p}: {what} ω {omega:.10} (shooting {shooting:.10}), |Δω| {:.1e}",
        (omega - shooting).abs()
    );
    assert!(
        (omega - shooting).abs() < 1e-7,
        "F = {p}: {omega} vs {shooting}"
    );
}

/// `y(t_end)` of the planar system `y' = rhs(t, y)` from `y0` at t = 0 (RK4,
/// `steps` steps).
pub fn flow(
    rhs: impl Fn(f64, [f64; 2]) -> [f64; 2],
    y0: [f64; 2],
    t_end: f64,
    steps: usize,
) -> [f64; 2] {
    let mut y = y0;
    let f = |t: f64, y: &[f64], dy: &mut [f64]| dy.copy_from_slice(&rhs(t, [y[0], y[1]]));
    rk4(f, 0.0, &mut y, t_end / steps as f64, steps);
    y
}
