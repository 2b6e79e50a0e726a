//! The rig loop (issue #29): a simulated rig commissioned, its recording
//! identified by `ivt rig identify`, the plant file used by the design tools.

mod rig_sim;

use ivt_kin::plant::PlantParams;
use ivt_sim::scene::{PlantSection, PresetName};
use ivt_sim::sensors::Rng;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("ivt-rig-identify-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `ivt --json ARGS` → (exit status, JSON).
fn ivt(args: &[&str]) -> (i32, Value) {
    let out = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .arg("--json")
        .args(args)
        .output()
        .unwrap();
    let v = serde_json::from_slice(&out.stdout).unwrap_or(Value::Null);
    (out.status.code().unwrap_or(-1), v)
}

/// Table 1 with k_t, k_e, R_a, the inertias and the brake gain (through
/// r_u) each scaled by a factor in [0.7, 1.3] drawn from `seed`: the values
/// are not written in the test.
fn perturbed(seed: u64) -> PlantParams {
    let mut rng = Rng::new(seed);
    let mut p = PlantParams::printed();
    for x in [
        &mut p.k_t,
        &mut p.k_e,
        &mut p.r_a,
        &mut p.j_n1,
        &mut p.j_n2,
        &mut p.j_carrier,
        &mut p.j_ring,
        &mut p.j_crk,
        &mut p.m_r,
        &mut p.m_dr,
        &mut p.j_u,
        &mut p.r_u,
    ] {
        *x *= 0.7 + 0.6 * rng.uniform();
    }
    p
}

/// The `[plant]` table body of `p` (overrides of the printed preset).
fn plant_body(p: &PlantParams) -> String {
    let text = PlantSection::from_params(PresetName::Printed, p).to_toml();
    text.lines().skip(1).collect::<Vec<_>>().join("\n")
}

fn identify(dir: &Path, mcap: &[u8]) -> Value {
    let rec = dir.join("run.mcap");
    std::fs::write(&rec, mcap).unwrap();
    let out = dir.join("plant.toml");
    let (code, v) = ivt(&[
        "rig",
        "identify",
        rec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{v}");
    v
}

fn truth(p: &PlantParams) -> [(&'static str, f64); 4] {
    [
        ("motor_gain", p.motor_gain()),
        ("motor_damping", p.motor_damping()),
        ("j_a", p.j_a()),
        ("load_gain", p.load_gain()),
    ]
}

/// Ideal sensors: the four coefficients within 2 %.
#[test]
fn perturbed_plant_identified_within_2_percent_with_ideal_sensors() {
    let p = perturbed(29);
    let dir = scratch("ideal");
    let v = identify(
        &dir,
        &rig_sim::commission(&plant_body(&p), rig_sim::Sensors::IDEAL, 1),
    );
    for (name, want) in truth(&p) {
        let got = v["summary"][name].as_f64().unwrap();
        let ci = &v["ci95"][name];
        eprintln!(
            "{name}: {got} vs {want} ({:+.3} %), ci {ci}",
            100.0 * (got / want - 1.0)
        );
    }
    eprintln!("{}", v["summary"]);
    for (name, want) in truth(&p) {
        let got = v["summary"][name].as_f64().unwrap();
        assert!((got / want - 1.0).abs() < 0.02, "{name}: {got} vs {want}");
    }
}

/// Noise, quantization and jitter on: the truth inside each reported 95 % interval.
#[test]
fn perturbed_plant_inside_the_95_percent_intervals_with_noisy_sensors() {
    let p = perturbed(29);
    let dir = scratch("noisy");
    let v = identify(
        &dir,
        &rig_sim::commission(&plant_body(&p), rig_sim::Sensors::NOISY, 2),
    );
    for (name, want) in truth(&p) {
        let got = v["summary"][name].as_f64().unwrap();
        let ci = &v["ci95"][name];
        eprintln!(
            "{name}: {got} vs {want} ({:+.3} %), ci {ci}",
            100.0 * (got / want - 1.0)
        );
    }
    for (name, want) in truth(&p) {
        let ci = &v["ci95"][name];
        let (lo, hi) = (ci[0].as_f64().unwrap(), ci[1].as_f64().unwrap());
        assert!(
            lo <= want && want <= hi,
            "{name}: {want} outside [{lo}, {hi}]"
        );
    }
}

#[test]
#[ignore]
fn tmp_seed_coverage() {
    for seed in [3u64, 5, 7, 11, 13, 17] {
        let p = perturbed(seed);
        let dir = scratch(&format!("cov{seed}"));
        let v = identify(&dir, &rig_sim::commission(&plant_body(&p), rig_sim::Sensors::NOISY, seed));
        for (name, want) in truth(&p) {
            let got = v["summary"][name].as_f64().unwrap();
            let ci = &v["ci95"][name];
            let (lo, hi) = (ci[0].as_f64().unwrap(), ci[1].as_f64().unwrap());
            eprintln!("seed {seed} {name}: {:+.3} % half {:.3} % in={}", 100.0 * (got / want - 1.0), 50.0*(hi-lo)/want, lo <= want && want <= hi);
        }
    }
}
