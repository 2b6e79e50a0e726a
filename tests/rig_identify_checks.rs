//! Identification that knows what it cannot know (issue #43): every plant
//! preset of the toolkit commissioned (`ivt rig commission --sim
//! --plant-file`) and identified (`ivt rig identify`) either inside its 95 %
//! intervals or refused with the reason; stuck sensors and an L_a that the
//! model leaves out refused instead of fitted; every metadata value bounded
//! by its range.
// A test may index and unwrap (the package's panic lints guard library code).
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_kin::plant::{PlantParams, PlantPreset};
use ivt_sim::scene::PlantSection;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[path = "common/cores.rs"]
mod cores;
#[path = "common/rig.rs"]
mod rig;
use cores::on_every_core;
use rig::{commission_sim, ivt};

fn scratch(name: &str) -> ivt_sim::testing::Scratch {
    ivt_sim::testing::scratch_dir(&format!("id-checks-{name}"))
}

/// `ivt rig commission --sim` with realistic sensors (seed 1) on the plant
/// whose `[plant]` body is `body`: the recording's path and the true parameters.
fn commission(dir: &Path, body: &str) -> (PathBuf, PlantParams) {
    commission_with(dir, body, "realistic", 1)
}

/// [`commission`] with the sensor model `sensors` and the noise seed `seed`.
fn commission_with(dir: &Path, body: &str, sensors: &str, seed: u64) -> (PathBuf, PlantParams) {
    let plant = dir.join("rig_plant.toml");
    let text = format!("[plant]\n{body}\n");
    std::fs::write(&plant, &text).unwrap();
    let out = dir.join("run.mcap");
    let seed = seed.to_string();
    let (code, v) = commission_sim(&plant, &out, &["--sensors", sensors, "--seed", &seed]);
    assert_eq!(code, 0, "{v}");
    let truth = PlantSection::parse_file(&text, "rig_plant.toml")
        .unwrap()
        .params()
        .unwrap();
    (out, truth)
}

