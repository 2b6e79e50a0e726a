//! Period doubling, Neimark–Sacker and branch points located on traced branches
//! and checked against shooting with Floquet multipliers (RK4 with variational
//! equations, sharing no code with the HB path) and time integration.

use ivt_hb::aft::{eval_series, resize_harmonics};
use ivt_hb::mathieu::THESIS_A0;
use ivt_hb::ode::rk4;
use ivt_hb::{
    period_doubled_start, trace, BifurcationKind, BifurcationOptions, ContinuationOptions,
    FamilyBranch, HbOptions, MathieuDuffing, ModifiedIhb, TraceOptions,
};

/// Flow and monodromy of `ẍ = a(t, x, ẋ)` (1 DOF) over `[0, period]` from `y0 =
/// (x, ẋ)`, with `∂a/∂x`, `∂a/∂ẋ` for the variational equations: RK4, `steps`.
fn flow_1dof<A, D>(acc: A, dacc: D, y0: [f64; 2], period: f64, steps: usize) -> ([f64; 2], [f64; 4])
where
    A: Fn(f64, f64, f64) -> f64,
    D: Fn(f64, f64, f64) -> (f64, f64),
{
    let mut y = [y0[0], y0[1], 1.0, 0.0, 0.0, 1.0];
    rk4(
        |t, y, dy| {
            let (x, v) = (y[0], y[1]);
            let (ax, av) = dacc(t, x, v);
            dy[0] = v;
            dy[1] = acc(t, x, v);
            // Φ' = [[0, 1], [ax, av]] Φ, Φ = [[y2, y3], [y4, y5]].
            dy[2] = y[4];
            dy[3] = y[5];
            dy[4] = ax * y[2] + av * y[4];
            dy[5] = ax * y[3] + av * y[5];
        },
        0.0,
        &mut y,
        period / steps as f64,
        steps,
    );
    ([y[0], y[1]], [y[2], y[3], y[4], y[5]])
}

/// Periodic orbit by shooting (Newton on `P(y) − y`); returns `(y0, Φ)`.
fn shoot_1dof<A, D>(
    acc: &A,
    dacc: &D,
    mut y0: [f64; 2],
    period: f64,
    steps: usize,
) -> ([f64; 2], [f64; 4])
where
    A: Fn(f64, f64, f64) -> f64,
    D: Fn(f64, f64, f64) -> (f64, f64),
{
    for _ in 0..30 {
        let (y1, p) = flow_1dof(acc, dacc, y0, period, steps);
        let (r0, r1) = (y1[0] - y0[0], y1[1] - y0[1]);
        let (a, b, c, d) = (p[0] - 1.0, p[1], p[2], p[3] - 1.0);
        let det = a * d - b * c;
        let dx = -(d * r0 - b * r1) / det;
        let dv = -(-c * r0 + a * r1) / det;
        y0 = [y0[0] + dx, y0[1] + dv];
        if dx.abs().max(dv.abs()) < 1e-13 {
            return (y0, flow_1dof(acc, dacc, y0, period, steps).1);
        }
    }
    panic!("shooting did not converge from {y0:?}");
}

