//! Benchmarks of the hot paths (issue 3): Duffing by modified IHB (n = 20, N = 64,
//! from the linear guess), the classic Newton IHB beside it, and the full
//! frequency-response curve 0.2–3.0 with a stability flag at every point, with
//! either corrector, for the Duffing and for the 2-DOF chain of issue 17.
#![allow(clippy::unwrap_used)]

use ivt_hb::{
    frequency_response, ClassicIhb, Corrector, Duffing, FrcOptions, GalerkinJacobian, HbOptions,
    HbResidual, HsuRule, ModifiedIhb, StabilityAnalyzer,
};

fn main() {
    divan::main();
}

/// Fig. 28 point (ω_f = 0.4), modified IHB from the linear solution Eq. 59.
#[divan::bench]
fn duffing_modified_n20_n64(bencher: divan::Bencher) {
    let mut solver = ModifiedIhb::new(Duffing::fig28(), HbOptions::new(20, 64)).unwrap();
    let mut q = vec![0.0; 41];
    bencher.bench_local(|| {
        solver
            .solve_into(divan::black_box(0.4), false, None, &mut q)
            .unwrap()
    });
}

/// Same point including the solver's setup (FFT plans, buffers, linear Jacobian):
/// what a caller pays for one solve with a fresh solver, e.g. one Python call.
#[divan::bench]
fn duffing_modified_with_setup(bencher: divan::Bencher) {
    bencher.bench_local(|| {
        ModifiedIhb::new(Duffing::fig28(), HbOptions::new(20, 64))
            .and_then(|mut s| s.solve(divan::black_box(0.4), None))
            .unwrap()
    });
}

/// Same point, classic IHB (Newton with the quadrature Galerkin Jacobian).
#[divan::bench]
fn duffing_classic_n20_n64(bencher: divan::Bencher) {
    let mut solver = ClassicIhb::new(Duffing::fig28(), HbOptions::new(20, 64)).unwrap();
    bencher.bench_local(|| solver.solve(divan::black_box(0.4), None).unwrap());
}

/// Floquet multipliers by Hsu (256 Magnus-4 steps) at the Fig. 28 point.
#[divan::bench]
fn duffing_hsu_256(bencher: divan::Bencher) {
    let d = Duffing::fig28();
    let sol = ModifiedIhb::new(d.clone(), HbOptions::new(20, 64))
        .unwrap()
        .solve(0.4, None)
        .unwrap();
    let mut an = StabilityAnalyzer::new(&d, 20, 256).unwrap();
    bencher.bench_local(|| an.hsu(&d, &sol, HsuRule::Magnus4));
}

/// Fig. 29: the whole curve 0.2 → 3.0 with stability at every point.
#[divan::bench(sample_count = 10)]
fn duffing_frc_0p2_to_3(bencher: divan::Bencher) {
    let d = Duffing::fig28();
    let hb = HbOptions::new(20, 64);
    let opts = FrcOptions::default();
    bencher.bench_local(|| frequency_response(&d, &hb, &opts).unwrap());
}

#[path = "../tests/common/chain.rs"]
mod chain;
use chain::cubic_chain as chain;

/// The chain's curve with the default (Broyden) corrector.
#[divan::bench(sample_count = 10)]
fn chain_frc_0p2_to_3(bencher: divan::Bencher) {
    let p = chain();
    let hb = HbOptions::new(20, 84);
    let opts = FrcOptions::default();
    bencher.bench_local(|| frequency_response(&p, &hb, &opts).unwrap());
}

/// The same curve with the Newton–chord corrector (exact Galerkin Jacobian).
#[divan::bench(sample_count = 10)]
fn chain_frc_newton_0p2_to_3(bencher: divan::Bencher) {
    let p = chain();
    let hb = HbOptions::new(20, 84);
    let mut opts = FrcOptions::default();
    opts.path.continuation.corrector = Corrector::Newton;
    bencher.bench_local(|| frequency_response(&p, &hb, &opts).unwrap());
}

/// The Duffing curve with the Newton–chord corrector.
#[divan::bench(sample_count = 10)]
fn duffing_frc_newton_0p2_to_3(bencher: divan::Bencher) {
    let d = Duffing::fig28();
    let hb = HbOptions::new(20, 64);
    let mut opts = FrcOptions::default();
    opts.path.continuation.corrector = Corrector::Newton;
    bencher.bench_local(|| frequency_response(&d, &hb, &opts).unwrap());
}

/// One exact Galerkin Jacobian (Eq. 56) of the chain, n = 20, 2N = 168, at the
/// orbit of ω_f = 1.2: what every Newton step of the classic IHB, the fold
/// locator and exact continuation pays.
#[divan::bench]
fn chain_galerkin_assemble(bencher: divan::Bencher) {
    let chain = chain();
    let opts = HbOptions::new(20, 84);
    let sol = ModifiedIhb::new(chain.clone(), opts.clone())
        .unwrap()
        .solve(1.2, None)
        .unwrap();
    let mut res = HbResidual::new(&chain, &opts).unwrap();
    let mut galerkin = GalerkinJacobian::new(&res);
    let m = res.len();
    let mut jac = vec![0.0; m * m];
    bencher.bench_local(|| {
        galerkin.assemble(
            &mut res,
            &chain,
            divan::black_box(&sol.coeffs),
            1.2,
            1.0,
            &mut jac,
        )
    });
}
