//! Period doubling, Neimark–Sacker and branch points located on traced branches
//! and checked against shooting with Floquet multipliers (RK4 with variational
//! equations, sharing no code with the HB path) and time integration.
#![allow(clippy::indexing_slicing, clippy::panic, clippy::unwrap_used)]

use ivt_hb::branches::mathieu::THESIS_A0;
use ivt_hb::orbit::aft::{eval_series, resize_harmonics};
use ivt_hb::problem::ode::{first_order, rk4};
use ivt_hb::{
    period_doubled_start, switch_branch, trace, BifurcationKind, ContinuationOptions, Corrector,
    Family, FamilyBranch, GeneralProblem, HbOptions, LocateOptions, MathieuDuffing, ModifiedIhb,
    PathOptions, PeriodicProblem, Trace, TraceOptions,
};

/// The forcing-frequency family `ω_f ↦ (problem, ω_f)` and its trace with the
/// default options from the modified-IHB orbit at `omega_from` to `omega_to`.
fn trace_in_omega<'a, P: PeriodicProblem>(
    problem: &'a P,
    hb: &HbOptions,
    omega_from: f64,
    omega_to: f64,
    corrector: Corrector,
) -> (FamilyBranch<impl Family<Problem = &'a P>>, Trace) {
    let start = ModifiedIhb::new(problem, hb.clone())
        .unwrap()
        .solve(omega_from, None)
        .unwrap();
    let mut branch = FamilyBranch::new(move |w: f64| (problem, w), hb, omega_from).unwrap();
    let mut opts = TraceOptions {
        lambda_to: omega_to,
        ..TraceOptions::default()
    };
    opts.path.continuation.corrector = corrector;
    let tr = trace(&mut branch, &start.coeffs, omega_from, &opts).unwrap();
    (branch, tr)
}

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

/// det(Φ − μI) of a row-major 2×2 monodromy `p`: zero iff μ is a multiplier.
fn det_shifted(p: [f64; 4], mu: f64) -> f64 {
    (p[0] - mu) * (p[3] - mu) - p[1] * p[2]
}

