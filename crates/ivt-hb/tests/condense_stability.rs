//! Floquet multipliers of condensed orbits (issue 28) against the full,
//! uncondensed variational equation: the cantilever of N = 20 elements
//! (80 states) by Hsu's method on all DOFs, from the recovered orbits, at
//! points on the three branches of the hardening peak.

#[path = "common/beam.rs"]
mod beam;

use beam::{beam, full_beam, orbit, FORCE, OMEGA1};
use ivt_hb::condense::{condensed_response, multiplier_distance, CondensedFrcOptions};
use ivt_hb::{AdaptiveHsu, HbOptions, HsuSteps};

#[test]
fn reduced_multipliers_equal_the_full_systems_within_their_estimate() {
    let n = 20;
    let hb = HbOptions::new(7, 32);
    let mut branch = beam(n, FORCE, &hb);
    let opts = CondensedFrcOptions {
        from: 0.7 * OMEGA1,
        to: 1.3 * OMEGA1,
        ..CondensedFrcOptions::default()
    };
    let frc = condensed_response(&mut branch, &opts).unwrap();
    let (first, second) = (frc.folds[0].index, frc.folds[1].index);
    // Stability changes exactly at the folds: stable before the first and
    // after the second, one multiplier beyond +1 between.
    for (i, p) in frc.points.iter().enumerate() {
        let f = p.floquet.as_ref().unwrap();
        let unstable = f.floquet.max_modulus() > 1.0;
        if i + 1 < first || i > second + 1 {
            assert!(!unstable, "point {i} (ω = {}) unstable", p.omega_f);
        } else if i > first + 1 && i + 1 < second {
            assert!(unstable, "point {i} (ω = {}) stable", p.omega_f);
            assert!(f.floquet.multipliers[0].re > 1.0 && f.floquet.multipliers[0].im == 0.0);
        }
    }
    let (full, _) = full_beam(n);
    let mut hsu = AdaptiveHsu::new(
        &full,
        hb.harmonics,
        HsuSteps::Tolerance {
            tol: 1e-8,
            max: 4096,
        },
    )
    .unwrap();
    let nd = branch.structure().n_dof();
    let all: Vec<usize> = (0..nd).collect();
    let picks = [
        first / 2,
        first + 1,
        (first + second) / 2,
        second - 1,
        (second + frc.points.len()) / 2,
    ];
    let mut worst_ratio = 0.0f64;
    for &i in &picks {
        let p = &frc.points[i];
        let coeffs = branch.recover(&p.coeffs, p.omega_f, &all).unwrap().concat();
        let sol = orbit(coeffs, p.omega_f, hb.harmonics);
        let reference = hsu.floquet(&full, &sol).unwrap();
        let reduced = p.floquet.as_ref().unwrap();
        let d = multiplier_distance(&reduced.floquet.multipliers, &reference.floquet.multipliers);
        let estimate = reduced.error_estimate() + reference.error.unwrap();
        println!(
            "ω = {:.6}: |μ|max {:.9} (full {:.9}), distance {d:e}, estimate {estimate:e} (basis {})",
            p.omega_f,
            reduced.floquet.max_modulus(),
            reference.floquet.max_modulus(),
            reduced.basis
        );
        assert!(
            d <= estimate,
            "ω = {}: distance {d:e} > estimate {estimate:e}",
            p.omega_f
        );
        // Not vacuous: the estimate says the multipliers are good to 1e-4.
        assert!(estimate <= 1e-4, "ω = {}: estimate {estimate:e}", p.omega_f);
        assert_eq!(reduced.floquet.kind, reference.floquet.kind);
        worst_ratio = worst_ratio.max(d / estimate);
    }
    println!("worst distance / estimate {worst_ratio}");
}
