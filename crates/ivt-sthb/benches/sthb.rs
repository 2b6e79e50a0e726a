//! STHB benchmarks (issue 4): one frequency–response curve with stability,
//! the pieces of one Newton step against the unknown count, the stability
//! methods, and the "traditional route" (the hand-derived modal model through
//! the general engine) on the same point and curve.
//! Run: `cargo bench -p ivt-hb --bench sthb`.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use divan::Bencher;
use faer::linalg::solvers::Solve;
use faer::Mat;
use ivt_hb::branches::frc::{frequency_response as engine_frc, FrcOptions};
use ivt_hb::{HbOptions, ModifiedIhb};
use ivt_sthb::frc::{frequency_response, trace, StringFrcOptions};
use ivt_sthb::modal::ModalString;
use ivt_sthb::stability::{hill, monodromy};
use ivt_sthb::{StringHb, StringParams};

fn main() {
    divan::main();
}

#[path = "../tests/common/string.rs"]
mod string;

/// The default string (k_d = 10) of `modes` modes and `harmonics` harmonics
/// solved at `omega`.
fn solved(modes: usize, harmonics: usize, omega: f64) -> (StringHb, Vec<f64>) {
    string::solved(modes, harmonics, 10.0, omega, 1e-10)
}

/// Fig. 34 curve: k_d = 10, N = 5, M = 19, ω ∈ [1, 6], stability at every point.
#[divan::bench(sample_count = 5)]
fn frc_kd10_n5(bencher: Bencher) {
    bencher.bench_local(|| {
        let mut hb = StringHb::new(StringParams::default()).unwrap();
        frequency_response(&mut hb, 1.0, 6.0, &StringFrcOptions::default()).unwrap()
    });
}

/// Whole curve ω ∈ [1, 6] with stability against N × M (issue 28): traced in
/// the invariant subspace (odd harmonics × odd modes), monodromy split by mode
/// parity. `bench/sthb_scaling.sh` gives the same with CPU time and points.
#[divan::bench(args = [(5, 19), (10, 19), (10, 39), (20, 39)], sample_count = 3)]
fn frc_whole_curve(bencher: Bencher, (n, m): (usize, usize)) {
    let params = StringParams {
        modes: n,
        harmonics: m,
        ..Default::default()
    };
    bencher.bench_local(|| {
        let mut hb = StringHb::new(params.clone()).unwrap();
        frequency_response(&mut hb, 1.0, 6.0, &StringFrcOptions::default()).unwrap()
    });
}

/// The curve's per-point stability at N = 20, M = 39 (ω = 3): the RK4
/// monodromy of the odd- and even-mode blocks.
#[divan::bench]
fn stability_monodromy_n20(bencher: Bencher) {
    let (hb, _) = solved(20, 39, 3.0);
    bencher.bench_local(|| monodromy(&hb, 3.0).unwrap());
}

/// Residual + exact Jacobian (one Newton step's assembly), unknowns N(2M+1).
#[divan::bench(args = [(5, 19), (10, 19), (20, 19), (5, 40), (10, 40)])]
fn residual_jacobian(bencher: Bencher, (n, m): (usize, usize)) {
    let (mut hb, a) = solved(n, m, 3.0);
    let dim = hb.dim();
    let (mut r, mut j) = (vec![0.0; dim], Mat::zeros(dim, dim));
    bencher.bench_local(|| hb.residual_jacobian(&a, 3.0, &mut r, &mut j));
}

/// Residual only (one chord-corrector step's evaluation).
#[divan::bench(args = [(5, 19), (10, 19)])]
fn residual_only(bencher: Bencher, (n, m): (usize, usize)) {
    let (mut hb, a) = solved(n, m, 3.0);
    let mut r = vec![0.0; hb.dim()];
    bencher.bench_local(|| hb.residual(&a, 3.0, &mut r));
}

/// Dense LU of the (augmented) Jacobian, N = 5, M = 19 (196 unknowns).
#[divan::bench]
fn lu_196(bencher: Bencher) {
    let (mut hb, a) = solved(5, 19, 3.0);
    let dim = hb.dim();
    let (mut r, mut j) = (vec![0.0; dim], Mat::zeros(dim, dim));
    hb.residual_jacobian(&a, 3.0, &mut r, &mut j);
    bencher.bench_local(|| j.partial_piv_lu());
}

/// A full Newton solve from the linear solution's neighbourhood (warm start).
#[divan::bench(args = [(5, 19), (10, 19), (20, 19), (5, 40)], sample_count = 10)]
fn newton_solve(bencher: Bencher, (n, m): (usize, usize)) {
    let (mut hb, a) = solved(n, m, 3.0);
    bencher.bench_local(|| {
        let mut b = a.clone();
        hb.solve(3.05, &mut b, 1e-10, 50).unwrap()
    });
}

/// Monodromy (RK4) against Hill at one point, N = 5, M = 19.
#[divan::bench]
fn stability_monodromy(bencher: Bencher) {
    let (hb, _) = solved(5, 19, 3.0);
    bencher.bench_local(|| monodromy(&hb, 3.0).unwrap());
}

/// Hill's method (Eq. 126–131), N = 5, M = 19 (390 × 390 eigenvalues).
#[divan::bench(sample_count = 5)]
fn stability_hill(bencher: Bencher) {
    let (hb, _) = solved(5, 19, 3.0);
    bencher.bench_local(|| hill(&hb, 3.0).unwrap());
}

