//! Backbone curve of the undamped Duffing oscillator `ẍ + x + αx³ = 0` against
//! its closed-form period (complete elliptic integral) and the first-order
//! harmonic-balance law ω² = 1 + ¾αa².
#![allow(clippy::unwrap_used)]

mod common;
use common::tight_backbone;
use ivt_hb::orbit::aft::eval_series;
use ivt_hb::{backbone, Corrector, Duffing, HbOptions};

/// Exact frequency of `ẍ + x + αx³ = 0` with `x(0) = A`, `ẋ(0) = 0`:
/// `T = 4K(k)/√(1 + αA²)`, `k² = αA²/(2(1 + αA²))`, so
/// `ω = 2π/T = √(1 + αA²) · AGM(1, √(1 − k²))` (`K = π/(2 AGM)`).
fn exact_omega(alpha: f64, amp: f64) -> f64 {
    let s = 1.0 + alpha * amp * amp;
    let k2 = alpha * amp * amp / (2.0 * s);
    let (mut a, mut b) = (1.0f64, (1.0 - k2).sqrt());
    // Quadratic convergence: 6 steps reach rounding for k² ≤ 1/2.
    for _ in 0..8 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    s.sqrt() * a
}

#[test]
fn duffing_backbone_matches_the_elliptic_closed_form() {
    // Broyden on the secant model, and Newton on the exact Jacobian of
    // {q, ω, κ} (Galerkin Jacobian, exact ∂R/∂ω): the same curve.
    for corrector in [Corrector::Broyden, Corrector::Newton] {
        closed_form_within(corrector);
    }
}

fn closed_form_within(corrector: Corrector) {
    let alpha = 1.0;
    let duffing = Duffing::new(0.0, 1.0, alpha, 0.0);
    let hb = HbOptions::new(15, 64);
    let mut opts = tight_backbone(0.01, 2.0, 0.02, 0.1);
    opts.continuation.corrector = corrector;
    let bb = backbone(&duffing, &hb, 1.0, &[1.0], &opts).unwrap();
    assert!(
        bb.points.last().unwrap().amplitude >= 2.0,
        "{:?}",
        bb.termination
    );
    // a₁ is the path parameter and grows along the whole curve: no turn.
    assert!(bb.events.is_empty(), "{:?}", bb.events);
    let mut worst = 0.0f64;
    for p in &bb.points {
        // x(0) is the turning point (b₁ = 0 and the orbit is even in t).
        let amp = eval_series(&p.coeffs, 0.0, 0);
        let exact = exact_omega(alpha, amp);
        worst = worst.max((p.omega - exact).abs() / exact);
        // The unfolding damping vanishes on a conservative orbit, up to the
        // corrector's residual tolerance 1e-12 (its force is κωa₁; measured
        // κa₁ ≤ 1.5e-13).
        assert!(
            p.kappa.abs() * p.amplitude < 1e-11,
            "κ = {} at a₁ = {}",
            p.kappa,
            p.amplitude
        );
        // First-order HB (one harmonic): ω² = 1 + ¾αa₁², exact as a₁ → 0; the
        // next term is O(a₁⁴) (relative error ≤ a₁⁴/10 measured up to a₁ = 2,
        // asserted ≤ a₁⁴/5).
        let first = (1.0 + 0.75 * alpha * p.amplitude * p.amplitude).sqrt();
        assert!(
            (p.omega - first).abs() / first <= 0.2 * p.amplitude.powi(4),
            "a₁ = {}: ω = {} vs first order {first}",
            p.amplitude,
            p.omega
        );
    }
    // n = 15 harmonics: the Fourier coefficients of the elliptic cosine decay
    // like qⁿ (nome q ≤ 0.03 at A = 2): ω is exact to the corrector's
    // tolerance 1e-12 (measured 9.6e-13 relative over 108 points).
    eprintln!(
        "{corrector:?}: {} points, worst relative error {worst:.1e}",
        bb.points.len()
    );
    assert!(
        worst < 1e-11,
        "{corrector:?}: max relative error against the closed form {worst:e}"
    );
}
