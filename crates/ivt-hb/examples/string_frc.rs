//! Frequency–response curve of the nonlinear string (Figs. 34–35):
//! `cargo run --release -p ivt-hb --example string_frc -- KD N FROM TO`.
use ivt_hb::sthb::continuation::{frequency_response, ContinuationOptions};
use ivt_hb::sthb::{StringHb, StringParams};

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
    let stability = args.get(4).is_none_or(|v| *v != 0.0);
    let frc = frequency_response(
        &mut hb,
        from,
        to,
        &ContinuationOptions {
            stability,
            ..Default::default()
        },
    )
    .expect("frc");
    let dt = t0.elapsed().as_secs_f64();
    for p in &frc.points {
        let Some(s) = p.stability else {
            println!("{:.5} {:.6}", p.omega, p.norm);
            continue;
        };
        println!(
            "{:.5} {:.6} {:?} {:.4} {:?} {}",
            p.omega,
            p.norm,
            s.kind,
            s.critical.norm(),
            s.method,
            p.iterations
        );
    }
    eprintln!(
        "points {} factorizations {} hill {} time {:.3} s stop {:?}",
        frc.points.len(),
        frc.factorizations,
        frc.hill_calls,
        dt,
        frc.stop
    );
}
