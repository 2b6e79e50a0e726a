//! Condensation onto the nonlinear DOFs (issue 28), checked from outside:
//! the cantilever's condensed curve against the uncondensed harmonic balance
//! (N = 20: every coefficient of every DOF and both folds to 1e-10), against
//! RK4 time integration of the full ODE (N = 4), the refined receptances of
//! the fine mesh against a double-double band elimination (N = 50, 500), and
//! the per-point truncation estimate against more harmonics.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

#[path = "common/beam.rs"]
mod beam;
#[path = "../../ivt-hb/tests/common/mod.rs"]
mod common;
#[path = "common/dd.rs"]
mod dd;
#[path = "common/disk.rs"]
mod disk;
#[path = "common/full_dd.rs"]
mod full_dd;

use beam::{beam, full_beam, orbit, FORCE, OMEGA1};
use common::orbit_defect;
use faer::{c64, Mat};
use ivt_condense::models::{cantilever, BeamProperties};
use ivt_condense::{
    condensed_response, correct_condensed, CondensedFrc, CondensedFrcOptions, Structure,
};
use ivt_hb::{
    locate_fold, ClassicIhb, FamilyBranch, Frequency, HbOptions, LocateOptions, PeriodicProblem,
};

/// The condensed curve of the `n`-element beam over 0.7–1.3 ω₁ with `hb`.
fn curve(
    n: usize,
    hb: &HbOptions,
) -> (
    CondensedFrc,
    ivt_condense::CondensedBranch<impl PeriodicProblem>,
) {
    let mut branch = beam(n, FORCE, hb);
    let opts = CondensedFrcOptions {
        from: 0.7 * OMEGA1,
        to: 1.3 * OMEGA1,
        ..CondensedFrcOptions::default()
    };
    let frc = condensed_response(&mut branch, &opts).unwrap();
    (frc, branch)
}

/// All DOFs' coefficients of a condensed orbit, DOF-major (the layout of
/// the uncondensed unknowns).
fn all_dofs<P: PeriodicProblem>(
    branch: &mut ivt_condense::CondensedBranch<P>,
    q: &[f64],
    omega_f: f64,
) -> Vec<f64> {
    let nd = branch.structure().n_dof();
    let dofs: Vec<usize> = (0..nd).collect();
    branch.recover(q, omega_f, &dofs).unwrap().concat()
}

/// The condensed curve of the `n`-element beam against the uncondensed HB
/// (dense, `n_dof·(2n+1)` unknowns): every coefficient of every DOF at every
/// fourth point, from a full Newton started 1e-4 away (to `full_rtol` of the
/// force), within `coeff_tol` of
/// the largest; the full residual at the condensed orbit within
/// `residual_tol` of the force; both folds again on the full extended system
/// to 1e-10 in ω.
fn against_uncondensed(n: usize, full_rtol: f64, coeff_tol: f64, residual_tol: f64) {
    let hb = HbOptions::new(7, 32).with_tolerances(1e-12, 0.0);
    let (frc, mut branch) = curve(n, &hb);
    assert_eq!(frc.events.len(), 2, "the hardening peak turns twice");
    assert!(frc.events.iter().all(|f| f.located));
    let (full, _) = full_beam(n);
    let mut classic = ClassicIhb::new(&full, hb.clone().with_tolerances(full_rtol, 0.0)).unwrap();
    let mut residual = ivt_hb::HbResidual::new(&full, &hb).unwrap();
    let mut r = vec![0.0; residual.len()];
    let (mut worst, mut worst_r) = (0.0f64, 0.0f64);
    for p in frc.points.iter().step_by(4) {
        let condensed = all_dofs(&mut branch, &p.coeffs, p.omega_f);
        residual.eval(&full, &condensed, p.omega_f, 1.0, &mut r);
        worst_r = worst_r.max(ivt_num::vector::norm2(&r) / FORCE);
        let guess: Vec<f64> = condensed.iter().map(|v| v * (1.0 + 1e-4)).collect();
        let sol = classic.solve(p.omega_f, Some(&guess)).unwrap();
        let scale = condensed.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let diff = sol
            .coeffs
            .iter()
            .zip(&condensed)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        worst = worst.max(diff / scale);
    }
    assert!(
        worst <= coeff_tol,
        "N = {n}: condensed vs full coefficients {worst:e}"
    );
    assert!(
        worst_r <= residual_tol,
        "N = {n}: full residual {worst_r:e}"
    );
    // Each fold located again on the full extended system.
    let mut family = FamilyBranch::new(Frequency(&full), &hb, frc.events[0].omega_f).unwrap();
    for fold in &frc.events {
        let q = all_dofs(&mut branch, &fold.coeffs, fold.omega_f);
        let located = locate_fold(&mut family, &q, fold.omega_f, &LocateOptions::fold()).unwrap();
        let rel = (located.lambda - fold.omega_f).abs() / fold.omega_f;
        assert!(
            rel <= 1e-10,
            "N = {n}: fold {} vs {}: {rel:e}",
            fold.omega_f,
            located.lambda
        );
    }
}

