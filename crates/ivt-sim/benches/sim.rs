//! Hot paths of the simulator (divan): the default 60 s drive scene at PPR
//! 1200 (target: ≥ 1000× real time, i.e. ≤ 60 ms, with MCAP on), and one
//! open-loop angle-domain solve of the work–precision problem.
// A bench may expect (the package's panic lints guard library code).
#![allow(clippy::expect_used)]

use ivt_sim::integrate::{Method, Tolerance};
use ivt_sim::scene::Scene;
use ivt_sim::testing::shipped_scene;

fn main() {
    divan::main();
}

fn drive() -> Scene {
    shipped_scene("drive.toml")
}

/// The closed loop alone (no channels, no files).
#[divan::bench(sample_count = 10)]
fn drive_60s_no_outputs(b: divan::Bencher) {
    let mut s = drive();
    s.outputs = Default::default();
    b.bench(|| ivt_sim::run::Simulation::new(&s).run().expect("runs"));
}

/// What `cargo run --release` does (minus process start): the run with the
/// MCAP log streamed to a file by the writer thread, then summary + PNG.
#[divan::bench(sample_count = 10)]
fn drive_60s_with_mcap_and_png(b: divan::Bencher) {
    bench_write(b, &drive(), "ivt-sim-bench");
}

/// MCAP (+ summary) only, no PNG: the acceptance configuration (≤ 60 ms).
#[divan::bench(sample_count = 10)]
fn drive_60s_with_mcap(b: divan::Bencher) {
    let mut s = drive();
    s.outputs.plots.clear();
    bench_write(b, &s, "ivt-sim-bench-mcap");
}

/// The MCAP log written after the run from the recorded channels (no writer
/// thread): the serial cost of serialization + compression.
#[divan::bench(sample_count = 10)]
fn drive_60s_with_mcap_serial(b: divan::Bencher) {
    let mut s = drive();
    s.outputs.plots.clear();
    let dir = std::env::temp_dir().join("ivt-sim-bench-mcap-serial");
    b.bench(|| {
        let r = ivt_sim::run::Simulation::new(&s).run().expect("runs");
        ivt_sim::output::write_all(&dir, &s, &r).expect("writes")
    });
}

/// Times `run_and_write` of `s` into the temporary directory `dir_name`.
fn bench_write(b: divan::Bencher, s: &Scene, dir_name: &str) {
    let dir = std::env::temp_dir().join(dir_name);
    b.bench(|| {
        ivt_sim::output::run_and_write(&dir, s, |sink| {
            ivt_sim::run::Simulation::new(s)
                .sink(sink)
                .answer_by_time_integration()
        })
        .expect("runs and writes")
        .1
    });
}

/// Work–precision problem, DP5 at rtol = atol = 1e-8 (≈ 100 rad of θ).
#[divan::bench]
fn open_loop_dp5_1e8() -> (f64, u64) {
    let tol = Tolerance::uniform(1e-8);
    ivt_sim::work_precision::solve(&ivt_sim::work_precision::PROBLEM, Method::Dp5(tol))
}
