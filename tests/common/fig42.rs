//! Fig. 42's example point and its two printed multipliers, shared by the
//! Chapter 4 hypothesis tests (`tests/ch4_causes.rs`, `tests/ch4_causes_law.rs`,
//! included by `#[path]`; each uses a part of it).
#![allow(dead_code)]
// A test may expect and index (the package's panic lints guard library code).
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use ivt_design::delay::{delay_stability_about, steady_orbit, DelayOptions, FeedbackGains};
use ivt_design::shooting::PeriodicOrbit;
use ivt_design::OperatingPoint;
use ivt_hb::stability::floquet::eigenvalues;
use ivt_kin::plant::{PlantParams, PlantPreset};

/// Fig. 42's two printed cases at (7 V, 2 N·m): gains in mm·rad⁻¹ and the
/// printed max |multiplier| (§4.3).
pub const PRINTED: [(f64, f64, f64); 2] = [(0.01, 0.02, 0.7776), (0.06, 0.12, 0.4871)];

/// Ours on thesis-ch4 (Chebyshev Tau N = 16, RK6 monodromy), confirmed by
/// simulation in `tests/ch4_plant.rs`.
pub const OURS: [f64; 2] = [0.78657, 0.60444];

pub fn fig42_point() -> OperatingPoint {
    OperatingPoint::at_100_rpm(7.0, 2.0)
}

/// Max |multiplier| (structural one set aside) for both printed gain pairs,
/// each gain multiplied by (s_k, s_k2), about `orbit` of `plant` at `op`.
pub fn printed_pair(
    plant: &PlantParams,
    op: &OperatingPoint,
    orbit: &PeriodicOrbit,
    (s_k, s_k2): (f64, f64),
) -> [f64; 2] {
    PRINTED.map(|(k, k2, _)| {
        let g = FeedbackGains::from_thesis_mm_per_rad(s_k * k, s_k2 * k2);
        delay_stability_about(plant, op, g, orbit, &DelayOptions::default())
            .expect("stability")
            .max_abs_multiplier
    })
}

/// Thesis-ch4, the example point (7 V, 2 N·m) and its exact 100-rpm orbit.
pub fn fig42_orbit() -> (PlantParams, OperatingPoint, PeriodicOrbit) {
    let plant = PlantPreset::ThesisCh4.params();
    let op = fig42_point();
    let orbit = steady_orbit(&plant, &op, None, &DelayOptions::default()).expect("orbit");
    (plant, op, orbit)
}

/// Both printed pairs on the thesis-ch4 orbit at (7 V, 2 N·m), gains scaled.
pub fn ch4_pair(scale: (f64, f64)) -> [f64; 2] {
    let (plant, op, orbit) = fig42_orbit();
    printed_pair(&plant, &op, &orbit, scale)
}

/// Distance of a computed pair from the printed one, the larger of the two.
pub fn miss(pair: [f64; 2]) -> f64 {
    (pair[0] - PRINTED[0].2)
        .abs()
        .max((pair[1] - PRINTED[1].2).abs())
}

/// Largest |eigenvalue| of a row-major monodromy, the one closest to 1 set
/// aside (Appendix C's structural unit multiplier).
pub fn max_without_structural(m: &[f64], dim: usize) -> f64 {
    let mut mods: Vec<(f64, f64)> = eigenvalues(m, dim)
        .iter()
        .map(|z| (z.re.hypot(z.im), (z.re - 1.0).hypot(z.im)))
        .collect();
    mods.sort_by(|a, b| a.1.total_cmp(&b.1));
    mods[1..].iter().map(|m| m.0).fold(0.0, f64::max)
}
