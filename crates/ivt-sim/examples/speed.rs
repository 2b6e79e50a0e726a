//! Where the default scene's time goes, in CPU time per thread — steadier
//! than wall time on a shared machine (Linux: reads /proc).
//!
//! ```sh
//! cargo run --release -p ivt-sim --example speed [RUNS]
//! ```
//!
//! Modes: `loop` (no outputs), `record` (channels kept in memory), `serial`
//! (run, then MCAP + summary written by `write_all`), `stream` (`run_and_write`:
//! the MCAP writer thread works while the loop runs). For each: best wall time,
//! best CPU time of the loop's thread, and the mean CPU time of the whole process
//! per run (so the writer thread's share is `process − loop`).
// An example may expect (the package's panic lints guard library code).
#![allow(clippy::expect_used)]

use ivt_sim::run::Simulation;
use ivt_sim::scene::Scene;
use ivt_sim::testing::shipped_scene;
use std::path::Path;
use std::time::Instant;

/// CPU time of the calling thread \[ns\] (first field of schedstat).
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// CPU time of the whole process \[s\] (utime + stime, in clock ticks of 10 ms).
fn process_cpu_s() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // the fields after the command name in parentheses
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
    Some(ticks as f64 / 100.0)
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(15);
    let mut scene = shipped_scene("drive.toml");
    scene.outputs.plots.clear();
    let dir = std::env::temp_dir().join("ivt-sim-speed");
    println!("mode      best wall   best loop-thread CPU   process CPU per run");
    for mode in ["loop", "record", "serial", "stream"] {
        let (mut wall, mut cpu) = (f64::INFINITY, f64::INFINITY);
        let p0 = process_cpu_s();
        for _ in 0..runs {
            let c0 = thread_cpu_ns();
            let t0 = Instant::now();
            one(mode, &scene, &dir);
            wall = wall.min(t0.elapsed().as_secs_f64());
            if let (Some(a), Some(b)) = (c0, thread_cpu_ns()) {
                cpu = cpu.min((b - a) as f64 * 1e-9);
            }
        }
        let per_run = match (p0, process_cpu_s()) {
            (Some(a), Some(b)) => format!("{:.1} ms", (b - a) / runs as f64 * 1e3),
            _ => "n/a".into(),
        };
        println!(
            "{mode:<8} {:>8.1} ms   {:>17.1} ms   {per_run:>12}",
            wall * 1e3,
            cpu * 1e3
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn one(mode: &str, scene: &Scene, dir: &Path) {
    match mode {
        "loop" => {
            let mut s = scene.clone();
            s.outputs = Default::default();
            Simulation::new(&s).run().expect("runs");
        }
        "record" => {
            Simulation::new(scene).run().expect("runs");
        }
        "serial" => {
            let r = Simulation::new(scene).run().expect("runs");
            ivt_sim::output::write_all(dir, scene, &r).expect("writes");
        }
        _ => {
            ivt_sim::output::run_and_write(dir, scene, |sink| {
                Simulation::new(scene)
                    .sink(sink)
                    .answer_by_time_integration()
            })
            .expect("runs and writes");
        }
    }
}