/// One full Newton step (residual + exact Jacobian, dense LU, solve) against the
/// unknown count `N(2M + 1)`.
#[divan::bench(args = [(5, 19), (10, 19), (20, 19), (5, 40), (10, 40), (20, 40)], sample_count = 10)]
fn newton_step(bencher: Bencher, (n, m): (usize, usize)) {
    let (mut hb, a) = solved(n, m, 3.0);
    let dim = hb.dim();
    let (mut r, mut j) = (vec![0.0; dim], Mat::zeros(dim, dim));
    bencher.bench_local(|| {
        hb.residual_jacobian(&a, 3.0, &mut r, &mut j);
        let rhs = Mat::from_fn(dim, 1, |i, _| r[i]);
        j.partial_piv_lu().solve(&rhs)
    });
}

// ---- The traditional route: ModalString (N = 5, k_d = 10, c_d = 0.8, y0 = 0.5)
// through the engine's modified IHB (Broyden, AFT with 2·64 = M_s samples, M = 19).

fn modal_ihb() -> ModifiedIhb<ModalString> {
    let p = StringParams::default();
    ModifiedIhb::new(
        ModalString::new(p.clone()),
        HbOptions::new(p.harmonics, p.ms / 2),
    )
    .unwrap()
}

/// One point from scratch: STHB Newton from a = 0.
#[divan::bench(args = [2.0, 3.0, 5.0])]
fn point_cold_sthb(bencher: Bencher, omega: f64) {
    let mut hb = StringHb::new(StringParams::default()).unwrap();
    let dim = hb.dim();
    bencher.bench_local(|| {
        let mut a = vec![0.0; dim];
        hb.solve(omega, &mut a, 1e-10, 50).unwrap()
    });
}

/// One point from scratch: engine modified IHB from the linear solution (Eq. 59).
#[divan::bench(args = [2.0, 3.0, 5.0])]
fn point_cold_engine(bencher: Bencher, omega: f64) {
    let mut ihb = modal_ihb();
    bencher.bench_local(|| ihb.solve(omega, None).unwrap());
}

/// One point on the resonant peak warm-started from ω − 0.02 (a continuation
/// step without the predictor): STHB Newton.
#[divan::bench]
fn point_warm_peak_sthb(bencher: Bencher) {
    let (mut hb, a) = solved(5, 19, 3.78);
    bencher.bench_local(|| {
        let mut b = a.clone();
        hb.solve(3.8, &mut b, 1e-10, 50).unwrap()
    });
}

/// The same for the engine (guess = its solution at ω − 0.02).
#[divan::bench]
fn point_warm_peak_engine(bencher: Bencher) {
    let mut ihb = modal_ihb();
    let q = ihb.solve(3.78, None).unwrap().coeffs;
    bencher.bench_local(|| ihb.solve(3.8, Some(&q)).unwrap());
}

fn sthb_curve_points() -> Vec<f64> {
    let mut hb = StringHb::new(StringParams::default()).unwrap();
    trace(&mut hb, 1.0, 6.0, &StringFrcOptions::default().continuation)
        .unwrap()
        .points
        .iter()
        .map(|p| p.lambda())
        .collect()
}

/// Fig. 34 curve by STHB without stability (173 points, ω ∈ [1, 6]).
#[divan::bench(sample_count = 5)]
fn curve_sthb_no_stability(bencher: Bencher) {
    let opts = StringFrcOptions::default().continuation;
    bencher.bench_local(|| {
        let mut hb = StringHb::new(StringParams::default()).unwrap();
        trace(&mut hb, 1.0, 6.0, &opts).unwrap()
    });
}

/// The engine at the same 173 ω points (warm start from its previous point).
#[divan::bench(sample_count = 2)]
fn curve_engine_same_omegas(bencher: Bencher) {
    let omegas = sthb_curve_points();
    bencher.bench_local(|| {
        let mut ihb = modal_ihb();
        let mut q: Option<Vec<f64>> = None;
        for &w in &omegas {
            q = Some(ihb.solve(w, q.as_deref()).unwrap().coeffs);
        }
        q
    });
}

/// The engine's own curve: `frc::frequency_response` (pseudo-arclength with
/// Broyden, Hsu stability at every point), ω ∈ [1, 6].
#[divan::bench(sample_count = 2)]
fn curve_engine_arclength(bencher: Bencher) {
    let p = StringParams::default();
    let modal = ModalString::new(p.clone());
    let hb = HbOptions::new(p.harmonics, p.ms / 2);
    let opts = FrcOptions {
        from: 1.0,
        to: 6.0,
        ..Default::default()
    };
    bencher.bench_local(|| engine_frc(&modal, &hb, &opts).unwrap());
}

/// One engine residual (AFT of the closed-form cubic), 195 unknowns: the cost of
/// one Broyden iteration besides its O(m²) rank-one update.
#[divan::bench]
fn residual_engine(bencher: Bencher) {
    let mut ihb = modal_ihb();
    let q = ihb.solve(3.0, None).unwrap().coeffs;
    let mut r = vec![0.0; q.len()];
    bencher.bench_local(|| ihb.residual(&q, 3.0, &mut r));
}
