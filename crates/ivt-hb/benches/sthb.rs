//! STHB benchmarks (issue 4): one frequency–response curve with stability,
//! the pieces of one Newton step against the unknown count, and the stability
//! methods. Run: `cargo bench -p ivt-hb --bench sthb`.

use divan::Bencher;
use faer::Mat;
use ivt_hb::sthb::continuation::{frequency_response, ContinuationOptions};
use ivt_hb::sthb::stability::{hill, monodromy};
use ivt_hb::sthb::{StringHb, StringParams};

fn main() {
    divan::main();
}

fn solved(modes: usize, harmonics: usize, omega: f64) -> (StringHb, Vec<f64>) {
    let mut hb = StringHb::new(StringParams {
        modes,
        harmonics,
        ..Default::default()
    })
    .unwrap();
    let mut a = vec![0.0; hb.dim()];
    hb.solve(omega, &mut a, 1e-10, 50).unwrap();
    (hb, a)
}

/// Fig. 34 curve: k_d = 10, N = 5, M = 19, ω ∈ [1, 6], stability at every point.
#[divan::bench(sample_count = 5)]
fn frc_kd10_n5(bencher: Bencher) {
    bencher.bench_local(|| {
        let mut hb = StringHb::new(StringParams::default()).unwrap();
        frequency_response(&mut hb, 1.0, 6.0, &ContinuationOptions::default()).unwrap()
    });
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
