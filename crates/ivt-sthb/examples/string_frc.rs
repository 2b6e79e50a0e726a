//! Frequency–response curve of the nonlinear string (Figs. 34–35):
//! `cargo run --release -p ivt-hb --example string_frc -- KD N FROM TO`.
#![allow(clippy::expect_used, clippy::indexing_slicing)]
use ivt_sthb::frc::{frequency_response, trace, StringFrcOptions};
use ivt_sthb::{StringHb, StringParams};

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().expect("number"))
        .collect();
    let (kd, n, from, to) = (args[0], args[1] as usize, args[2], args[3]);
    let mut hb = StringHb::new(StringParams {
        kd,
        modes: n,
        ..Default::default()
    })
    .expect("params");
    let t0 = std::time::Instant::now();
    if args.get(4).is_some_and(|v| *v == 0.0) {
        let opts = StringFrcOptions::default().continuation;
        let path = trace(&mut hb, from, to, &opts).expect("path");
        let dt = t0.elapsed().as_secs_f64();
        let dim = hb.dim();
        for p in &path.points {
            println!("{:.5} {:.6}", p.lambda(), hb.complex_norm(&p.x[..dim]));
        }
        eprintln!(
            "points {} time {dt:.3} s stop {:?}",
            path.points.len(),
            path.termination
        );
        return;
    }
    let curve = frequency_response(&mut hb, from, to, &StringFrcOptions::default()).expect("frc");
    let dt = t0.elapsed().as_secs_f64();
    for (p, method) in curve.frc.points.iter().zip(&curve.methods) {
        println!(
            "{:.5} {:.6} {:?} {:.4} {:?}",
            p.omega_f,
            p.amplitude,
            p.kind,
            p.multipliers[0].norm(),
            method
        );
    }
    eprintln!(
        "points {} jacobians {} hill {} time {dt:.3} s stop {:?}",
        curve.frc.points.len(),
        curve.jacobians,
        curve.hill_calls,
        curve.frc.termination
    );
}
