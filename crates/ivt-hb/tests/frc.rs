//! Fig. 29: the Duffing frequency-response curve 0.2 ≤ ω_f ≤ 3 (ξ = 0.02, α = 1,
//! ε = 1, F = 0.1, n = 20, N = 64) through both folds of the hardening peak.

use ivt_hb::aft::eval_series;
use ivt_hb::ode::rk4;
use ivt_hb::{
    frequency_response, BroydenStats, Duffing, FrcOptions, HbOptions, HbSolution, HsuRule,
    StabilityAnalyzer, StabilityKind,
};
use std::f64::consts::PI;

/// Shooting residual of a fold of Duffing's equation, an independent reference
/// (time integration, no harmonic balance): unknowns `(u₀, v₀, ω_f)`, residual
/// `[u(T) − u₀, v(T) − v₀, det(Φ(T) − I)]` with `T = 2π/ω_f` and `Φ` the
/// variational matrix, integrated by RK4 with `steps` steps per period.
fn shooting_residual(d: &Duffing, y0: [f64; 3], steps: usize) -> [f64; 3] {
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
    let det = (y[2] - 1.0) * (y[5] - 1.0) - y[3] * y[4];
    [y[0] - y0[0], y[1] - y0[1], det]
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
        // Cramer's rule for the 3×3 step.
        let det3 = |a: [[f64; 3]; 3]| {
            a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
        };
        let dj = det3(jac);
        let mut step = [0.0; 3];
        for (k, s) in step.iter_mut().enumerate() {
            let mut a = jac;
            for i in 0..3 {
                a[i][k] = -r[i];
            }
            *s = det3(a) / dj;
        }
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
    let down = frequency_response(
        &d,
        &hb,
        &FrcOptions {
            from: 3.0,
            to: 0.2,
            ..FrcOptions::default()
        },
    )
    .unwrap();
    assert_eq!(up.folds.len(), 2, "{:?}", up.folds);
    assert_eq!(down.folds.len(), 2, "{:?}", down.folds);
    let mut analyzer = StabilityAnalyzer::new(&d, 20, 4096).unwrap();
    for (k, (want, fold)) in [1.6548121, 1.1687244].iter().zip(&up.folds).enumerate() {
        assert!(fold.located, "{fold:?}");
        // The same fold from the other direction (it is met in reverse order).
        let back = &down.folds[1 - k];
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
        let c = &fold.coeffs;
        let y0 = [
            eval_series(c, 0.0, 0),
            fold.omega_f * eval_series(c, 0.0, 1),
            fold.omega_f,
        ];
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
            stats: BroydenStats {
                iterations: 0,
                residual_evals: 0,
                jacobian_refreshes: 0,
                residual_norm: 0.0,
            },
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
        frc.folds,
        frc.termination
    );
    assert!(
        pts.last().unwrap().omega_f >= 3.0,
        "reached {}",
        pts.last().unwrap().omega_f
    );
    assert_eq!(frc.folds.len(), 2, "{:?}", frc.folds);
    // Upper fold (peak) first, then the lower (jump-up) fold at smaller ω_f.
    let (f1, f2) = (&frc.folds[0], &frc.folds[1]);
    assert!(f1.omega_f > f2.omega_f);
    // First-harmonic estimate: the backbone ω² = α + (3/4) ε a² meets the damping
    // limit a = F/(2ξω) at ω ≈ 1.655, a ≈ 1.51.
    assert!((f1.omega_f - 1.655).abs() < 0.02, "{f1:?}");
    let peak = pts.iter().map(|p| p.amplitude).fold(0.0, f64::max);
    assert!((peak - 1.51).abs() < 0.06, "peak amplitude {peak}");
    // Stability switches exactly at the folds: every change of the flag happens
    // between the points bracketing a fold, and the unstable branch is a fold type
    // (a real multiplier > 1).
    let switches: Vec<usize> = (1..pts.len())
        .filter(|&i| pts[i].stable() != pts[i - 1].stable())
        .collect();
    eprintln!("switches at {switches:?}");
    assert_eq!(switches.len(), 2, "{switches:?}");
    for (s, f) in switches.iter().zip(&frc.folds) {
        assert!(
            *s == f.index || *s == f.index + 1,
            "switch {s} vs fold {f:?}"
        );
    }
    for p in &pts[switches[0]..switches[1]] {
        assert_eq!(p.kind, StabilityKind::Fold, "{:?}", p.multipliers);
        assert!(p.multipliers[0].re > 1.0 && p.multipliers[0].im.abs() < 1e-9);
    }
    // The multiplier passes through +1 at the folds: nearest points are within the
    // step of 1.
    for f in &frc.folds {
        let mu = pts[f.index].multipliers[0].norm();
        assert!((mu - 1.0).abs() < 0.2, "|μ| = {mu} at fold {f:?}");
    }
}

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
        frc.folds
            .iter()
            .map(|f| (f.omega_f, f.located))
            .collect::<Vec<_>>()
    );
    assert_eq!(frc.folds.len(), 2);
    assert!(frc.folds.iter().all(|f| f.located));
}