/// Secant iteration on `f(λ) = 0` from two guesses.
fn secant(mut f: impl FnMut(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let (mut fa, mut fb) = (f(a), f(b));
    for _ in 0..40 {
        let c = b - fb * (b - a) / (fb - fa);
        (a, fa) = (b, fb);
        b = c;
        fb = f(b);
        if (b - a).abs() < 1e-13 * b.abs() {
            return b;
        }
    }
    panic!("secant did not converge: {a} {b}");
}

#[test]
fn mathieu_duffing_period_doubling_matches_shooting_and_switches_to_period_two() {
    // Eq. 81, ξ̂ = 0.125, α̂ = 1, γ = 1, Ω = 2 (§3.2.5): the period-1 branch from
    // β₀ = 3.6 doubles at β₁ (thesis 4.825).
    let n = 20;
    let hb = HbOptions::new(n, 4 * n);
    let family = |b: f64| (MathieuDuffing::thesis(b), 2.0);
    let guess = resize_harmonics(&THESIS_A0, n);
    let start = ModifiedIhb::new(MathieuDuffing::thesis(3.6), hb.clone())
        .unwrap()
        .solve(2.0, Some(&guess))
        .unwrap();
    let mut branch = FamilyBranch::new(family, &hb, 3.6).unwrap();
    let opts = TraceOptions {
        lambda_to: 5.0,
        continuation: ContinuationOptions {
            ds: 0.02,
            ds_max: 0.05,
            ..ContinuationOptions::default()
        },
        ..TraceOptions::default()
    };
    let tr = trace(&mut branch, &start.coeffs, 3.6, &opts).unwrap();
    let pds: Vec<_> = tr
        .events
        .iter()
        .filter(|e| e.kind == BifurcationKind::PeriodDoubling)
        .collect();
    assert_eq!(
        pds.len(),
        1,
        "{:?}",
        tr.events
            .iter()
            .map(|e| (e.kind, e.index))
            .collect::<Vec<_>>()
    );
    let pd = pds[0].location.as_ref().unwrap();

    // Shooting + Floquet: β where det(Φ + I) = 0.
    let (xi, alpha, gamma) = (0.125, 1.0, 1.0);
    let period = std::f64::consts::PI;
    let steps = 4000;
    let c = &pd.q;
    let y_hb = [eval_series(c, 0.0, 0), 2.0 * eval_series(c, 0.0, 1)];
    let mut y0 = y_hb;
    let beta_shoot = secant(
        |beta| {
            let acc = |t: f64, x: f64, v: f64| {
                -2.0 * xi * v + (alpha + beta * (2.0 * t).sin()) * x - gamma * x * x * x
            };
            let dacc = |t: f64, x: f64, _v: f64| {
                (
                    alpha + beta * (2.0 * t).sin() - 3.0 * gamma * x * x,
                    -2.0 * xi,
                )
            };
            let (y, p) = shoot_1dof(&acc, &dacc, y0, period, steps);
            y0 = y;
            (p[0] + 1.0) * (p[3] + 1.0) - p[1] * p[2]
        },
        pd.lambda - 1e-3,
        pd.lambda + 1e-3,
    );
    // Both sides solve the same β to their own accuracy: HB n = 20 (last
    // coefficients ~1e-12), Hsu 2048 Magnus4 steps, RK4 4000 steps per period.
    // Measured 2e-12; the extended system converges in 4 Newton steps.
    assert!(
        (pd.lambda - beta_shoot).abs() < 1e-9,
        "{} vs {beta_shoot}",
        pd.lambda
    );
    assert!(
        (pd.lambda - 4.825).abs() < 1e-3,
        "thesis β₁ = 4.825: {}",
        pd.lambda
    );
    assert!((pd.multipliers[0].re + 1.0).abs() < 1e-9 && pd.multipliers[0].im == 0.0);
    assert!(pd.residual_norm < 1e-10 && pd.iterations <= 8, "{pd:?}");
    // The points before the doubling are stable, the ones after are not.
    let k = pds[0].index;
    assert!(tr.points[k].kind == ivt_hb::StabilityKind::Stable);
    assert!(tr.points[k + 1].kind == ivt_hb::StabilityKind::PeriodDoubling);

    // Period-2 branch: its first point is an orbit of period 2T (RK4 over 2T from
    // the HB state follows the HB orbit) and not of period T.
    let (br2, q2, b2) =
        period_doubled_start(family, &hb, pd, 0.05, &BifurcationOptions::default()).unwrap();
    let (_, sol2) = br2.solution(&q2, b2);
    // Supercritical: the period-2 branch exists beyond β₁.
    assert!(b2 > pd.lambda, "{b2}");
    let acc = |t: f64, x: f64, v: f64| {
        -2.0 * xi * v + (alpha + b2 * (2.0 * t).sin()) * x - gamma * x * x * x
    };
    let w = sol2.omega();
    let mut y = [sol2.x_at(0, 0.0), w * eval_series(sol2.dof(0), 0.0, 1)];
    let (mut dev, mut gap) = (0.0f64, 0.0f64);
    let quarter = 2.0 * period / 16.0;
    for j in 1..=16 {
        let t0 = (j - 1) as f64 * quarter;
        let mut z = [y[0], y[1]];
        rk4(
            |t, z, dz| {
                dz[0] = z[1];
                dz[1] = acc(t, z[0], z[1]);
            },
            t0,
            &mut z,
            quarter / 500.0,
            500,
        );
        y = z;
        let t = j as f64 * quarter;
        dev = dev.max((y[0] - sol2.x_at(0, t)).abs());
        gap = gap.max((sol2.x_at(0, t) - sol2.x_at(0, t + period)).abs());
    }
    // RK4 over 2T follows the HB orbit (measured 1e-10); x(t + T) ≠ x(t).
    assert!(dev < 1e-8, "RK4 vs HB period-2 orbit: {dev:e}");
    assert!(gap > 0.05, "not period 2: {gap:e}");
    println!("period-2 start β {b2}: RK4 deviation {dev:e}, |x(t+T) − x(t)| {gap:e}");
}
