//! Scale invariance (issue 17): with `x = L·u`, Duffing's Eq. 49 becomes
//! `ẍ + 2ξẋ + αx + (ε/L²)x³ = L·F cos ω_f t`, whose orbits are `L` times those of
//! Eq. 49 with the same Floquet multipliers (the variational equation is the
//! same after the change of variable). The user path (`GeneralProblem`: closures,
//! ∂g by central differences over all samples) must give exactly that for
//! amplitudes of micrometres, of 10 nm and of 1e8, with the default tolerances.
#![allow(clippy::indexing_slicing)]

use ivt_hb::{
    Duffing, GeneralProblem, HbOptions, HsuRule, ModifiedIhb, PeriodicProblem, StabilityAnalyzer,
    StabilityKind,
};

mod common;

/// Fig. 28's Duffing (ξ = 0.02, α = ε = 1, F = 0.1) in the length unit `1/L`.
fn scaled(l: f64) -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![0.04],
        vec![1.0],
        move |x: &[f64], _v: &[f64], _th: f64, g: &mut [f64]| g[0] = x[0] * x[0] * x[0] / (l * l),
        move |th: f64, f: &mut [f64]| f[0] = l * 0.1 * th.cos(),
    )
    .with_velocity_dependent(false)
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

/// Relative distance `max|q_l/l − q_ref| / max|q_ref|`.
fn scaled_distance(q_l: &[f64], l: f64, q_ref: &[f64]) -> f64 {
    let d: Vec<f64> = q_l.iter().zip(q_ref).map(|(a, b)| a / l - b).collect();
    max_abs(&d) / max_abs(q_ref)
}

#[test]
fn middle_branch_is_the_same_orbit_and_verdict_at_micrometre_and_nanometre_scale() {
    let hb = HbOptions::new(20, 64);
    // The unstable middle branch at ω_f ≈ 1.4 from the built-in Duffing FRC
    // (exact ∂g): the orbit scipy shooting and the thesis call a saddle.
    let frc = common::frc_between(&Duffing::fig28(), &hb, 0.2, 3.0);
    let mid = frc
        .points
        .iter()
        .filter(|p| p.kind == StabilityKind::Fold)
        .min_by(|a, b| (a.omega_f - 1.4).abs().total_cmp(&(b.omega_f - 1.4).abs()))
        .expect("the FRC has an unstable middle branch");
    let omega = mid.omega_f;
    let mu_ref = mid.multipliers[0];
    assert!(mu_ref.re > 1.0 && mu_ref.im.abs() < 1e-9, "μ = {mu_ref:?}");
    for l in [1.0, 1e-6, 1e-8] {
        let problem = scaled(l);
        // Start 0.1 % off the orbit so the solver iterates to the tolerance.
        let guess: Vec<f64> = mid.coeffs.iter().map(|c| 1.001 * l * c).collect();
        let sol = ModifiedIhb::new(&problem, hb.clone())
            .unwrap()
            .solve(omega, Some(&guess))
            .unwrap();
        assert!(sol.stats.iterations > 0);
        let dist = scaled_distance(&sol.coeffs, l, &mid.coeffs);
        // Both solves stop at ‖r‖ ≤ 1e-9·‖f̂‖: the orbits agree to ~‖J⁻¹‖·1e-9.
        assert!(dist < 1e-7, "L = {l:e}: orbit/L differs by {dist:e}");
        let mut analyzer = StabilityAnalyzer::new(&problem, 20, 256).unwrap();
        let fl = analyzer.hsu(&problem, &sol, HsuRule::Magnus4);
        assert_eq!(fl.kind, StabilityKind::Fold, "L = {l:e}: {fl:?}");
        // The same multiplier: the differenced ∂g (relative step 1e-6 of the
        // orbit) matches the exact one to ~1e-10, the orbits to 1e-7.
        let err = (fl.multipliers[0] - mu_ref).norm();
        assert!(
            err < 1e-6,
            "L = {l:e}: μ = {:?} vs {mu_ref:?}",
            fl.multipliers[0]
        );
    }
}

#[test]
fn a_1e8_scaled_duffing_converges_to_the_scaled_orbit() {
    let hb = HbOptions::new(20, 64);
    let reference = ModifiedIhb::new(Duffing::fig28(), hb.clone())
        .unwrap()
        .solve(0.4, None)
        .unwrap();
    for l in [1e8, 1e-8] {
        let problem = scaled(l);
        // From the linear solution, as a user would start.
        let sol = ModifiedIhb::new(&problem, hb.clone())
            .unwrap()
            .solve(0.4, None)
            .unwrap();
        let dist = scaled_distance(&sol.coeffs, l, &reference.coeffs);
        assert!(dist < 1e-9, "L = {l:e}: orbit/L differs by {dist:e}");
        // ‖r‖ relative to the force scale ‖f̂‖ = 0.1·L, as for L = 1.
        let rel = sol.stats.residual_norm / (0.1 * l);
        assert!(rel <= 1e-9, "L = {l:e}: ‖r‖/‖f̂‖ = {rel:e}");
        let mut analyzer = StabilityAnalyzer::new(&problem, 20, 256).unwrap();
        assert!(analyzer.hsu(&problem, &sol, HsuRule::Magnus4).stable());
    }
}

#[test]
fn tolerances_and_iteration_limit_are_honoured() {
    let problem = Duffing::fig28();
    // Absolute tolerance: ‖r‖ ≤ atol whatever the force scale.
    let sol = ModifiedIhb::new(&problem, HbOptions::new(20, 64).with_tolerances(0.0, 1e-13))
        .unwrap()
        .solve(0.4, None)
        .unwrap();
    assert!(sol.stats.residual_norm <= 1e-13);
    // Relative: ‖r‖ ≤ rtol·‖f̂‖ = 1e-4·0.1 stops earlier than the default.
    let loose = ModifiedIhb::new(&problem, HbOptions::new(20, 64).with_tolerances(1e-4, 0.0))
        .unwrap()
        .solve(0.4, None)
        .unwrap();
    assert!(loose.stats.residual_norm <= 1e-5);
    assert!(loose.stats.iterations < sol.stats.iterations);
    // One iteration cannot reach the default tolerance: an error with the history.
    let capped = HbOptions::new(20, 64).with_max_iter(1);
    let err = ivt_hb::ClassicIhb::new(&problem, capped)
        .unwrap()
        .solve(1.6, None)
        .unwrap_err();
    assert!(matches!(err, ivt_hb::HbError::Solve(_)), "{err:?}");
    // Nonsense tolerances are input errors, not endless iterations.
    for bad in [
        HbOptions::new(20, 64).with_tolerances(0.0, 0.0),
        HbOptions::new(20, 64).with_tolerances(-1e-9, 0.0),
        HbOptions::new(20, 64).with_tolerances(f64::NAN, 0.0),
        HbOptions::new(20, 64).with_max_iter(0),
    ] {
        assert!(matches!(
            ModifiedIhb::new(&problem, bad),
            Err(ivt_hb::HbError::InvalidInput(_))
        ));
    }
}
