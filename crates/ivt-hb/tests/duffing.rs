//! Duffing's equation (Eq. 49) at the Fig. 28 parameters against independent
//! references: a long RK4 integration, the classic Newton IHB, and Hill vs Hsu.

mod common;

use common::{max_abs_diff, orbit_defect, solve_classic, solve_modified};
use ivt_hb::orbit::aft::{eval_series, resize_harmonics};
use ivt_hb::problem::ode::{first_order, rk4};
use ivt_hb::{ClassicIhb, Duffing, HbOptions, HsuRule, ModifiedIhb, StabilityAnalyzer};
use std::f64::consts::PI;

/// Fig. 28: n = 20, N = 64, ξ = 0.02, α = 1, ε = 1, ω_f = 0.4, F = 0.1.
const OMEGA_F: f64 = 0.4;

/// Steady state by RK4 from rest over 150 forcing periods (transient ~e^{−ξt} =
/// e^{−47}), h = T/4000; returns x at 64 points of the next period.
fn rk_reference(problem: &Duffing, omega_f: f64, periods: usize, per_period: usize) -> Vec<f64> {
    let period = 2.0 * PI / omega_f;
    let dt = period / per_period as f64;
    let mut y = [0.0, 0.0];
    rk4(
        first_order(problem, omega_f),
        0.0,
        &mut y,
        dt,
        periods * per_period,
    );
    let mut out = Vec::with_capacity(64);
    let mut t = periods as f64 * period;
    for _ in 0..64 {
        out.push(y[0]);
        rk4(
            first_order(problem, omega_f),
            t,
            &mut y,
            dt,
            per_period / 64,
        );
        t += dt * (per_period / 64) as f64;
    }
    out
}

fn hb_at_rk_points(coeffs: &[f64]) -> Vec<f64> {
    (0..64)
        .map(|j| eval_series(coeffs, 2.0 * PI * j as f64 / 64.0, 0))
        .collect()
}

#[test]
fn fig28_matches_long_rk_integration() {
    let duffing = Duffing::fig28();
    let mut solver = ModifiedIhb::new(duffing.clone(), HbOptions::new(20, 64)).unwrap();
    let sol = solver.solve(OMEGA_F, None).unwrap();
    assert!(sol.stats.residual_norm <= 1e-10);
    let rk = rk_reference(&duffing, OMEGA_F, 150, 4096);
    let err = max_abs_diff(&rk, &hb_at_rk_points(sol.dof(0)));
    // RK4 with h = T/4096 ≈ 3.8e-3 has global error ~1e-11 here (checked by
    // halving h below); HB truncation at n = 20 is far smaller. Acceptance: 1e-8.
    eprintln!(
        "Fig. 28: max |x_HB − x_RK| = {err:.3e}, iterations {}",
        sol.stats.iterations
    );
    assert!(err <= 1e-8, "HB vs RK error {err:e}");
    // RK self-consistency: halving the step changes the answer by far less than 1e-8.
    let rk2 = rk_reference(&duffing, OMEGA_F, 150, 8192);
    assert!(max_abs_diff(&rk, &rk2) < 1e-9);
}

#[test]
fn modified_and_classic_ihb_agree() {
    let duffing = Duffing::fig28();
    let opts = HbOptions::new(20, 64);
    let a = solve_modified(duffing.clone(), opts.clone(), OMEGA_F);
    let b = solve_classic(duffing, opts, OMEGA_F);
    let d = max_abs_diff(&a.coeffs, &b.coeffs);
    eprintln!(
        "modified vs classic: max coefficient difference {d:.3e} (iterations {} vs {})",
        a.stats.iterations, b.stats.iterations
    );
    // Both drive the same discrete residual below 1e-10; the linearised solution
    // map has a condition ~ 1/(2ξω) ≈ 60, so 1e-9 holds with margin.
    assert!(d <= 1e-9, "{d:e}");
}

