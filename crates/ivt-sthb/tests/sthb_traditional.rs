//! The "traditional route" of issue 4: the hand-derived N-mode Galerkin model
//! (`ModalString`, closed-form cubic tensor) solved as a `PeriodicProblem` by
//! the general engine (modified IHB, Broyden, pseudo-arclength, Hsu), against
//! the STHB route on the same curve (N = 5, k_d = 10, c_d = 0.8, y0 = 0.5, M = 19).
#![allow(clippy::unwrap_used)]

use ivt_hb::branches::frc::{frequency_response as engine_frc, FrcOptions};
use ivt_hb::{HbOptions, HbResidual, ModifiedIhb, Path};
use ivt_sthb::frc::{trace, StringFrcOptions};
use ivt_sthb::modal::ModalString;
use ivt_sthb::{StringHb, StringParams};
use std::time::Instant;

/// The engine's options matching the STHB grid: M = 19 harmonics, 2·64 = M_s samples.
fn engine_options(p: &StringParams) -> HbOptions {
    HbOptions::new(p.harmonics, p.ms / 2)
}

/// The STHB arclength curve 1 ≤ ω ≤ 6 without stability (the reference of both
/// curve tests).
/// Points hold the coefficients, then ω.
fn sthb_curve(p: &StringParams) -> Path {
    let mut hb = StringHb::new(p.clone()).unwrap();
    trace(&mut hb, 1.0, 6.0, &StringFrcOptions::default().continuation).unwrap()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Both routes discretize the same algebraic system: the STHB residual (DST-I on
/// N_s − 1 = 63 points, FFT on M_s = 128 samples) equals the engine's AFT residual
/// of the closed-form modal ODEs, row for row, at arbitrary coefficients.
///
/// Why exactly: `k_d w_x² w_xx` with N modes is a sine series up to mode 3N; on the
/// grid `x_k = k/N_s` mode `2N_s − n` aliases onto `n`, which stays clear of
/// `n ≤ N` while `N_s > 2N` (15 < 123 here, and always under `StringParams::validate`).
/// In time the cubic has harmonics up to 3M = 57, aliasing onto `k ≤ M` only if
/// `M_s ≤ 4M = 76` (M_s = 128). So the only differences are rounding (different
/// summation orders of cubic terms with coefficients up to k_d π⁴ a b c² ≈ 1e6):
/// measured ≤ 2.2e-16 of the largest entry, 1e-13 asserted.
#[test]
fn residuals_are_the_same_algebraic_system() {
    let p = StringParams::default();
    let modal = ModalString::new(p.clone());
    let mut hb = StringHb::new(p.clone()).unwrap();
    let mut res = HbResidual::new(&modal, &engine_options(&p)).unwrap();
    let dim = hb.dim();
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    for (amp, omega) in [(0.02, 1.7), (0.1, 3.9), (0.3, 5.2)] {
        let a: Vec<f64> = (0..dim)
            .map(|i| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                // Decaying with harmonic and mode like a response.
                let (h, n) = (i / p.modes, i % p.modes);
                amp * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
                    / (1.0 + h as f64)
                    / (1.0 + n as f64).powi(2)
            })
            .collect();
        let mut r_sthb = vec![0.0; dim];
        hb.residual(&a, omega, &mut r_sthb);
        let mut r_eng = vec![0.0; dim];
        res.eval(&modal, &modal.engine_coeffs(&a), omega, 1.0, &mut r_eng);
        // Rows map like the coefficients, except that the constant row is the mean
        // in both (no factor ½ to undo): `sthb_coeffs` halves it, so double it back.
        let mut r_eng_in_sthb = modal.sthb_coeffs(&r_eng);
        r_eng_in_sthb[..p.modes].iter_mut().for_each(|v| *v *= 2.0);
        let scale = max_abs(&r_sthb);
        let diff = r_sthb
            .iter()
            .zip(&r_eng_in_sthb)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        eprintln!(
            "amp {amp}, ω {omega}: max |ΔR| / max |R| = {:e}",
            diff / scale
        );
        assert!(
            diff <= 1e-13 * scale,
            "amp {amp}, ω {omega}: residuals differ by {diff:e} (max entry {scale:e})"
        );
    }
}

/// The same curve through both routes at the same ω points: the engine's
/// modified IHB, warm-started from its own previous point, at every ω of the
/// STHB arclength curve (k_d = 10 is single-valued, Fig. 34).
///
/// Tolerance: both solvers stop at ‖R‖ ≤ ~1.5e-10 of the same residual (previous
/// test); the coefficient error is at most ‖J⁻¹‖ times that, and ‖J⁻¹‖ ≤ 1/(c_d ω)
/// ≈ 1.25 for the resonant mode and smaller elsewhere along this stable branch, so
/// ~2e-10 is expected; 1e-8 of max |a| (≈ 0.4) is asserted.
#[test]
fn engine_route_matches_sthb_on_the_curve() {
    let p = StringParams::default();
    let t0 = Instant::now();
    let frc = sthb_curve(&p);
    let t_sthb = t0.elapsed();
    let modal = ModalString::new(p.clone());
    let mut ihb = ModifiedIhb::new(modal.clone(), engine_options(&p)).unwrap();
    let t0 = Instant::now();
    let mut prev: Option<Vec<f64>> = None;
    let mut worst: f64 = 0.0;
    let mut iters = 0;
    for pt in &frc.points {
        let (omega, coeffs) = (pt.lambda(), &pt.x[..pt.x.len() - 1]);
        let sol = ihb
            .solve(omega, prev.as_deref())
            .unwrap_or_else(|e| panic!("engine at ω = {omega}: {e}"));
        iters += sol.stats.iterations;
        let a = modal.sthb_coeffs(&sol.coeffs);
        let err = a
            .iter()
            .zip(coeffs)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        worst = worst.max(err / max_abs(coeffs));
        prev = Some(sol.coeffs);
    }
    let t_engine = t0.elapsed();
    eprintln!(
        "{} points: STHB {:?}, engine {:?} ({} Broyden iterations); worst relative difference {worst:e}",
        frc.points.len(),
        t_sthb,
        t_engine,
        iters
    );
    assert!(worst <= 1e-8, "routes differ by {worst:e} (relative)");
}

/// The engine's own path (pseudo-arclength with Broyden, Hsu stability) on the
/// modal model: all stable like Fig. 34, and each of its points is an STHB
/// solution (Newton at the engine's ω from the nearest STHB point, same tolerance
/// argument as above).
#[test]
fn engine_arclength_curve_is_the_sthb_curve() {
    let p = StringParams::default();
    let modal = ModalString::new(p.clone());
    let t0 = Instant::now();
    let eng = engine_frc(
        &modal,
        &engine_options(&p),
        &FrcOptions {
            from: 1.0,
            to: 6.0,
            ..Default::default()
        },
    )
    .unwrap();
    eprintln!(
        "engine arclength: {} points in {:?}, {:?}",
        eng.points.len(),
        t0.elapsed(),
        eng.termination
    );
    assert!(eng.points.last().unwrap().omega_f >= 6.0);
    assert!(eng.points.iter().all(|pt| pt.stable()));
    let frc = sthb_curve(&p);
    let mut hb = StringHb::new(p.clone()).unwrap();
    let mut worst: f64 = 0.0;
    for pt in &eng.points {
        let near = frc
            .points
            .iter()
            .min_by(|x, y| {
                (x.lambda() - pt.omega_f)
                    .abs()
                    .total_cmp(&(y.lambda() - pt.omega_f).abs())
            })
            .unwrap();
        let mut a = near.x[..near.x.len() - 1].to_vec();
        hb.solve(pt.omega_f, &mut a, 1e-10, 50).unwrap();
        let b = modal.sthb_coeffs(&pt.coeffs);
        let err = a
            .iter()
            .zip(&b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        worst = worst.max(err / max_abs(&a));
    }
    eprintln!("engine arclength vs STHB: worst relative difference {worst:e}");
    assert!(worst <= 1e-8, "routes differ by {worst:e} (relative)");
}
