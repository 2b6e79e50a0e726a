//! What the ivt-design tests and benchmarks share (the benchmark includes
//! this file by path).
// Test code: the crate's panic lints guard shipped code only.
#![allow(clippy::unwrap_used)]

use ivt_design::steady::IhbOptions;
use ivt_design::sweep::{sweep_serial, Grid, SweepPoint};
use ivt_kin::plant::PlantParams;

/// The thesis grid (26 × 16 operating points, [`Grid::thesis`]) solved by the
/// IHB with the default options on the printed plant, one thread, warm starts
/// along rows.
pub fn thesis_grid_serial() -> Vec<SweepPoint> {
    sweep_serial(
        &PlantParams::printed(),
        &Grid::thesis(),
        IhbOptions::default(),
    )
    .unwrap()
}