/// Secant iteration on `f(λ) = 0` from the guesses `λ0 ∓ 1e-3` around an HB
/// location `λ0`.
fn secant_near(mut f: impl FnMut(f64) -> f64, lambda0: f64) -> f64 {
    let (mut a, mut b) = (lambda0 - 1e-3, lambda0 + 1e-3);
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
        path: PathOptions {
            continuation: ContinuationOptions {
                ds: 0.02,
                ds_max: 0.05,
                ..ContinuationOptions::default()
            },
            ..PathOptions::default()
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
    let beta_shoot = secant_near(
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
            det_shifted(p, -1.0)
        },
        pd.lambda,
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
        period_doubled_start(family, &hb, pd, 0.05, &LocateOptions::default()).unwrap();
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

/// `ẍ − ε(1 − x²)ẋ + x = F cos ω_f t` (forced Van der Pol), ε = 0.2, F = 0.3.
const VDP: (f64, f64) = (0.2, 0.3);

#[test]
fn forced_van_der_pol_neimark_sacker_matches_shooting_and_time_integration() {
    let (eps, f) = VDP;
    let vdp = GeneralProblem::new(
        1,
        vec![1.0],
        vec![-eps],
        vec![1.0],
        move |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| g[0] = eps * x[0] * x[0] * v[0],
        move |t: f64, out: &mut [f64]| out[0] = f * t.cos(),
    );
    let hb = HbOptions::new(9, 32);
    let (_, tr) = trace_in_omega(&vdp, &hb, 0.5, 1.6, Corrector::Broyden);
    let ns: Vec<_> = tr
        .events
        .iter()
        .filter(|e| e.kind == BifurcationKind::NeimarkSacker)
        .map(|e| e.location.as_ref().unwrap())
        .collect();
    // The small unstable orbit locks in through one Neimark–Sacker point and
    // unlocks through another (measured ω_f = 0.89805, 1.08673).
    assert_eq!(ns.len(), 2, "{:?}", tr.events);
    for (k, bif) in ns.iter().enumerate() {
        assert!(bif.residual_norm < 1e-12 && bif.iterations <= 8, "{bif:?}");
        let pair = &bif.multipliers;
        assert!(
            (pair[0].norm() - 1.0).abs() < 1e-9 && pair[0].im.abs() > 0.1,
            "{pair:?}"
        );
        // Shooting + Floquet: ω_f where det Φ = 1 (the product of the pair).
        let c = &bif.q;
        let mut y0 = [eval_series(c, 0.0, 0), bif.lambda * eval_series(c, 0.0, 1)];
        let acc =
            |w: f64| move |t: f64, x: f64, v: f64| eps * (1.0 - x * x) * v - x + f * (w * t).cos();
        let dacc = |_t: f64, x: f64, v: f64| (-2.0 * eps * x * v - 1.0, eps * (1.0 - x * x));
        let w_shoot = secant_near(
            |w| {
                let period = 2.0 * std::f64::consts::PI / w;
                let (y, p) = shoot_1dof(&acc(w), &dacc, y0, period, 4000);
                y0 = y;
                p[0] * p[3] - p[1] * p[2] - 1.0
            },
            bif.lambda,
        );
        println!(
            "NS ω_f {} shooting {w_shoot} ({:e})",
            bif.lambda,
            bif.lambda - w_shoot
        );
        // Measured ≤ 2e-13 (HB n = 9 coefficients end at ~1e-13).
        assert!(
            (bif.lambda - w_shoot).abs() < 1e-9,
            "{} vs {w_shoot}",
            bif.lambda
        );
        // Time integration 0.005 on either side: inside the locking interval a
        // perturbed orbit returns to the periodic one, outside it drifts away
        // (quasi-periodic response).
        let inside = if k == 0 { 1.0 } else { -1.0 };
        for (side, stable) in [(inside, true), (-inside, false)] {
            let w = bif.lambda + side * 0.005;
            let period = 2.0 * std::f64::consts::PI / w;
            let (orbit, _) = shoot_1dof(&acc(w), &dacc, y0, period, 4000);
            let mut y = [orbit[0] + 1e-3, orbit[1]];
            for _ in 0..300 {
                y = flow_1dof(acc(w), dacc, y, period, 400).0;
            }
            let dist = (y[0] - orbit[0]).hypot(y[1] - orbit[1]);
            assert_eq!(
                dist < 1e-5,
                stable,
                "ω_f {w}: distance after 300 periods {dist:e}"
            );
        }
    }
}

#[test]
fn symmetric_chain_branch_point_matches_shooting_and_switches_to_the_asymmetric_branch() {
    // Two equal masses, cubic springs to ground, in-phase forcing:
    // K = [[1.1, 0.1], [0.1, 1.1]] (in-phase mode 1.2, anti-phase 1.0), C = 0.02 I,
    // g = [x₁³, x₂³], f = 0.05 cos ω_f t [1, 1]. The symmetric response
    // parametrically excites the anti-phase mode: a pitchfork.
    let k = vec![1.1, 0.1, 0.1, 1.1];
    let chain = GeneralProblem::new(
        2,
        vec![1.0, 0.0, 0.0, 1.0],
        vec![0.02, 0.0, 0.0, 0.02],
        k,
        |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
            g[0] = x[0].powi(3);
            g[1] = x[1].powi(3);
        },
        |t: f64, f: &mut [f64]| {
            f[0] = 0.05 * t.cos();
            f[1] = 0.05 * t.cos();
        },
    );
    let hb = HbOptions::new(9, 32);
    let (mut branch, tr) = trace_in_omega(&chain, &hb, 0.8, 2.5, Corrector::Broyden);
    let event = tr
        .events
        .iter()
        .find(|e| e.kind == BifurcationKind::BranchPoint)
        .unwrap();
    let bp = event.location.as_ref().unwrap();
    assert!(bp.residual_norm < 1e-12 && bp.iterations <= 8, "{bp:?}");
    // The Newton path detects it from the sign of its tangent's LU (no own
    // assembly): the same branch point, located to the same λ.
    let (_, by_newton) = trace_in_omega(&chain, &hb, 0.8, 2.5, Corrector::Newton);
    let first = by_newton
        .events
        .iter()
        .find(|e| e.kind == BifurcationKind::BranchPoint)
        .unwrap();
    let same = first.location.as_ref().unwrap().lambda;
    // Measured 1e-13.
    assert!((same - bp.lambda).abs() < 1e-10, "{same} vs {}", bp.lambda);
    // Shooting on the symmetric orbit (x₁ = x₂ = x: ẍ + 0.02ẋ + 1.2x + x³ =
    // 0.05 cos ωt) and Floquet of the anti-phase variation
    // ÿ + 0.02ẏ + (1 + 3x²) y = 0: a multiplier +1 there.
    let l = 2 * hb.harmonics + 1;
    let c = &bp.q[..l];
    let mut y0 = [eval_series(c, 0.0, 0), bp.lambda * eval_series(c, 0.0, 1)];
    let acc = |w: f64| {
        move |t: f64, x: f64, v: f64| -0.02 * v - 1.2 * x - x * x * x + 0.05 * (w * t).cos()
    };
    let d_sym = |_t: f64, x: f64, _v: f64| (-1.2 - 3.0 * x * x, -0.02);
    let d_anti = |_t: f64, x: f64, _v: f64| (-1.0 - 3.0 * x * x, -0.02);
    let w_shoot = secant_near(
        |w| {
            let period = 2.0 * std::f64::consts::PI / w;
            let (y, _) = shoot_1dof(&acc(w), &d_sym, y0, period, 4000);
            y0 = y;
            let p = flow_1dof(acc(w), d_anti, y, period, 4000).1;
            det_shifted(p, 1.0)
        },
        bp.lambda,
    );
    // Measured 1e-12.
    assert!(
        (bp.lambda - w_shoot).abs() < 1e-9,
        "{} vs {w_shoot}",
        bp.lambda
    );

    // Branch switching: along the null direction orthogonal to the symmetric
    // branch's tangent, to an orbit with x₁ ≠ x₂ that RK4 (full 2-DOF system)
    // follows over a period.
    let (a, b) = (&tr.points[event.index], &tr.points[event.index + 1]);
    let tangent: Vec<f64> =
        b.q.iter()
            .chain([&b.lambda])
            .zip(a.q.iter().chain([&a.lambda]))
            .map(|(p, q)| p - q)
            .collect();
    let d = bp.second_direction(&tangent).unwrap();
    let (q, w) = switch_branch(
        &mut branch,
        &bp.q,
        bp.lambda,
        &d,
        0.05,
        &LocateOptions::default(),
    )
    .unwrap();
    let (_, sol) = branch.solution(&q, w);
    let asym = (0..64)
        .map(|i| {
            let t = i as f64 / 64.0 * 2.0 * std::f64::consts::PI / w;
            (sol.x_at(0, t) - sol.x_at(1, t)).abs()
        })
        .fold(0.0f64, f64::max);
    assert!(asym > 0.01, "switched orbit is symmetric: {asym:e}");
    let mut y: Vec<f64> = (0..2)
        .map(|dof| sol.x_at(dof, 0.0))
        .chain((0..2).map(|dof| w * eval_series(sol.dof(dof), 0.0, 1)))
        .collect();
    let period = 2.0 * std::f64::consts::PI / w;
    let mut dev = 0.0f64;
    for j in 1..=8 {
        rk4(
            first_order(&chain, w),
            (j - 1) as f64 * period / 8.0,
            &mut y,
            period / 8000.0,
            1000,
        );
        let t = j as f64 * period / 8.0;
        dev = dev
            .max((y[0] - sol.x_at(0, t)).abs())
            .max((y[1] - sol.x_at(1, t)).abs());
    }
    // HB n = 9 against RK4: measured 2e-9.
    assert!(dev < 1e-7, "RK4 vs switched HB orbit: {dev:e}");
    println!("BP ω_f {} (shooting {w_shoot}); switched to ω_f {w}, |x₁ − x₂| {asym:e}, RK4 deviation {dev:e}", bp.lambda);
}
