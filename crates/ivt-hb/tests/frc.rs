//! Fig. 29: the Duffing frequency-response curve 0.2 ≤ ω_f ≤ 3 (ξ = 0.02, α = 1,
//! ε = 1, F = 0.1, n = 20, N = 64) through both folds of the hardening peak.
#![allow(clippy::indexing_slicing, clippy::panic)]

use ivt_hb::orbit::aft::eval_series;
use ivt_hb::problem::ode::rk4;
use ivt_hb::{
    c64, frequency_response, BroydenStats, Duffing, FrcFold, FrcOptions, HbOptions, HbSolution,
    HsuRule, StabilityAnalyzer, StabilityKind,
};
use std::f64::consts::PI;

mod common;
use common::max_distance;
use common::shooting::solve3;

/// One period `T = 2π/ω_f` of Duffing's equation and its variational equation
/// from `(u₀, v₀) = y0[..2]` at `ω_f = y0[2]`, by RK4 with `steps` steps per
/// period (time integration, no harmonic balance): the end state `(u(T), v(T))`
/// and the monodromy matrix `Φ(T)` row-major.
fn period_map(d: &Duffing, y0: [f64; 3], steps: usize) -> ([f64; 2], [f64; 4]) {
    let (xi2, alpha, eps, force, w) = (2.0 * d.xi(), d.alpha(), d.eps, d.force, y0[2]);
    let mut y = [y0[0], y0[1], 1.0, 0.0, 0.0, 1.0];
    let period = 2.0 * PI / w;
    rk4(
        |t, y: &[f64], dy: &mut [f64]| {
            let (u, v) = (y[0], y[1]);
            dy[0] = v;
            dy[1] = force * (w * t).cos() - xi2 * v - alpha * u - eps * u * u * u;
            // Φ' = [[0, 1], [−α − 3εu², −2ξ]] Φ.
            let k = -alpha - 3.0 * eps * u * u;
            dy[2] = y[4];
            dy[3] = y[5];
            dy[4] = k * y[2] - xi2 * y[4];
            dy[5] = k * y[3] - xi2 * y[5];
        },
        0.0,
        &mut y,
        period / steps as f64,
        steps,
    );
    ([y[0], y[1]], [y[2], y[3], y[4], y[5]])
}

/// Shooting residual of a fold of Duffing's equation, an independent reference:
/// unknowns `(u₀, v₀, ω_f)`, residual `[u(T) − u₀, v(T) − v₀, det(Φ(T) − I)]`.
fn shooting_residual(d: &Duffing, y0: [f64; 3], steps: usize) -> [f64; 3] {
    let (end, phi) = period_map(d, y0, steps);
    let det = (phi[0] - 1.0) * (phi[3] - 1.0) - phi[1] * phi[2];
    [end[0] - y0[0], end[1] - y0[1], det]
}

/// The initial state `(u(0), u̇(0), ω_f)` of the HB orbit with Fourier
/// coefficients `c` at `omega_f`.
fn initial_state(c: &[f64], omega_f: f64) -> [f64; 3] {
    [
        eval_series(c, 0.0, 0),
        omega_f * eval_series(c, 0.0, 1),
        omega_f,
    ]
}

/// The two Floquet multipliers of the HB orbit `c` at `omega_f` as the
/// eigenvalues of the RK4 monodromy matrix (`steps` steps per period), by
/// decreasing modulus.
fn reference_multipliers(d: &Duffing, c: &[f64], omega_f: f64, steps: usize) -> [c64; 2] {
    let (_, phi) = period_map(d, initial_state(c, omega_f), steps);
    let (half_trace, det) = (0.5 * (phi[0] + phi[3]), phi[0] * phi[3] - phi[1] * phi[2]);
    let disc = half_trace * half_trace - det;
    if disc >= 0.0 {
        let r = disc.sqrt();
        let (a, b) = (half_trace + r, half_trace - r);
        if a.abs() >= b.abs() {
            [c64::new(a, 0.0), c64::new(b, 0.0)]
        } else {
            [c64::new(b, 0.0), c64::new(a, 0.0)]
        }
    } else {
        let r = (-disc).sqrt();
        [c64::new(half_trace, -r), c64::new(half_trace, r)]
    }
}

