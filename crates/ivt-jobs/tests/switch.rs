//! Branch switching ([`ivt_jobs::switch`]) checked by shooting (RK4 with
//! Newton on the period map, sharing no code with the HB path): the period-2
//! branch of a forced Duffing oscillator in a well, born at a period doubling,
//! and the symmetry-breaking branch of a symmetric 2-DOF chain at a pitchfork.
#![allow(
    clippy::indexing_slicing,
    clippy::panic,
    clippy::unreachable,
    clippy::unwrap_used
)]

use ivt_hb::orbit::aft::eval_series;
use ivt_hb::problem::ode::{first_order, rk4};
use ivt_hb::{BifurcationKind, GeneralProblem, HbOptions, PeriodicProblem};
use ivt_jobs::{self as jobs, SwitchRequest, SwitchStart, SwitchedBranch};
use std::f64::consts::PI;

/// The twin-well Duffing ü + 0.1u̇ − u + u³ = 0.5 cos ω_f t about its well
/// u = 1 (x = u − 1): ẍ + 0.1ẋ + 2x + 3x² + x³ = 0.5 cos ω_f t. The quadratic
/// term makes the forced orbit excite x's own oscillation at ω_f/2 near
/// ω_f = 2√2: a period doubling.
fn well() -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![0.1],
        vec![2.0],
        |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| g[0] = 3.0 * x[0] * x[0] + x[0].powi(3),
        |t: f64, f: &mut [f64]| f[0] = 0.5 * t.cos(),
    )
    .with_velocity_dependent(false)
}

/// Two equal masses, cubic springs to ground, in-phase forcing (the chain of
/// tests/bifurcation.rs): the symmetric response loses the anti-phase mode's
/// stability at a pitchfork.
fn chain() -> impl PeriodicProblem {
    let (stiff, damp) = ([1.1, 0.1, 0.1, 1.1], 0.02);
    GeneralProblem::new(
        2,
        vec![1.0, 0.0, 0.0, 1.0],
        vec![damp, 0.0, 0.0, damp],
        stiff.to_vec(),
        |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
            g.iter_mut().zip(x).for_each(|(gi, xi)| *gi = xi.powi(3))
        },
        |t: f64, f: &mut [f64]| f.fill(0.05 * t.cos()),
    )
    .with_velocity_dependent(false)
}

/// The state `[x…, ẋ…]` after `periods` periods 2π/ω_f from `y` (RK4, 2000
/// steps per period).
fn flow<P: PeriodicProblem>(p: &P, omega: f64, y: &[f64], periods: usize) -> Vec<f64> {
    let mut y = y.to_vec();
    let steps = 2000 * periods;
    let t = periods as f64 * 2.0 * PI / omega;
    rk4(first_order(p, omega), 0.0, &mut y, t / steps as f64, steps);
    y
}

/// Solves `a x = b` (row-major, small) by Gaussian elimination with pivoting.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))
            .unwrap();
        for k in 0..n {
            a.swap(c * n + k, p * n + k);
        }
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r * n + c] / a[c * n + c];
            for k in c..n {
                a[r * n + k] -= f * a[c * n + k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| a[r * n + k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r * n + r];
    }
    x
}

/// The monodromy matrix over `periods` periods at `y` (central differences).
fn monodromy<P: PeriodicProblem>(p: &P, omega: f64, y: &[f64], periods: usize) -> Vec<f64> {
    let n = y.len();
    let mut phi = vec![0.0; n * n];
    for k in 0..n {
        let (mut up, mut um) = (y.to_vec(), y.to_vec());
        up[k] += 1e-6;
        um[k] -= 1e-6;
        let (a, b) = (flow(p, omega, &up, periods), flow(p, omega, &um, periods));
        for i in 0..n {
            phi[i * n + k] = (a[i] - b[i]) / 2e-6;
        }
    }
    phi
}

/// Shooting: Newton on `P^periods(y) − y` from `y`; the fixed point.
fn shoot<P: PeriodicProblem>(p: &P, omega: f64, mut y: Vec<f64>, periods: usize) -> Vec<f64> {
    let n = y.len();
    for _ in 0..30 {
        let r: Vec<f64> = flow(p, omega, &y, periods)
            .iter()
            .zip(&y)
            .map(|(a, b)| a - b)
            .collect();
        let mut j = monodromy(p, omega, &y, periods);
        for i in 0..n {
            j[i * n + i] -= 1.0;
        }
        let step = solve(j, r.iter().map(|v| -v).collect());
        y.iter_mut().zip(&step).for_each(|(a, s)| *a += s);
        // 1e-10: the monodromy by differences limits the rate next to a fold.
        if step.iter().all(|s| s.abs() < 1e-10) {
            return y;
        }
    }
    panic!("shooting did not converge at ω_f = {omega}");
}