#[test]
fn condensed_equals_uncondensed_harmonic_balance() {
    // N = 8: the full solve reaches 1e-10. N = 20: the full solve's own
    // rounding floor (‖R‖ ≈ 2e-12 ≈ ε‖K‖‖x‖, K entries ~1e5) limits it to a
    // few 1e-9 near the folds (measured 3.4e-9 there, ≤ 1e-9 elsewhere), so
    // there the condensed orbit is checked as a solution of the full
    // equations: its full residual is at that floor.
    against_uncondensed(8, 1e-10, 1e-10, 1e-10);
    against_uncondensed(20, 1e-9, 5e-9, 5e-9);
}

#[test]
fn condensed_equals_the_refined_uncondensed_harmonic_balance_at_n_20() {
    // The uncondensed equations of `against_uncondensed` solved with their
    // residual in double-double (common/full_dd.rs, written out there, not
    // ivt-hb's), Newton started 1e-4 away from the condensed orbit: at every
    // fourth point every coefficient of every DOF within 1e-10 of the
    // largest (the double solve's floor stopped it at 3.4e-9 near the folds;
    // refined, the two agree to 1.2e-14, measured).
    let n = 20;
    let hb = HbOptions::new(7, 32).with_tolerances(1e-12, 0.0);
    let (frc, mut branch) = curve(n, &hb);
    let full = full_dd::FullBeam::new(n, 7);
    let (mut worst, mut worst_r) = (0.0f64, 0.0f64);
    for p in frc.points.iter().step_by(4) {
        let condensed = all_dofs(&mut branch, &p.coeffs, p.omega_f);
        let start: Vec<f64> = condensed.iter().map(|v| v * (1.0 + 1e-4)).collect();
        let (refined, residual) = full.refine(start, p.omega_f);
        worst_r = worst_r.max(residual);
        let scale = condensed.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let diff = refined
            .iter()
            .zip(&condensed)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        worst = worst.max(diff / scale);
    }
    // The refined orbit's residual is at the floor of a double vector,
    // ε‖K‖‖x‖ (≈ 1e-10 of the force here; measured ≤ 3.0e-10): the written-out
    // equations are the ones solved.
    assert!(worst_r <= 1e-9, "full residual {worst_r:e}");
    // Measured 1.2e-14.
    assert!(worst <= 1e-10, "condensed vs refined full {worst:e}");
    eprintln!("N = 20: condensed vs refined full {worst:e}, full residual {worst_r:e}");
}

#[test]
fn condensed_orbits_solve_the_ode_by_rk4_at_n_4() {
    // Points of the two stable branches (away from the folds): one period of
    // RK4 (2^16 steps) from the recovered full state stays on the orbit.
    let hb = HbOptions::new(11, 48).with_tolerances(1e-13, 0.0);
    let (frc, mut branch) = curve(4, &hb);
    let (full, _) = full_beam(4);
    let (first, second) = (frc.events[0].index, frc.events[1].index);
    let stable = frc
        .points
        .iter()
        .enumerate()
        .filter(|(i, _)| *i + 3 < first || *i > second + 3)
        .step_by(6);
    let mut checked = 0;
    for (_, p) in stable {
        let coeffs = all_dofs(&mut branch, &p.coeffs, p.omega_f);
        let sol = orbit(coeffs, p.omega_f, hb.harmonics);
        let defect = orbit_defect(&full, &sol, 1 << 16);
        assert!(
            defect <= 1e-9 * p.amplitude,
            "ω = {}: defect {defect:e} of {}",
            p.omega_f,
            p.amplitude
        );
        checked += 1;
    }
    assert!(checked >= 4, "{checked} points checked");
}

#[test]
fn refined_receptances_equal_a_double_double_elimination() {
    // The fine mesh: κ(K) ~ N⁴. The tip receptance by LU + refinement equals
    // Gaussian elimination in double-double (≈ 32 digits) to rounding, and its
    // error estimate covers the difference; the LU alone does not come close
    // near resonance at N = 500. The rounding of the stored M and C (K is
    // exact) is a model perturbation of its own: 1.3e-7 at ω₁ for N = 500,
    // 7e-12 for N = 50 (measured), which no solver of the stored matrices
    // can undo.
    for n in [50usize, 500] {
        let b = cantilever(n, &BeamProperties::default()).unwrap();
        let s = &b.model;
        let st = Structure::new(s.m.as_ref(), s.c.as_ref(), s.k.as_ref()).unwrap();
        for w in [0.0, 3.3, OMEGA1, 3.9, 11.0, 15.4, 22.0] {
            let reference =
                dd::receptance_column(s.m.as_ref(), s.c.as_ref(), s.k.as_ref(), w, 3, b.tip)[b.tip];
            let exact = c64::new(reference.re.to_f64(), reference.im.to_f64());
            let f = st.factor(w).unwrap();
            let mut u = Mat::<c64>::zeros(s.n_dof(), 1);
            u[(b.tip, 0)] = c64::new(1.0, 0.0);
            let mut plain = u.clone();
            let estimate = st.solve_refined(&f, u.as_mut());
            st.solve_plain(&f, plain.as_mut());
            let err = (u[(b.tip, 0)] - exact).norm() / exact.norm();
            assert!(
                err <= 4e-16 && err <= estimate,
                "N = {n}, w = {w}: {err:e} (estimate {estimate:e})"
            );
            assert!(estimate <= 1e-15, "N = {n}, w = {w}: estimate {estimate:e}");
            if n == 500 && w == OMEGA1 {
                let lost = (plain[(b.tip, 0)] - exact).norm() / exact.norm();
                assert!(lost > 1e-7, "the plain LU loses {lost:e} at resonance");
            }
            // What the stored (rounded) M and C themselves move: the same
            // elimination on the element formulas in double-double.
            let ideal = dd::band_solve(
                s.n_dof(),
                |i, j| dd::exact_cantilever_entry(n, i, j),
                w,
                3,
                b.tip,
            )[b.tip];
            let ideal = c64::new(ideal.re.to_f64(), ideal.im.to_f64());
            let data = (ideal - exact).norm() / ideal.norm();
            let bound = if n == 500 { 3e-7 } else { 1e-10 };
            assert!(
                data <= bound,
                "N = {n}, w = {w}: stored data move it by {data:e}"
            );
        }
    }
}

