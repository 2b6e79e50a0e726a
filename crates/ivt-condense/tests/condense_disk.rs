//! Floquet multipliers of the condensed bladed disk (issue 28, pyHarm's
//! tutorial 006: 72 DOFs, the cubic spring 5e10 x³ at sector 0's blade tip,
//! C = 2e-6 K) against Hsu's method on the whole uncondensed structure
//! (144 states) from the recovered orbits.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

#[path = "common/beam.rs"]
mod beam;
#[path = "common/disk.rs"]
mod disk;

use beam::orbit;
use disk::{full_disk, tip_problem};
use faer::c64;
use ivt_condense::models::bladed_disk;
use ivt_condense::{
    condensed_response, CondensedBranch, CondensedFrc, CondensedFrcOptions, Structure,
};
use ivt_hb::{AdaptiveHsu, HbOptions, HsuSteps, PeriodicProblem};

/// The disk condensed onto the tip, `F = 1` there, and its curve over
/// 1150–1260 rad/s with `opts`' stability settings.
fn disk_curve(opts: CondensedFrcOptions) -> (CondensedFrc, CondensedBranch<impl PeriodicProblem>) {
    let disk = bladed_disk().unwrap();
    let s = &disk.model;
    let structure = Structure::new(s.m.as_ref(), s.c.as_ref(), s.k.as_ref()).unwrap();
    let mut load = vec![0.0; s.n_dof()];
    load[disk.tip] = 1.0;
    let hb = HbOptions::new(5, 32);
    let mut branch =
        CondensedBranch::new(structure, vec![disk.tip], &load, &[], tip_problem(), &hb).unwrap();
    let opts = CondensedFrcOptions {
        from: 1150.0,
        to: 1260.0,
        ..opts
    };
    let frc = condensed_response(&mut branch, &opts).unwrap();
    (frc, branch)
}

/// The largest distance of each of `a` to its nearest in `b`, each taken
/// out of `b` once matched (one-to-one, greedy).
fn matched(a: &[c64], b: &mut Vec<c64>) -> f64 {
    let mut worst = 0.0f64;
    for z in a {
        let (j, d) = b
            .iter()
            .map(|w| (z - w).norm())
            .enumerate()
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap();
        b.remove(j);
        worst = worst.max(d);
    }
    worst
}

#[test]
fn disk_multipliers_equal_the_full_structures_within_their_estimate() {
    // The default basis grows until its truncation estimate is ≤ 1e-6: on
    // the disk it closes the invariant subspace the tip sees (39 vectors:
    // 13 nodal diameters × 3 modes), so the estimate is rounding and Hsu's.
    let (frc, mut branch) = disk_curve(CondensedFrcOptions::default());
    let n = frc.points.len();
    let peak = (0..n)
        .max_by(|&a, &b| frc.points[a].amplitude.total_cmp(&frc.points[b].amplitude))
        .unwrap();
    let mut picks = vec![
        0,
        n / 4,
        peak.saturating_sub(3),
        peak,
        peak + 3,
        (3 * n) / 4,
        n - 1,
    ];
    for fold in &frc.events {
        picks.extend([fold.index.saturating_sub(1), fold.index + 1]);
    }
    picks.sort_unstable();
    picks.dedup();
    picks.retain(|&i| i < n);
    let full = full_disk();
    let mut hsu = AdaptiveHsu::new(
        &full,
        5,
        HsuSteps::Tolerance {
            tol: 1e-8,
            max: 4096,
        },
    )
    .unwrap();
    let all: Vec<usize> = (0..full.n_dof()).collect();
    let mut worst_ratio = 0.0f64;
    for &i in &picks {
        let p = &frc.points[i];
        let coeffs = branch.recover(&p.coeffs, p.omega_f, &all).unwrap().concat();
        let reference = hsu.floquet(&full, &orbit(coeffs, p.omega_f, 5)).unwrap();
        let unforced = orbit(vec![0.0; all.len() * 11], p.omega_f, 5);
        let linear = hsu.floquet(&full, &unforced).unwrap();
        let reduced = p.floquet.as_ref().unwrap();
        // The 33 modes the tip does not see (one of each degenerate pair of
        // nodal diameters 1–11) keep their linear multipliers, which the
        // reduced set omits: each reduced multiplier is matched to its own
        // full one, and each full multiplier left to its own multiplier of
        // the unforced structure.
        let mut rest = reference.floquet.multipliers.clone();
        let seen = matched(&reduced.floquet.multipliers, &mut rest);
        let unseen = matched(&rest, &mut linear.floquet.multipliers.clone());
        assert_eq!(rest.len(), 66);
        let d = seen.max(unseen);
        println!(
            "seen {seen:e} unseen {unseen:e} hsu {:e} ref {:e}",
            reduced.hsu_error,
            reference.error.unwrap()
        );
        let estimate = reduced.error_estimate() + reference.error.unwrap() + linear.error.unwrap();
        println!(
            "ω = {:.4} (amplitude {:.4e}): |μ|max {:.12} (full {:.12}), distance {d:e}, \
             estimate {estimate:e} (basis {})",
            p.omega_f,
            p.amplitude,
            reduced.floquet.max_modulus(),
            reference.floquet.max_modulus(),
            reduced.basis
        );
        assert!(
            d <= estimate,
            "ω = {}: distance {d:e} > estimate {estimate:e}",
            p.omega_f
        );
        // Not vacuous: Hsu's part is at most twice its 1e-6 tolerance, the
        // basis's rounding.
        assert!(
            reduced.error_estimate() <= 2e-6,
            "ω = {}: {:e}",
            p.omega_f,
            reduced.error_estimate()
        );
        assert_eq!(reduced.basis, 39, "ω = {}", p.omega_f);
        assert!(reduced.truncation_error <= 1e-9, "ω = {}", p.omega_f);
        assert_eq!(
            reduced.floquet.kind, reference.floquet.kind,
            "ω = {}",
            p.omega_f
        );
        worst_ratio = worst_ratio.max(d / estimate);
    }
    println!(
        "{} folds; worst distance / estimate {worst_ratio}",
        frc.events.len()
    );
}
