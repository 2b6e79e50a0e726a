//! Benchmarks of the IVT design tools (issue 7 targets: 416-point IHB grid
//! ≤ 50 ms single thread; one stability evaluation at N = 16 ≤ 5 ms; the
//! whole stability map ≤ 2 s on 2 cores).
// Test code: the crate's panic lints guard shipped code only.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

#[path = "../tests/common/mod.rs"]
mod common;

use ivt_design::delay::{delay_stability_about, steady_orbit, DelayOptions, FeedbackGains};
use ivt_design::gains::stability_map;
use ivt_design::sweep::Grid;
use ivt_design::OperatingPoint;
use ivt_kin::plant::PlantParams;

fn main() {
    divan::main();
}

/// 26 × 16 IHB solves (n = 7), warm starts along rows, one thread.
#[divan::bench(sample_count = 10)]
fn ihb_thesis_grid_serial() {
    divan::black_box(common::thesis_grid_serial());
}

/// One monodromy + eigenvalues at N = 16 about a precomputed steady state.
#[divan::bench(sample_count = 20)]
fn stability_one_point_n16(b: divan::Bencher) {
    let plant = PlantParams::printed();
    let op = OperatingPoint::at_100_rpm(8.4, 4.0);
    let opts = DelayOptions::default();
    let orbit = steady_orbit(&plant, &op, None, &opts).unwrap();
    let g = FeedbackGains::from_thesis_mm_per_rad(0.01, 0.02);
    b.bench(|| delay_stability_about(&plant, &op, g, &orbit, &opts).unwrap());
}

/// The full 416-point map (steady state + stability per point), rayon.
#[divan::bench(sample_count = 3)]
fn stability_map_thesis_grid() {
    let plant = PlantParams::printed();
    let g = Grid::thesis();
    let ops: Vec<OperatingPoint> = g
        .t_u
        .iter()
        .flat_map(|&t| g.v_m.iter().map(move |&v| OperatingPoint::at_100_rpm(v, t)))
        .collect();
    let m = stability_map(
        &plant,
        &ops,
        FeedbackGains::from_thesis_mm_per_rad(0.01, 0.02),
        &DelayOptions::default(),
    )
    .unwrap();
    divan::black_box(m);
}
