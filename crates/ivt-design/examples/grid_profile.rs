//! Profile helper: the 416-point IHB grid, repeated (for `perf record`).
use ivt_design::steady::IhbOptions;
use ivt_design::sweep::{sweep_serial, Grid};
use ivt_kin::plant::PlantParams;
fn main() {
    let t0 = std::time::Instant::now();
    for _ in 0..5 {
        let p = sweep_serial(
            &PlantParams::printed(),
            &Grid::thesis(),
            IhbOptions::default(),
        )
        .unwrap();
        std::hint::black_box(p);
    }
    eprintln!("per grid: {:?}", t0.elapsed() / 5);
}