/// Newton (central-difference Jacobian) on [`shooting_residual`] from `y0`.
fn shooting_fold(d: &Duffing, mut y: [f64; 3], steps: usize) -> [f64; 3] {
    for _ in 0..30 {
        let r = shooting_residual(d, y, steps);
        let mut jac = [[0.0; 3]; 3];
        for k in 0..3 {
            let h = 1e-6 * y[k].abs().max(1e-2);
            let (mut yp, mut ym) = (y, y);
            yp[k] += h;
            ym[k] -= h;
            let (rp, rm) = (
                shooting_residual(d, yp, steps),
                shooting_residual(d, ym, steps),
            );
            for i in 0..3 {
                jac[i][k] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        let step = solve3(jac, r.map(|v| -v));
        for k in 0..3 {
            y[k] += step[k];
        }
        if step.iter().all(|s| s.abs() < 1e-11) {
            return y;
        }
    }
    panic!("shooting fold did not converge from {y:?}");
}

#[test]
fn duffing_folds_located_to_shooting_accuracy_in_both_directions() {
    // Thesis Duffing (Fig. 29): folds at ω_f = 1.6548121 (peak) and 1.1687244 by
    // shooting. The HB truncation error at n = 20 is far below 1e-10 here, so the
    // located folds must match the shooting folds to the Newton tolerance.
    let d = Duffing::fig28();
    let hb = HbOptions::new(20, 64);
    let up = frequency_response(&d, &hb, &FrcOptions::default()).unwrap();
    let down = common::frc_between(&d, &hb, 3.0, 0.2);
    assert_eq!(up.events.len(), 2, "{:?}", up.events);
    assert_eq!(down.events.len(), 2, "{:?}", down.events);
    let mut analyzer = StabilityAnalyzer::new(&d, 20, 4096).unwrap();
    for (k, (want, fold)) in [1.6548121, 1.1687244].iter().zip(&up.events).enumerate() {
        assert!(fold.located, "{fold:?}");
        // The same fold from the other direction (it is met in reverse order).
        let back = &down.events[1 - k];
        assert!(back.located, "{back:?}");
        assert!(
            (fold.omega_f - back.omega_f).abs() < 1e-10,
            "forward {} vs backward {}",
            fold.omega_f,
            back.omega_f
        );
        // Shooting from the HB fold orbit's initial state; RK4 with 4000 and 8000
        // steps per period agree to 1e-11, so the reference carries no
        // discretisation error at the 1e-8 level.
        let y0 = initial_state(&fold.coeffs, fold.omega_f);
        let shoot = shooting_fold(&d, y0, 4000);
        let fine = shooting_fold(&d, y0, 8000);
        assert!((shoot[2] - fine[2]).abs() < 1e-11, "{shoot:?} vs {fine:?}");
        eprintln!(
            "fold: HB {:.12}, shooting {:.12}, |Δ| = {:.1e}",
            fold.omega_f,
            fine[2],
            (fold.omega_f - fine[2]).abs()
        );
        assert!(
            (fold.omega_f - fine[2]).abs() < 1e-8,
            "{fold:?} vs {fine:?}"
        );
        assert!((fine[2] - want).abs() < 1e-7, "shooting {fine:?} vs {want}");
        // At the fold the leading multiplier is +1 (Hsu with 4096 Magnus-4 steps).
        let sol = HbSolution {
            coeffs: fold.coeffs.clone(),
            omega_f: fold.omega_f,
            harmonics: 20,
            subharmonic: 1,
            stats: BroydenStats::default(),
        };
        let mu = analyzer.hsu(&d, &sol, HsuRule::Magnus4).multipliers[0];
        assert!((mu.re - 1.0).abs() < 1e-6 && mu.im.abs() < 1e-9, "μ = {mu}");
    }
}

#[test]
fn duffing_frc_through_both_folds_with_flags_switching_at_them() {
    let frc = frequency_response(
        &Duffing::fig28(),
        &HbOptions::new(20, 64),
        &FrcOptions::default(),
    )
    .unwrap();
    let pts = &frc.points;
    eprintln!(
        "{} points, folds {:?}, termination {:?}",
        pts.len(),
        frc.events,
        frc.termination
    );
    assert!(
        pts.last().unwrap().omega_f >= 3.0,
        "reached {}",
        pts.last().unwrap().omega_f
    );
    assert_eq!(frc.events.len(), 2, "{:?}", frc.events);
    // Upper fold (peak) first, then the lower (jump-up) fold at smaller ω_f.
    let (f1, f2) = (&frc.events[0], &frc.events[1]);
    assert!(f1.omega_f > f2.omega_f);
    // First-harmonic estimate: the backbone ω² = α + (3/4) ε a² meets the damping
    // limit a = F/(2ξω) at ω ≈ 1.655, a ≈ 1.51.
    assert!((f1.omega_f - 1.655).abs() < 0.02, "{f1:?}");
    let peak = pts.iter().map(|p| p.amplitude).fold(0.0, f64::max);
    assert!((peak - 1.51).abs() < 0.06, "peak amplitude {peak}");
    // Every multiplier is right: Hsu (256 Magnus-4 steps) against the eigenvalues
    // of the RK4 monodromy matrix (4000 steps per period, an independent method)
    // at every point, near the folds and away from them, and the product of the
    // two against Liouville's closed form |μ₁μ₂| = exp(−2ξT), T = 2π/ω_f.
    let d = Duffing::fig28();
    let mut worst: f64 = 0.0;
    let mut reference = Vec::with_capacity(pts.len());
    for p in pts {
        let mu_ref = reference_multipliers(&d, &p.coeffs, p.omega_f, 4000);
        let err = max_distance(&p.multipliers, &mu_ref);
        worst = worst.max(err);
        assert!(
            err < MULTIPLIER_TOL,
            "ω_f = {}: Hsu {:?} vs RK {mu_ref:?}",
            p.omega_f,
            p.multipliers
        );
        let liouville = (-2.0 * d.xi() * 2.0 * PI / p.omega_f).exp();
        let product = (p.multipliers[0] * p.multipliers[1]).norm();
        assert!(
            (product / liouville - 1.0).abs() < 1e-6,
            "ω_f = {}: {product} vs {liouville}",
            p.omega_f
        );
        reference.push(mu_ref[0]);
    }
    eprintln!("largest |μ_Hsu − μ_RK| over the curve: {worst:.1e}");
    // The flag switches exactly at the located folds: a point is unstable iff it
    // lies on the path between them. A point counts as past a fold if its index
    // is beyond the fold's nearest point, or, for that nearest point itself, if
    // it lies ahead of the fold along the chord of its two neighbours. Points
    // whose reference multiplier is within MULTIPLIER_TOL of 1 sit on a fold to
    // the accuracy of Hsu's method and are not classified.
    assert!(f1.located && f2.located, "{:?}", frc.events);
    let past = |i: usize, f: &FrcFold| -> bool {
        if i != f.index {
            return i > f.index;
        }
        let (before, after) = (&pts[i - 1], &pts[i + 1]);
        let state = |c: &[f64], w: f64| c.iter().copied().chain([w]).collect::<Vec<f64>>();
        let (x, xf) = (
            state(&pts[i].coeffs, pts[i].omega_f),
            state(&f.coeffs, f.omega_f),
        );
        let (xa, xb) = (
            state(&before.coeffs, before.omega_f),
            state(&after.coeffs, after.omega_f),
        );
        let along: f64 = (0..x.len()).map(|k| (x[k] - xf[k]) * (xb[k] - xa[k])).sum();
        along > 0.0
    };
    let mut unstable = 0;
    for (i, (p, mu_ref)) in pts.iter().zip(&reference).enumerate() {
        if (mu_ref - 1.0).norm() < MULTIPLIER_TOL {
            continue;
        }
        let between = past(i, f1) && !past(i, f2);
        assert_eq!(
            p.stable(),
            !between,
            "point {i} at ω_f = {}: {:?}, folds {:?}",
            p.omega_f,
            p.multipliers,
            frc.events
                .iter()
                .map(|f| (f.index, f.omega_f))
                .collect::<Vec<_>>()
        );
        if between {
            unstable += 1;
            // The unstable branch is of fold type: a real multiplier above 1.
            assert_eq!(p.kind, StabilityKind::Fold, "{:?}", p.multipliers);
            assert!(p.multipliers[0].re > 1.0 && p.multipliers[0].im.abs() < 1e-9);
        }
    }
    assert!(unstable > 0, "no point on the middle branch");
}

/// Largest distance allowed between a Hsu multiplier (256 Magnus-4 steps) and
/// its RK4 monodromy reference (4000 steps per period): measured below 1e-6 at
/// every point of the curve; the bound leaves a factor 10.
const MULTIPLIER_TOL: f64 = 1e-5;

#[test]
fn chain_2dof_folds_are_located_with_a_finite_difference_jacobian() {
    // The 2-DOF cubic chain through its first resonance, g given as a closure
    // (so ∂g comes from the default central differences): both turns must be
    // located (ivt-py's tests/test_hb.py checks the values against scipy shooting).
    use ivt_hb::GeneralProblem;
    let chain = GeneralProblem::new(
        2,
        vec![1.0, 0.0, 0.0, 1.0],
        vec![0.02, 0.0, 0.0, 0.02],
        vec![2.0, -1.0, -1.0, 2.0],
        |x: &[f64], _v: &[f64], _th: f64, g: &mut [f64]| {
            g[0] = 0.5 * x[0] * x[0] * x[0];
            g[1] = 0.0;
        },
        |th: f64, f: &mut [f64]| {
            f[0] = 0.1 * th.cos();
            f[1] = 0.0;
        },
    );
    let opts = FrcOptions {
        from: 0.5,
        to: 1.6,
        ..FrcOptions::default()
    };
    let frc = frequency_response(&chain, &HbOptions::new(15, 64), &opts).unwrap();
    eprintln!(
        "chain folds: {:?}",
        frc.events
            .iter()
            .map(|f| (f.omega_f, f.located))
            .collect::<Vec<_>>()
    );
    assert_eq!(frc.events.len(), 2);
    assert!(frc.events.iter().all(|f| f.located));
}