/// `[x…, ẋ…]` at t = 0 of a point's coefficients (`dofs` DOFs, response
/// frequency ω_f / `sub`).
fn state(coeffs: &[f64], dofs: usize, omega: f64, sub: usize) -> Vec<f64> {
    let l = coeffs.len() / dofs;
    let w = omega / sub as f64;
    let dof = |d: usize| &coeffs[d * l..(d + 1) * l];
    (0..dofs)
        .map(|d| eval_series(dof(d), 0.0, 0))
        .chain((0..dofs).map(|d| w * eval_series(dof(d), 0.0, 1)))
        .collect()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Every `stride`-th point of the new branch (and its last) checked by
/// shooting over `sub` periods: the HB state is the shooting fixed point to
/// `tol`; returns the largest deviation and the smallest |P(y) − y| over one
/// excitation period.
fn check_by_shooting<P: PeriodicProblem>(
    p: &P,
    branch: &SwitchedBranch,
    stride: usize,
    tol: f64,
) -> (f64, f64) {
    let (dofs, sub) = (p.n_dof(), branch.subharmonic);
    let pts = &branch.curve.points;
    let (mut worst, mut gap) = (0.0f64, f64::INFINITY);
    for pt in pts.iter().step_by(stride).chain(pts.last()) {
        let y_hb = state(&pt.coeffs.0, dofs, pt.omega, sub);
        let y = shoot(p, pt.omega, y_hb.clone(), sub);
        let dev = max_diff(&y, &y_hb);
        assert!(dev < tol, "ω_f {}: HB vs shooting {dev:e}", pt.omega);
        worst = worst.max(dev);
        // The shooting monodromy's verdict is the point's, away from |μ| = 1.
        let phi = monodromy(p, pt.omega, &y, sub);
        let mu = max_modulus(&phi, 2 * dofs);
        if (mu - 1.0).abs() > 1e-3 {
            assert_eq!(pt.stable, mu < 1.0, "ω_f {}: |μ|max {mu}", pt.omega);
        }
        gap = gap.min(max_diff(&flow(p, pt.omega, &y, 1), &y));
    }
    (worst, gap)
}

/// Largest multiplier modulus of the `n × n` row-major monodromy `phi`
/// (nalgebra's eigenvalues, not the HB path's).
fn max_modulus(phi: &[f64], n: usize) -> f64 {
    nalgebra::DMatrix::from_row_slice(n, n, phi)
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

fn event(curve: &jobs::FrcCurve<jobs::FoldPoint>, kind: BifurcationKind) -> SwitchStart {
    let e = curve
        .bifurcations
        .iter()
        .find(|e| e.kind == kind && e.located)
        .unwrap_or_else(|| panic!("no {kind:?}: {:?}", curve.bifurcations));
    SwitchStart::Given {
        kind,
        omega: e.omega.unwrap(),
        coeffs: e.coeffs.clone().unwrap().0,
    }
}

/// The first located event of `kind` on the FRC of `p` from `from` to `to`.
fn frc_event<P: PeriodicProblem>(
    p: &P,
    hb: &HbOptions,
    (from, to): (f64, f64),
    kind: BifurcationKind,
) -> (SwitchStart, f64) {
    let req = jobs::FrcRequest {
        options: ivt_hb::FrcOptions::sweep(from, to, ivt_hb::Corrector::Newton),
        events: true,
    };
    let curve = jobs::frc(p, hb, &req).unwrap();
    let start = event(&curve, kind);
    let SwitchStart::Given { omega, .. } = start else {
        unreachable!()
    };
    (start, omega)
}

/// The branch switched onto at the first located `kind` event of the FRC of
/// `p` from `from` to `to`, with the event's ω_f (asserted within 1e-4 of
/// `expected`), after the switch towards `from` (the side the new branch does
/// not leave to) was refused by name.
fn switched<P: PeriodicProblem>(
    p: &P,
    hb: &HbOptions,
    (from, to): (f64, f64),
    kind: BifurcationKind,
    expected: f64,
) -> (SwitchedBranch, f64) {
    let (start, omega) = frc_event(p, hb, (from, to), kind);
    assert!((omega - expected).abs() < 1e-4, "{omega}");
    let e = switch_to(p, hb, &start, from).unwrap_err();
    assert_eq!(e.kind(), "input");
    assert!(e.to_string().contains("must lie on that side"), "{e}");
    (switch_to(p, hb, &start, to).unwrap(), omega)
}

/// The new branch towards `to`, or the job's error.
fn switch_to<P: PeriodicProblem>(
    p: &P,
    hb: &HbOptions,
    start: &SwitchStart,
    to: f64,
) -> Result<SwitchedBranch, ivt_hb::HbError> {
    let req = SwitchRequest {
        start: start.clone(),
        to,
        ..SwitchRequest::default()
    };
    jobs::switch(p, hb, &req)
}

#[test]
fn period_two_branch_of_the_duffing_well_is_a_period_two_orbit_by_shooting() {
    let p = well();
    let hb = HbOptions::new(10, 32);
    // The forced orbit doubles at ω_f = 2.93667 and 2.60375 (measured).
    // The period-2 branch is born towards lower ω_f (subcritical in ω_f):
    // `to` above it is refused by name.
    let (b, w_pd) = switched(
        &p,
        &hb,
        (3.6, 2.2),
        BifurcationKind::PeriodDoubling,
        2.93667,
    );
    assert_eq!(b.kind, BifurcationKind::PeriodDoubling);
    assert_eq!((b.harmonics, b.subharmonic), (20, 2));
    assert_eq!(b.curve.termination, ivt_hb::Termination::LeftInterval);
    assert!(b.curve.points.len() >= 10, "{}", b.curve.points.len());
    let first = b.curve.points[0].omega;
    assert!(first < w_pd && w_pd - first < 1e-3, "{first}");
    // Every 3rd point: the HB orbit is the shooting orbit over 2T (measured
    // ≤ 7e-11) and not one over T (|P(y) − y| ≥ 1e-2 measured).
    let (dev, gap) = check_by_shooting(&p, &b, 3, 1e-8);
    assert!(gap > 1e-3, "period-1 gap {gap:e}");
    // The period-2 orbit doubles again (towards period 4) on the way.
    assert!(
        b.curve
            .bifurcations
            .iter()
            .any(|e| e.kind == BifurcationKind::PeriodDoubling && e.located),
        "{:?}",
        b.curve.bifurcations
    );
    println!("period 2 from ω_f {w_pd}: shooting deviation {dev:e}, period-1 gap {gap:e}");
}

#[test]
fn symmetry_breaking_branch_of_the_chain_is_asymmetric_by_shooting() {
    let p = chain();
    let hb = HbOptions::new(9, 32);
    // The pitchfork at ω_f = 1.02624 (tests/bifurcation.rs checks it by
    // shooting to 1e-9).
    let (b, w_bp) = switched(&p, &hb, (0.8, 2.5), BifurcationKind::BranchPoint, 1.02624);
    assert_eq!((b.kind, b.subharmonic), (BifurcationKind::BranchPoint, 1));
    let l = 2 * hb.harmonics + 1;
    // The new branch is the asymmetric one (x₁ ≠ x₂; measured max
    // |coefficient difference| 0.1 and more), not the symmetric one traced.
    let asym = b
        .curve
        .points
        .iter()
        .map(|pt| max_diff(&pt.coeffs.0[..l], &pt.coeffs.0[l..]))
        .fold(0.0, f64::max);
    assert!(asym > 0.05, "{asym:e}");
    assert!(
        max_diff(
            &b.curve.points[1].coeffs.0[..l],
            &b.curve.points[1].coeffs.0[l..]
        ) > 1e-3
    );
    // Every 10th point: the HB orbit is the shooting orbit of the full
    // 2-DOF system to n = 9's truncation (measured 3.7e-7 at the largest
    // orbits), multipliers' verdict included.
    let (dev, _) = check_by_shooting(&p, &b, 10, 1e-6);
    println!(
        "asymmetric branch from ω_f {w_bp}: {} points, max |x₁ − x₂| coefficient {asym:.3}, shooting deviation {dev:e}",
        b.curve.points.len()
    );
}