/// `ivt rig identify REC --out DIR/plant.toml`, timed: (status, JSON, seconds).
fn identify(rec: &Path) -> (i32, Value, f64) {
    let out = rec.with_file_name("plant.toml");
    let t0 = Instant::now();
    let (code, v) = ivt(&[
        "rig",
        "identify",
        rec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    (code, v, t0.elapsed().as_secs_f64())
}

/// The coefficients that fix the identified plant, with their true values.
fn required(p: &PlantParams) -> [(&'static str, f64); 5] {
    [
        ("j_a", p.j_a()),
        ("j_d", p.j_d()),
        ("motor_damping", p.motor_damping()),
        ("motor_gain", p.motor_gain()),
        ("load_gain", p.load_gain()),
    ]
}

/// Every coefficient of Eq. 151 with its true value (J_b and J_c too: an
/// interval that includes 0 says "not determined", it must still hold the truth).
fn coefficients(p: &PlantParams) -> [(&'static str, f64); 7] {
    let [a, d, damping, gain, load] = required(p);
    [
        a,
        ("j_b", p.j_b()),
        ("j_c", p.j_c()),
        d,
        damping,
        gain,
        load,
    ]
}

/// The coefficients whose reported 95 % interval misses the truth (each
/// printed with its interval).
fn misses(name: &str, v: &Value, p: &PlantParams) -> Vec<&'static str> {
    let mut out = Vec::new();
    for (key, want) in coefficients(p) {
        let ci = &v["ci95"][key];
        let (lo, hi) = (ci[0].as_f64().unwrap(), ci[1].as_f64().unwrap());
        let inside = lo <= want && want <= hi;
        eprintln!("{name} {key}: {want:.5e} in [{lo:.5e}, {hi:.5e}]: {inside}");
        if !inside {
            out.push(key);
        }
    }
    out
}

/// Noise seeds of the realistic sensors per plant.
const SEEDS: u64 = 10;

/// A 95 % interval misses the truth in 5 % of the runs: of [`SEEDS`]
/// independent runs, 3 or more misses of one coefficient happen with
/// probability 1.2 % (binomial), so more than this many is a lie.
const MISSES_ALLOWED: usize = 2;

/// Every preset and a plant with L_a = 1 mH, each commissioned with ideal
/// sensors and with realistic ones under [`SEEDS`] noise seeds: identified,
/// or refused as `unidentifiable` naming the coefficient. Identified, the
/// ideal run has the truth of all seven coefficients inside their 95 %
/// intervals, and of the realistic runs at most [`MISSES_ALLOWED`] miss it
/// for any one coefficient (measured: `printed` none, L_a = 1 mH one run,
/// seed 2, whose scale — J_a, the motor's two, the load gain together — is
/// 1.1 half-widths off). Pinned: `printed` and L_a = 1 mH (Eq. 137 with the
/// nominal L_a) are identified, the model string stating the L_a used;
/// `thesis-ch4` is refused: under the default plan its motor runs at up to
/// 960 rpm, where the gravity work that fixes the scale of Eq. 151 (2.1e-2 J
/// RMS per window) is not above the equation's residual (2.1e-2 J with ideal
/// sensors: the timer's 1 µs tick on edges ~50 µs apart), and J_a's interval
/// includes 0.
///
/// Before the θ-integrals of f and f² were exact (a midpoint rule over each
/// pulse interval), `printed` with ideal sensors gave J_d = 0.002364 with
/// the interval [0.002353, 0.002375] against the true 0.002347.
#[test]
fn every_preset_is_identified_inside_its_intervals_or_refused_with_the_reason() {
    let mut cases: Vec<(String, String)> = PlantPreset::ALL
        .iter()
        .map(|p| (p.name().to_string(), format!("preset = \"{}\"", p.name())))
        .collect();
    cases.push(("l_a = 1 mH".into(), "l_a = 1e-3".into()));
    let runs: Vec<(&str, u64)> = std::iter::once(("ideal", 1))
        .chain((1..=SEEDS).map(|s| ("realistic", s)))
        .collect();
    // Every run of every case commissioned and identified on all cores (each
    // run is two single-threaded `ivt` processes), then checked in order.
    let jobs: Vec<(&str, &str, &str, u64)> = cases
        .iter()
        .flat_map(|(case, body)| {
            runs.iter()
                .map(move |&(s, seed)| (case.as_str(), body.as_str(), s, seed))
        })
        .collect();
    let results = on_every_core(&jobs, |&(case, body, sensors, seed)| {
        let dir = scratch(&format!("{}-{sensors}-{seed}", case.replace(' ', "_")));
        let (rec, truth) = commission_with(&dir, body, sensors, seed);
        let (code, v, secs) = identify(&rec);
        (truth, code, v, secs)
    });
    for ((case, _), outcomes) in cases.iter().zip(results.chunks(runs.len())) {
        let mut missed: BTreeMap<&str, Vec<u64>> = BTreeMap::new();
        for (&(sensors, seed), (truth, code, v, secs)) in runs.iter().zip(outcomes) {
            let code = *code;
            let name = format!("{case} ({sensors} sensors, seed {seed})");
            eprintln!("{name}: exit {code} in {secs:.1} s");
            match code {
                0 => {
                    let out = misses(&name, v, truth);
                    if sensors == "ideal" {
                        assert!(out.is_empty(), "{name}: the truth outside {out:?}");
                    }
                    for key in out {
                        missed.entry(key).or_default().push(seed);
                    }
                }
                _ => {
                    assert_eq!(code, 2, "{name}: {v}");
                    assert_eq!(v["kind"], "unidentifiable", "{name}: {v}");
                    let e = v["error"].as_str().unwrap();
                    assert!(
                        e.contains("is not identifiable") || e.contains("not consistent"),
                        "{e}"
                    );
                }
            }
            match case.as_str() {
                "printed" => {
                    assert_eq!(code, 0, "{v}");
                    assert!(v["model"].as_str().unwrap().contains("L_a = 0"), "{v}");
                }
                "l_a = 1 mH" => {
                    assert_eq!(code, 0, "{v}");
                    assert!(v["model"]
                        .as_str()
                        .unwrap()
                        .starts_with("Eq. 137 with L_a = 0.001 H"));
                    assert_eq!(v["l_a"], 1e-3);
                }
                "thesis-ch4" => {
                    assert_eq!(code, 2, "{v}");
                    let e = v["error"].as_str().unwrap();
                    assert!(
                        e.contains("j_a is not identifiable") && e.contains("includes 0"),
                        "{e}"
                    );
                }
                _ => {}
            }
        }
        eprintln!("{case}: seeds whose interval misses the truth {missed:?}");
        for (key, seeds) in &missed {
            assert!(
                seeds.len() <= MISSES_ALLOWED,
                "{case} {key}: the truth outside the 95 % interval in {} of {SEEDS} runs (seeds {seeds:?})",
                seeds.len()
            );
        }
    }
}

/// A copy of the MCAP recording `src` with every `/sensors` message and the
/// metadata record changed by `sensors` and `meta`.
fn rewrite(
    src: &[u8],
    sensors: impl Fn(&mut Value),
    meta: impl Fn(&mut BTreeMap<String, String>),
) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    {
        let mut w = mcap::Writer::new(&mut out).unwrap();
        for m in mcap::MessageStream::new(src).unwrap() {
            let mut m = m.unwrap();
            if m.channel.topic == "/sensors" {
                let mut v: Value = serde_json::from_slice(&m.data).unwrap();
                sensors(&mut v);
                m.data = serde_json::to_vec(&v).unwrap().into();
            }
            w.write(&m).unwrap();
        }
        for r in mcap::read::LinearReader::new(src).unwrap() {
            if let mcap::records::Record::Metadata(mut md) = r.unwrap() {
                meta(&mut md.metadata);
                w.write_metadata(&md).unwrap();
            }
        }
        w.finish().unwrap();
    }
    out.into_inner()
}

/// The case: V_m and T_U stuck at their first readings while the
/// sequences run. Before: exit 0 with k_t = 0.113 against 0.76 and
/// intervals excluding the truth. Now: refused, the residual 87× the noise
/// the two halves imply (the limit is 3×; clean runs measure 0.86–1.10), both
/// sensors named.
#[test]
fn stuck_sensors_are_refused_and_named() {
    let dir = scratch("stuck");
    let (rec, _) = commission(&dir, "preset = \"printed\"");
    let (code, clean, _) = identify(&rec);
    assert_eq!(code, 0, "{clean}");
    let ratio = clean["residual_rms"].as_f64().unwrap() / clean["noise_rms"].as_f64().unwrap();
    assert!(
        (0.8..1.5).contains(&ratio),
        "clean run: residual/noise = {ratio}"
    );
    // Its only possible warnings: J_b or J_c not determined (seed 1's J_c
    // interval is [−0.005, 1.63], truth 0.339), never a stuck sensor or a
    // residual beyond the noise.
    for w in clean["warnings"].as_array().unwrap() {
        let w = w.as_str().unwrap();
        assert!(
            (w.starts_with("j_b = ") || w.starts_with("j_c = ")) && w.contains("not determined"),
            "{w}"
        );
    }

    let data = std::fs::read(&rec).unwrap();
    let first = mcap::MessageStream::new(&data)
        .unwrap()
        .map(|m| m.unwrap())
        .find(|m| m.channel.topic == "/sensors")
        .map(|m| serde_json::from_slice::<Value>(&m.data).unwrap())
        .unwrap();
    let stuck = rewrite(
        &data,
        |v| {
            v["v_m"] = first["v_m"].clone();
            v["t_u"] = first["t_u"].clone();
        },
        |_| {},
    );
    let bad = dir.join("stuck.mcap");
    std::fs::write(&bad, stuck).unwrap();
    let (code, v, _) = identify(&bad);
    assert_eq!(code, 2, "{v}");
    assert_eq!(v["kind"], "unidentifiable");
    let e = v["error"].as_str().unwrap();
    eprintln!("{e}");
    assert!(e.contains("not consistent with Eq. 151"), "{e}");
    assert!(e.contains("V_m reads ") && e.contains("T_U reads "), "{e}");
    assert!(e.contains("a stuck sensor?"), "{e}");
}

/// The L_a assumption matters: the L_a = 1 mH rig's recording with its
/// metadata claiming L_a = 0 (the model Eq. 151 without the lag) is refused,
/// J_d's whole interval below 0 (−0.008 kg·m²) and L_a named as the likely
/// cause, instead of being identified; with the metadata's L_a it is
/// identified (above).
#[test]
fn a_rig_with_inductance_identified_as_l_a_0_is_refused_naming_j_d() {
    let dir = scratch("la0");
    let (rec, _) = commission(&dir, "l_a = 1e-3");
    let data = std::fs::read(&rec).unwrap();
    let zeroed = rewrite(
        &data,
        |_| {},
        |m| {
            let mut plant: Value = serde_json::from_str(&m["plant"]).unwrap();
            assert_eq!(plant["l_a"], 1e-3);
            plant["l_a"] = 0.0.into();
            m.insert("plant".into(), plant.to_string());
        },
    );
    let bad = dir.join("l_a_0.mcap");
    std::fs::write(&bad, zeroed).unwrap();
    let (code, v, _) = identify(&bad);
    assert_eq!(code, 2, "{v}");
    assert_eq!(v["kind"], "unidentifiable");
    let e = v["error"].as_str().unwrap();
    assert!(
        e.contains("j_d is not identifiable") && e.contains("lies below 0"),
        "{e}"
    );
    assert!(e.contains("L_a"), "{e}");
}

/// Every numeric metadata value outside its range is refused by name
/// (`input`), within seconds: `theta0 = "1e20"` made `rig identify` loop
/// without end (an index saturated and wrapped).
#[test]
fn metadata_values_outside_their_range_are_refused_by_name() {
    let dir = scratch("meta");
    let (rec, _) = commission(&dir, "preset = \"printed\"");
    let data = std::fs::read(&rec).unwrap();
    let cases = [
        ("theta0", "1e20"),
        ("theta0", "-1e20"),
        ("theta0", "NaN"),
        ("theta0", "7"),
        ("f_timer_hz", "1e300"),
        ("f_timer_hz", "0"),
        ("steps_per_rev", "1e300"),
        ("steps_per_rev", "-3200"),
        ("frame_version", "1e30"),
        ("ppr", "1e7"),
        ("ppr", "0"),
    ];
    for (key, value) in cases {
        let changed = rewrite(
            &data,
            |_| {},
            |m| {
                m.insert(key.into(), value.into());
            },
        );
        let bad = dir.join("meta.mcap");
        std::fs::write(&bad, changed).unwrap();
        let (code, v, secs) = identify(&bad);
        eprintln!("{key} = {value}: {v} ({secs:.2} s)");
        assert!(secs < 20.0, "{key} = {value}: {secs} s");
        assert_eq!(code, 2, "{key} = {value}: {v}");
        assert_eq!(v["kind"], "input", "{key} = {value}: {v}");
        let e = v["error"].as_str().unwrap();
        assert!(e.contains(&format!("metadata `{key}` = {value}")), "{e}");
    }
    // θ0 one turn lower (inside the range) is the same encoder zero: the
    // same estimates (f has period π/2, gravity's sin θ + cos θ 2π)
    let (code, clean, _) = identify(&rec);
    assert_eq!(code, 0, "{clean}");
    let theta0 = std::f64::consts::TAU / 1200.0 - std::f64::consts::TAU;
    let turned = rewrite(
        &data,
        |_| {},
        |m| {
            m.insert("theta0".into(), theta0.to_string());
        },
    );
    let other = dir.join("turned.mcap");
    std::fs::write(&other, turned).unwrap();
    let (code, v, _) = identify(&other);
    assert_eq!(code, 0, "{v}");
    // (window ends on a pulse may round to the next one: a fraction of the
    // interval, measured 0.03 of its half-width for J_a)
    for (key, _) in required(&PlantParams::printed()) {
        let (a, b) = (
            v["summary"][key].as_f64().unwrap(),
            clean["summary"][key].as_f64().unwrap(),
        );
        let ci = &clean["ci95"][key];
        let half = 0.5 * (ci[1].as_f64().unwrap() - ci[0].as_f64().unwrap());
        assert!((a - b).abs() < 0.25 * half, "{key}: {a} vs {b} (±{half})");
    }
}
