//! scratch
use ivt_hb::ivt::delay::*;
use ivt_hb::ivt::*;
use ivt_kin::plant::PlantParams;
fn main() {
    let plant = PlantParams::printed();
    for (v, t) in [(7.0, 2.0), (10.0, 6.0)] {
        let op = OperatingPoint::at_100_rpm(v, t);
        for (k, k2) in [(0.01, 0.02), (0.06, 0.12)] {
            for scale in [1e-3, 1.0] {
                let g = FeedbackGains {
                    k: k * scale,
                    k2: k2 * scale,
                };
                for nn in [8, 16, 32] {
                    let o = DelayOptions {
                        chebyshev_order: nn,
                        ..Default::default()
                    };
                    let t0 = std::time::Instant::now();
                    match delay_stability(&plant, &op, g, &o) {
                    Ok(s) => println!("V={v} T={t} k={} k2={} N={nn}: max={:.8} unit=({:.2e},{:.1e}) r={:.5} {:?}", g.k, g.k2, s.max_abs_multiplier, s.structural.0-1.0, s.structural.1, s.orbit.r, t0.elapsed()),
                    Err(e) => println!("err {e}"),
                }
                }
            }
        }
    }
}