#[test]
fn truncation_estimate_covers_the_change_to_more_harmonics() {
    // n = 5 against n = 11 at every third point of the N = 20 curve: no
    // coefficient of the tip moves by more than twice the per-point estimate
    // of n = 5 (relative to the largest).
    let low = HbOptions::new(5, 32).with_tolerances(1e-13, 0.0);
    let high = HbOptions::new(11, 48).with_tolerances(1e-13, 0.0);
    let (frc, _) = curve(20, &low);
    let mut fine = beam(20, FORCE, &high);
    let mut worst_ratio = 0.0f64;
    for p in frc.points.iter().step_by(3) {
        let mut x = ivt_hb::orbit::aft::resize_harmonics(&p.coeffs, high.harmonics);
        correct_condensed(&mut fine, &mut x, p.omega_f, 1e-14).unwrap();
        let coarse = ivt_hb::orbit::aft::resize_harmonics(&p.coeffs, high.harmonics);
        let scale = x
            .iter()
            .take(coarse.len())
            .fold(0.0f64, |a, v| a.max(v.abs()));
        let moved = coarse
            .iter()
            .zip(&x)
            .fold(0.0f64, |a, (c, f)| a.max((c - f).abs()))
            / scale;
        println!("{} {moved:e} {:e}", p.omega_f, p.truncation_error.unwrap());
        let estimate = p.truncation_error.unwrap();
        assert!(
            moved <= 2.0 * estimate + 1e-12,
            "ω = {}: moved {moved:e}, estimate {estimate:e}",
            p.omega_f
        );
        worst_ratio = worst_ratio.max(moved / estimate);
    }
    assert!(
        worst_ratio > 0.05,
        "the estimate is not vacuous: {worst_ratio}"
    );
}

#[test]
fn bladed_disk_curve_solves_the_uncondensed_equations() {
    // pyHarm's 72-DOF disk (tutorial 006) with the cubic spring 5e10 x³ at
    // sector 0's blade tip, F = 1 there, from ω = 1150 rad/s: every tenth
    // point's recovered 72-DOF orbit has a full HB residual (dense, Eq. 61)
    // below 1e-9 of the force.
    use ivt_condense::models::bladed_disk;
    use ivt_condense::CondensedBranch;
    let disk = bladed_disk().unwrap();
    let s = &disk.model;
    let nd = s.n_dof();
    let structure = Structure::new(s.m.as_ref(), s.c.as_ref(), s.k.as_ref()).unwrap();
    let mut load = vec![0.0; nd];
    load[disk.tip] = 1.0;
    let local = disk::tip_problem();
    let hb = HbOptions::new(5, 32);
    let mut branch =
        CondensedBranch::new(structure, vec![disk.tip], &load, &[], local, &hb).unwrap();
    // The whole band at the default step control (in scaled unknowns: the
    // path once took > 5000 steps to 1218 rad/s, the corrector's tolerance
    // below the rounding of ω_f).
    let opts = CondensedFrcOptions {
        from: 1150.0,
        to: 1260.0,
        ..CondensedFrcOptions::default()
    };
    let frc = condensed_response(&mut branch, &opts).unwrap();
    println!("{} points, {} folds", frc.points.len(), frc.events.len());
    assert_eq!(frc.termination, ivt_hb::Termination::LeftInterval);
    assert!(frc.points.len() < 400, "{} points", frc.points.len());
    assert!(frc.points.iter().all(|p| p.floquet.is_some()));
    let full = disk::full_disk();
    let mut residual = ivt_hb::HbResidual::new(&full, &hb).unwrap();
    let mut r = vec![0.0; residual.len()];
    for p in frc.points.iter().step_by(10) {
        let q = all_dofs(&mut branch, &p.coeffs, p.omega_f);
        residual.eval(&full, &q, p.omega_f, 1.0, &mut r);
        let rel = ivt_num::vector::norm2(&r);
        assert!(rel <= 1e-9, "ω = {}: full residual {rel:e}", p.omega_f);
    }
}
