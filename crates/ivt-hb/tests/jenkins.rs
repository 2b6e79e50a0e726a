//! The Jenkins element (issue 27, item 6): its first harmonic against the
//! describing function in closed form, and a forced oscillator's orbit against
//! time integration of the hysteretic ODE, with the order of convergence in n.
#![allow(clippy::unwrap_used)]

use ivt_hb::orbit::aft::eval_series;
use ivt_hb::{Element, ElementProblem, Harmonic, HbOptions, HbResidual, Law, ModifiedIhb};
use std::f64::consts::PI;

/// `ẍ + 2ξẋ + x + F_J(x) = force·cos θ` with a Jenkins element to ground.
fn oscillator(xi: f64, k: f64, slip_force: f64, force: f64) -> ElementProblem {
    ElementProblem::new(
        1,
        [vec![1.0], vec![2.0 * xi], vec![1.0]],
        vec![Element {
            a: 0,
            b: None,
            law: Law::Jenkins { k, slip_force },
        }],
        vec![Harmonic {
            dof: 0,
            amplitude: force,
            phase: 0.0,
        }],
    )
    .unwrap()
}

/// First-harmonic coefficients `(a₁, b₁)` of the Jenkins force along
/// `δ = A cos τ` (elastic–perfectly-plastic describing function):
/// `a₁ = (kA/π)(φ − sin 2φ / 2)`, `b₁ = −(4F_s/π)(1 − F_s/(kA))` with
/// `cos φ = 1 − 2F_s/(kA)` once it slips (A > F_s/k), else `(kA, 0)`.
fn describing_function(k: f64, fs: f64, a: f64) -> (f64, f64) {
    if k * a <= fs {
        return (k * a, 0.0);
    }
    let phi = (1.0 - 2.0 * fs / (k * a)).acos();
    (
        k * a / PI * (phi - 0.5 * (2.0 * phi).sin()),
        -4.0 * fs / PI * (1.0 - fs / (k * a)),
    )
}

#[test]
fn first_harmonic_is_the_describing_function() {
    let (k, fs) = (1.3, 0.7);
    // 2N = 2²² samples: the force's kinks between samples err by O(h²) ≈ 1e-12
    // in the quadrature (the turning points τ = 0, π are samples).
    let hb = HbOptions::new(1, 1 << 21);
    let p = oscillator(0.0, k, fs, 0.0);
    let mut res = HbResidual::new(&p, &hb).unwrap();
    for a in [0.3, 0.6, 1.0, 2.5, 10.0] {
        let q = [0.0, a, 0.0];
        let (mut full, mut linear) = ([0.0; 3], [0.0; 3]);
        res.eval(&p, &q, 1.0, 1.0, &mut full);
        res.eval(&p, &q, 1.0, 0.0, &mut linear);
        let (a1, b1) = (full[1] - linear[1], full[2] - linear[2]);
        let (w1, v1) = describing_function(k, fs, a);
        eprintln!("A = {a}: a₁ {a1:.15} ({w1:.15}), b₁ {b1:.15} ({v1:.15})");
        assert!(
            (a1 - w1).abs() < 1e-10 && (b1 - v1).abs() < 1e-10,
            "A = {a}"
        );
        assert!((full[0] - linear[0]).abs() < 1e-10, "mean at A = {a}");
    }
}

/// One period of `x` at 64 points after `periods` periods from rest: RK4 with
/// `per` steps per period on (x, ẋ), the slider moved by the play operator at
/// the end of each step and the force `clamp(k(x − z), ±F_s)` at the stages.
fn time_reference(
    (xi, k, fs, force, omega): (f64, f64, f64, f64, f64),
    periods: usize,
    per: usize,
) -> Vec<f64> {
    let dt = 2.0 * PI / omega / per as f64;
    let (mut x, mut v, mut z) = (0.0f64, 0.0f64, 0.0f64);
    let half = fs / k;
    let accel = |t: f64, x: f64, v: f64, z: f64| {
        let zz = z.clamp(x - half, x + half);
        force * (omega * t).cos() - 2.0 * xi * v - x - k * (x - zz)
    };
    let mut out = Vec::with_capacity(64);
    for step in 0..periods * per + per {
        if step >= periods * per && (step - periods * per).is_multiple_of(per / 64) {
            out.push(x);
        }
        let t = step as f64 * dt;
        let (k1x, k1v) = (v, accel(t, x, v, z));
        let (k2x, k2v) = (
            v + 0.5 * dt * k1v,
            accel(t + 0.5 * dt, x + 0.5 * dt * k1x, v + 0.5 * dt * k1v, z),
        );
        let (k3x, k3v) = (
            v + 0.5 * dt * k2v,
            accel(t + 0.5 * dt, x + 0.5 * dt * k2x, v + 0.5 * dt * k2v, z),
        );
        let (k4x, k4v) = (v + dt * k3v, accel(t + dt, x + dt * k3x, v + dt * k3v, z));
        x += dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        v += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        z = z.clamp(x - half, x + half);
    }
    out
}

#[test]
fn forced_orbit_converges_in_n_to_time_integration() {
    let params = (0.05, 1.0, 0.3, 0.5, 1.2);
    let (xi, k, fs, force, omega) = params;
    let (reference, finer) = (
        time_reference(params, 300, 12_800),
        time_reference(params, 300, 25_600),
    );
    let ref_err = reference
        .iter()
        .zip(&finer)
        .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
    eprintln!("time reference: halving the step moves it by {ref_err:.1e}");
    assert!(ref_err < 1e-6);
    let p = oscillator(xi, k, fs, force);
    let mut errors = Vec::new();
    for n in [4, 8, 16, 32, 64] {
        let hb = HbOptions::new(n, 32 * n).with_max_iter(400);
        let sol = ModifiedIhb::new(&p, hb)
            .unwrap()
            .solve(omega, None)
            .unwrap();
        let err = finer
            .iter()
            .enumerate()
            .map(|(j, x)| (eval_series(sol.dof(0), 2.0 * PI * j as f64 / 64.0, 0) - x).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "n = {n}: max |x_HB − x_RK| = {err:.2e} (amplitude {:.4})",
            sol.amplitude(0)
        );
        errors.push((n as f64, err));
    }
    // Measured order: the least-squares slope of ln(err) against ln(n).
    let m = errors.len() as f64;
    let (sx, sy) = errors
        .iter()
        .fold((0.0, 0.0), |a, (n, e)| (a.0 + n.ln(), a.1 + e.ln()));
    let sxx: f64 = errors.iter().map(|(n, _)| n.ln().powi(2)).sum();
    let sxy: f64 = errors.iter().map(|(n, e)| n.ln() * e.ln()).sum();
    let slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
    eprintln!("order of convergence in n: {:.2}", -slope);
    assert!(errors.last().unwrap().1 < 1e-4);
    assert!(-slope > 1.5, "order {}", -slope);
}
