//! Fig. 29: the Duffing frequency-response curve 0.2 ≤ ω_f ≤ 3 (ξ = 0.02, α = 1,
//! ε = 1, F = 0.1, n = 20, N = 64) through both folds of the hardening peak.

use ivt_hb::{frequency_response, Duffing, FrcOptions, HbOptions, StabilityKind};

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
    let (f1, f2) = (frc.folds[0], frc.folds[1]);
    assert!(f1.lambda > f2.lambda);
    // First-harmonic estimate: the backbone ω² = α + (3/4) ε a² meets the damping
    // limit a = F/(2ξω) at ω ≈ 1.655, a ≈ 1.51.
    assert!((f1.lambda - 1.655).abs() < 0.02, "{f1:?}");
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
