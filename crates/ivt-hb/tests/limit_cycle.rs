//! Autonomous orbits: the unforced Van der Pol limit cycle
//! `ẍ − μ(1 − x²)ẋ + x = 0` (C = −μ, K = 1, g = μx²ẋ) by HB with the frequency as
//! an unknown, against shooting on the time integration.
#![allow(clippy::indexing_slicing, clippy::panic)]

use ivt_hb::orbit::aft::eval_series;
use ivt_hb::problem::ode::rk4;
use ivt_hb::Oscillator;
use ivt_hb::{
    limit_cycle, limit_cycle_branch, ContinuationOptions, HbError, HbOptions, PeriodicProblem,
    StabilityKind, Termination,
};
use std::f64::consts::PI;

mod common;
use common::assert_period;
use common::shooting::newton_plane;

fn van_der_pol(mu: f64) -> impl PeriodicProblem {
    Oscillator::VanDerPol.problem(mu)
}

/// Shooting reference on the section ẋ = 0: unknowns `(x₀, T)`, residual
/// `[x(T) − x₀, ẋ(T)]`, RK4 with `steps` steps, Newton with central differences.
fn shooting_period(mu: f64, steps: usize) -> f64 {
    let flow = |y0: [f64; 2]| {
        let mut y = [y0[0], 0.0];
        rk4(
            |_t, y: &[f64], dy: &mut [f64]| {
                dy[0] = y[1];
                dy[1] = mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
            },
            0.0,
            &mut y,
            y0[1] / steps as f64,
            steps,
        );
        [y[0] - y0[0], y[1]]
    };
    // First-order estimates: amplitude 2, period 2π(1 + μ²/16).
    let start = [2.0, 2.0 * PI * (1.0 + mu * mu / 16.0)];
    let h = |y: [f64; 2]| [1e-6 * y[0], 1e-6 * y[1]];
    newton_plane(flow, start, h, [1e-14, 1e-13])
        .unwrap_or_else(|| panic!("shooting did not converge for μ = {mu}"))[1]
}

#[test]
fn van_der_pol_period_matches_shooting_and_multiplier_matches_liouville() {
    for (mu, n) in [(0.2, 15), (1.0, 30)] {
        let vdp = van_der_pol(mu);
        let hb = HbOptions::new(n, 4 * n);
        let mut guess = vec![0.0; 2 * n + 1];
        guess[1] = 2.0;
        let lc = limit_cycle(&vdp, &hb, 1.0, &guess, 2048).unwrap();
        let (t_ref, t_fine) = (shooting_period(mu, 20_000), shooting_period(mu, 40_000));
        // RK4 at 2e4 and 4e4 steps agree to ~1e-13 relative: the reference is
        // exact at the 1e-8 level asserted.
        assert!(
            (t_ref - t_fine).abs() < 1e-11 * t_fine,
            "{t_ref} vs {t_fine}"
        );
        assert_period(&lc, t_fine, &format!("μ = {mu}"));
        // Phase condition b₁ = 0 holds; the amplitude is near 2.
        assert!(lc.solution.coeffs[n + 1].abs() < 1e-12);
        assert!((lc.solution.amplitude(0) - 2.0).abs() < 0.02);
        // Liouville: μ₁μ₂ = exp(∮ tr A dt) = exp(μ∫₀ᵀ(1 − x²)dt); μ₁ = 1 (phase),
        // so the other multiplier is that exponential (trapezoid on 4096 points,
        // spectrally accurate for a periodic integrand).
        let c = lc.solution.dof(0);
        let k = 4096;
        let integral: f64 = (0..k)
            .map(|i| {
                let x = eval_series(c, 2.0 * PI * i as f64 / k as f64, 0);
                1.0 - x * x
            })
            .sum::<f64>()
            * lc.period()
            / k as f64;
        let want = (mu * integral).exp();
        let (m0, m1) = (lc.multipliers[0], lc.multipliers[1]);
        assert!((m0.re - 1.0).abs() < 1e-6 && m0.im.abs() < 1e-9, "{m0}");
        assert!(
            (m1.re - want).abs() < 1e-6 * want.max(1.0),
            "{m1} vs {want}"
        );
        assert_eq!(lc.kind, StabilityKind::Stable);
        assert!(lc.stable());
    }
}

#[test]
fn bad_guesses_are_errors() {
    let vdp = van_der_pol(1.0);
    let hb = HbOptions::new(10, 40);
    assert!(matches!(
        limit_cycle(&vdp, &hb, 1.0, &[0.0; 21], 256),
        Err(HbError::InvalidInput(_))
    ));
    assert!(matches!(
        limit_cycle(&vdp, &hb, 1.0, &[1.0; 5], 256),
        Err(HbError::InvalidInput(_))
    ));
    assert!(matches!(
        limit_cycle(&vdp, &hb, -1.0, &[1.0; 21], 256),
        Err(HbError::InvalidInput(_))
    ));
}

#[test]
fn van_der_pol_branch_in_mu_matches_shooting_at_every_point() {
    // From the μ = 0.2 cycle to μ = 1 by pseudo-arclength in μ; every point's
    // period against shooting at its own μ (1e-8 relative: the corrector's
    // residual tolerance 1e-10 bounds the error well below that).
    let n = 30;
    let hb = HbOptions::new(n, 4 * n);
    let mut guess = vec![0.0; 2 * n + 1];
    guess[1] = 2.0;
    let start = limit_cycle(&van_der_pol(0.2), &hb, 1.0, &guess, 512).unwrap();
    let opts = ContinuationOptions {
        ds: 0.05,
        ..ContinuationOptions::default()
    };
    let branch = limit_cycle_branch(van_der_pol, &hb, &start, 0.2, 1.0, &opts, 512).unwrap();
    assert_eq!(branch.termination, Termination::LeftInterval);
    assert!(branch.points.len() >= 5, "{} points", branch.points.len());
    // μ grows along the whole branch: no turning point.
    assert!(branch.events.is_empty(), "{:?}", branch.events);
    let mut last_period = 0.0;
    for (mu, lc) in &branch.points {
        let t_ref = shooting_period(*mu, 20_000);
        assert!(
            (lc.period() - t_ref).abs() < 1e-8 * t_ref,
            "μ = {mu}: {} vs {t_ref}",
            lc.period()
        );
        // The period grows with μ along this part of the branch; all stable.
        assert!(lc.period() > last_period);
        last_period = lc.period();
        assert!(lc.stable(), "μ = {mu}: {:?}", lc.multipliers);
    }
    assert!(branch.points.last().unwrap().0 >= 1.0);
}