#[test]
fn modified_and_classic_agree_on_the_resonant_branch() {
    // ω_f = 1.2 lies between the folds, where three orbits coexist. Each
    // method starts on its own (never from the other's solution), so
    // agreement is a check, not a copy: from the linear guess both reach the
    // lower orbit (amplitude 0.254); from the one-harmonic balance
    // ((1 − ω²)A + ¾εA³)² + (2ξωA)² = F² on its large root (A ≈ 0.87, a
    // closed-form guess a1 = A) both reach the resonant upper orbit.
    let duffing = Duffing::fig28();
    let opts = HbOptions::new(20, 64);
    let (w, xi, eps, f) = (1.2f64, 0.02, 1.0, 0.1);
    let one_harmonic = |a: f64| {
        let inphase = (1.0 - w * w) * a + 0.75 * eps * a.powi(3);
        inphase * inphase + (2.0 * xi * w * a).powi(2) - f * f
    };
    // Bisection on [0.7, 1.5] (between the middle and the large root).
    let (mut lo, mut hi) = (0.7, 1.5);
    assert!(one_harmonic(lo) < 0.0 && one_harmonic(hi) > 0.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if one_harmonic(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let mut upper_guess = vec![0.0; 41];
    upper_guess[1] = lo;
    for (guess, min_amp, max_amp) in [(None, 0.2, 0.3), (Some(&upper_guess[..]), 0.8, 1.0)] {
        let a = ModifiedIhb::new(duffing.clone(), opts.clone())
            .unwrap()
            .solve(w, guess)
            .unwrap();
        let b = ClassicIhb::new(duffing.clone(), opts.clone())
            .unwrap()
            .solve(w, guess)
            .unwrap();
        let amp = a.amplitude(0);
        let d = max_abs_diff(&a.coeffs, &b.coeffs);
        eprintln!("ω_f = 1.2: amplitude {amp:.6}, modified vs classic {d:.2e}");
        assert!((min_amp..max_amp).contains(&amp), "amplitude {amp}");
        assert!(d <= 1e-9, "{d:e}");
    }
}

#[test]
fn hsu_and_hill_multipliers_agree() {
    let duffing = Duffing::fig28();
    for omega_f in [0.4, 1.0, 1.6] {
        let sol = solve_modified(duffing.clone(), HbOptions::new(20, 64), omega_f);
        let mut an = StabilityAnalyzer::new(&duffing, 20, 4096).unwrap();
        let hsu = an.hsu(&duffing, &sol, HsuRule::Magnus4);
        let hill = an.hill(&duffing, &sol, 20).unwrap();
        let d = hsu
            .multipliers
            .iter()
            .zip(&hill.multipliers)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        eprintln!(
            "ω_f = {omega_f}: Hsu {:?} Hill {:?} diff {d:.2e}",
            hsu.multipliers, hill.multipliers
        );
        // Hsu: 4096 Magnus-4 steps (local error ~h⁵, h = 2π/(4096 ω)); Hill:
        // h = 20 harmonics of a spectrally accurate orbit. Measured ≤ 1.8e-13.
        assert!(d <= 1e-12, "Hsu vs Hill {d:e}");
        // Liouville: μ1 μ2 = exp(∮ tr Θ) = exp(−2π·2ξ/ω) for any solution.
        let det = hsu.multipliers[0] * hsu.multipliers[1];
        let want = (-2.0 * PI * 2.0 * 0.02 / omega_f).exp();
        assert!((det.re - want).abs() < 1e-9 && det.im.abs() < 1e-9);
        assert_eq!(hsu.kind, hill.kind);
    }
}

#[test]
fn eq80_literal_rule_converges_to_magnus() {
    // Eq. 80 (Θ frozen per sub-interval) is first order: its error halves with N_Q.
    let duffing = Duffing::fig28();
    let sol = solve_modified(duffing.clone(), HbOptions::new(20, 64), 0.4);
    let reference =
        StabilityAnalyzer::new(&duffing, 20, 4096)
            .unwrap()
            .hsu(&duffing, &sol, HsuRule::Magnus4);
    let err = |steps| {
        let f =
            StabilityAnalyzer::new(&duffing, 20, steps)
                .unwrap()
                .hsu(&duffing, &sol, HsuRule::Left);
        f.multipliers
            .iter()
            .zip(&reference.multipliers)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max)
    };
    let (e1, e2) = (err(512), err(1024));
    assert!(e2 < 0.6 * e1 && e1 < 0.05, "{e1:e} {e2:e}");
}

/// Error vs n (n = 4…30, N = 4n) against n = 64 for a strongly nonlinear case
/// (ε = 100, F = 1, ω_f = 1, ξ = 0.02) where many harmonics matter; the Fig. 28
/// point itself is converged to round-off by n = 6 (its error is below 1e-15).
/// Several periodic solutions coexist here, so each n starts from the reference
/// truncated to n harmonics to stay on the same branch.
#[test]
fn convergence_in_harmonics() {
    let duffing = Duffing::new(0.02, 1.0, 100.0, 1.0);
    let omega_f = 1.0;
    let reference = solve_modified(duffing.clone(), HbOptions::new(64, 160), omega_f);
    let mut table = Vec::new();
    for n in [4usize, 6, 8, 10, 12, 14, 16, 20, 24, 30] {
        let guess = resize_harmonics(&reference.coeffs, n);
        let sol = ModifiedIhb::new(duffing.clone(), HbOptions::new(n, 4 * n))
            .unwrap()
            .solve(omega_f, Some(&guess))
            .unwrap();
        let err = (0..256)
            .map(|j| {
                let t = 2.0 * PI * j as f64 / 256.0;
                (eval_series(sol.dof(0), t, 0) - eval_series(reference.dof(0), t, 0)).abs()
            })
            .fold(0.0, f64::max);
        eprintln!("| {n:2} | {err:.2e} |");
        table.push((n, err));
    }
    // Exponential convergence: the error falls monotonically, by ≥ 10× per 4–6
    // harmonics, and is below 1e-8 at n = 30.
    for w in table.windows(2) {
        assert!(w[1].1 < w[0].1, "{table:?}");
    }
    assert!(
        table[0].1 > 1e-3 && table.last().unwrap().1 < 1e-8,
        "{table:?}"
    );
    // The n = 64 orbit is a solution of the ODE: one RK4 period started from the
    // HB state (x(0), ẋ(0)) stays on it (coexisting attractors rule out a start
    // from rest here).
    let err = orbit_defect(&duffing, &reference, 65536);
    eprintln!("ε = 100: n = 64 orbit vs one RK period {err:.2e}");
    assert!(err < 1e-7, "{err:e}");
}
