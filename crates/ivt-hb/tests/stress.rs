//! Stress: strong nonlinearity, tiny damping, many harmonics, points near folds,
//! and bad inputs. Every converged answer is checked against one RK4 period started
//! on the HB orbit (an independent test that it solves the ODE); every failure
//! must be an error, never a panic or a silent wrong answer.

mod common;

use common::{max_abs_diff, orbit_defect, solve_classic, solve_modified};
use ivt_hb::{
    frequency_response, BroydenOptions, ClassicIhb, Duffing, FrcOptions, HbError, HbOptions,
    ModifiedIhb,
};

#[test]
fn strong_nonlinearity_up_to_eps_100() {
    for eps in [1.0, 10.0, 100.0] {
        for omega_f in [0.5, 1.5, 3.0] {
            let d = Duffing::new(0.02, 1.0, eps, 1.0);
            let sol = solve_modified(d.clone(), HbOptions::new(40, 100), omega_f);
            let err = orbit_defect(&d, &sol, 1 << 15);
            eprintln!(
                "ε = {eps}, ω_f = {omega_f}: amp {:.4}, {} it, orbit defect {err:.1e}",
                sol.amplitude(0),
                sol.stats.iterations
            );
            // n = 40 truncation error for these cases is below 1e-8 (cf. the
            // convergence study at ε = 100), RK4 error at T/32768 below 1e-10.
            assert!(err < 1e-7, "ε = {eps}, ω_f = {omega_f}: {err:e}");
        }
    }
}

#[test]
fn tiny_damping() {
    for omega_f in [0.4, 0.9, 2.0] {
        let d = Duffing::new(1e-4, 1.0, 1.0, 0.1);
        let sol = solve_modified(d.clone(), HbOptions::new(30, 80), omega_f);
        let err = orbit_defect(&d, &sol, 1 << 14);
        eprintln!(
            "ξ = 1e-4, ω_f = {omega_f}: amp {:.4}, orbit defect {err:.1e}",
            sol.amplitude(0)
        );
        assert!(err < 1e-8, "{err:e}");
    }
}

#[test]
fn many_harmonics_and_classic_agree() {
    let d = Duffing::fig28();
    let opts = HbOptions::new(64, 160);
    let a = solve_modified(d.clone(), opts.clone(), 1.3);
    // The classic Newton starts on its own from the linear guess, not from
    // the modified solution.
    let b = solve_classic(d.clone(), opts, 1.3);
    let diff = max_abs_diff(&a.coeffs, &b.coeffs);
    assert!(diff < 1e-9, "{diff:e}");
    assert!(orbit_defect(&d, &a, 1 << 14) < 1e-8);
}

#[test]
fn near_the_folds() {
    // Solve at fixed ω_f just inside each fold, from the nearest FRC point.
    let d = Duffing::fig28();
    let hb = HbOptions::new(20, 64);
    let frc = frequency_response(&d, &hb, &FrcOptions::default()).unwrap();
    for f in &frc.events {
        let p = &frc.points[f.index];
        let mut solver = ModifiedIhb::new(d.clone(), hb.clone()).unwrap();
        let sol = solver.solve(p.omega_f, Some(&p.coeffs)).unwrap();
        assert!(orbit_defect(&d, &sol, 1 << 14) < 1e-8);
        let gap = max_abs_diff(&sol.coeffs, &p.coeffs);
        assert!(gap < 1e-7, "fold at {}: {gap:e}", f.omega_f);
    }
}

#[test]
fn bad_inputs_are_errors() {
    let d = Duffing::fig28();
    // N ≤ n.
    assert!(matches!(
        ModifiedIhb::new(d.clone(), HbOptions::new(20, 20)),
        Err(HbError::AftTooFewSamples { .. })
    ));
    assert!(matches!(
        ClassicIhb::new(d.clone(), HbOptions::new(20, 10)),
        Err(HbError::AftTooFewSamples { .. })
    ));
    // No harmonics (n < p) and p = 0.
    assert!(matches!(
        ModifiedIhb::new(d.clone(), HbOptions::new(0, 8)),
        Err(HbError::InvalidInput(_))
    ));
    assert!(matches!(
        ModifiedIhb::new(d.clone(), HbOptions::new(4, 8).with_subharmonic(0)),
        Err(HbError::InvalidInput(_))
    ));
    // NaN parameters and frequencies.
    assert!(ModifiedIhb::new(Duffing::new(f64::NAN, 1.0, 1.0, 0.1), HbOptions::default()).is_err());
    assert!(ModifiedIhb::new(
        Duffing::new(0.02, 1.0, 1.0, f64::INFINITY),
        HbOptions::default()
    )
    .is_err());
    let mut s = ModifiedIhb::new(d.clone(), HbOptions::default()).unwrap();
    assert!(matches!(
        s.solve(f64::NAN, None),
        Err(HbError::InvalidInput(_))
    ));
    assert!(matches!(s.solve(-1.0, None), Err(HbError::InvalidInput(_))));
    assert!(matches!(
        s.solve(0.4, Some(&[f64::NAN; 41])),
        Err(HbError::InvalidInput(_))
    ));
    assert!(matches!(
        s.solve(0.4, Some(&[0.0; 3])),
        Err(HbError::InvalidInput(_))
    ));
    // NaN in the nonlinearity: the residual is not finite → error, no panic.
    let nan = Duffing::new(0.02, 1.0, f64::NAN, 0.1);
    assert!(ModifiedIhb::new(nan, HbOptions::default())
        .and_then(|mut s| s.solve(0.4, None))
        .is_err());
    // Bad sweep bounds.
    let bad = FrcOptions {
        from: 0.0,
        ..FrcOptions::default()
    };
    assert!(frequency_response(&d, &HbOptions::default(), &bad).is_err());
}

#[test]
fn non_convergence_returns_the_residual_history() {
    // A tolerance below round-off cannot be met by any of the fall-backs
    // (absolute 1e-300, no relative part).
    let d = Duffing::new(0.02, 1.0, 100.0, 1.0);
    let mut opts = HbOptions::new(20, 64);
    opts.broyden = BroydenOptions {
        max_iter: 20,
        tol: 1e-300,
        ..BroydenOptions::default()
    };
    opts.rtol = 0.0;
    let err = ModifiedIhb::new(d, opts)
        .unwrap()
        .solve(1.0, None)
        .unwrap_err();
    match err {
        HbError::Solve(e) => {
            assert!(!e.history().is_empty(), "{e}");
            assert!(e.history().iter().all(|v| v.is_finite()));
        }
        other => panic!("expected a solve error, got {other}"),
    }
}
