//! scratch
use ivt_hb::ivt::*;
use ivt_kin::plant::PlantParams;
fn main() {
    let plant = PlantParams::printed();
    for (v, t) in [(6.0, 6.0), (8.4, 1.5), (12.0, 2.0)] {
        let op = OperatingPoint::at_100_rpm(v, t);
        let rs = shooting::shoot_steady_state(&plant, &op, None, &Default::default()).unwrap().r;
        println!("V={v} T={t} shoot r={rs:.12e}");
        for n in [3, 7, 15, 31, 63, 127] {
            let o = steady::IhbOptions { harmonics: n, ..Default::default() };
            let t0 = std::time::Instant::now();
            match steady::solve_steady_state(&plant, &op, o) {
                Ok(st) => println!("  n={n} r={:.12e} rel={:.2e} it={} res={:.1e} {:?}", st.r, (st.r-rs)/rs, st.iterations, st.residual_norm, t0.elapsed()),
                Err(e) => println!("  n={n} err {e}"),
            }
        }
    }
}
