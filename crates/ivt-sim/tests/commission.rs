//! Commissioning sequences against the simulated rig: the SIL recording
//! follows the plan (stage starts on the nominal schedule, held r = Eq. 185
//! of the held angle, every edge of the hold logged, the proportional law
//! Eq. 189 bringing ω_a back to ω_r as Eq. 190 says it converges), and the
//! PIL recording (QEMU firmware driving the sequence) equals it byte for byte.
// A test may unwrap (the package's panic lints guard library code).
#![allow(clippy::unwrap_used)]

use std::collections::BTreeMap;
use std::path::Path;

use ivt_ctrl::commission::{Plan, Selection, SequenceName};
use ivt_sim::commission::{run_sil, CommissionOptions, SensorModel};
use ivt_sim::scene::PlantSection;
use serde_json::Value;

/// Eq. 185 in SI, from the thesis's constants (not the crate's): metres of
/// eccentricity per degree of stepper angle.
const M_PER_DEG: f64 = 7.0 * std::f64::consts::PI / 51840.0 * 0.0254;

/// A scratch directory for one test, removed when the test ends.
fn tmp(name: &str) -> ivt_sim::testing::Scratch {
    ivt_sim::testing::scratch_dir(&format!("commission-{name}"))
}

/// Messages per topic and the `ivt` metadata of a recording.
fn read(path: &Path) -> (BTreeMap<String, Vec<Value>>, BTreeMap<String, String>) {
    let data = std::fs::read(path).unwrap();
    let mut by_topic: BTreeMap<String, Vec<Value>> = BTreeMap::new();
    for m in mcap::MessageStream::new(&data).unwrap() {
        let m = m.unwrap();
        by_topic
            .entry(m.channel.topic.clone())
            .or_default()
            .push(serde_json::from_slice(&m.data).unwrap());
    }
    let summary = mcap::Summary::read(&data).unwrap().unwrap();
    let idx = summary
        .metadata_indexes
        .iter()
        .find(|i| i.name == "ivt")
        .unwrap();
    let meta = mcap::read::metadata(&data, idx).unwrap().metadata;
    (by_topic, meta)
}

fn f(v: &Value, k: &str) -> f64 {
    v[k].as_f64().unwrap_or(f64::NAN)
}

#[test]
fn sil_recording_follows_the_plan() {
    let dir = tmp("sil");
    let out = dir.join("sil.mcap");
    let s = run_sil(&CommissionOptions::default(), &out).unwrap();
    let (ch, meta) = read(&out);
    assert_eq!(meta["ppr"], "1200");
    assert_eq!(meta["frame_version"], "2");
    assert_eq!(meta["steps_per_rev"].parse::<f64>().unwrap(), 3200.0);
    let plant: Value = serde_json::from_str(&meta["plant"]).unwrap();
    assert_eq!(plant["r_max"], 0.012);

    // 12 sweep angles (0…1100°: r_max = 12 mm is 1113.7°), the hold, 6 holds
    // and 2 law stages of the step test, 6 drive stages.
    let seq = &ch["/sequence"];
    let names: Vec<&str> = seq.iter().map(|m| m["name"].as_str().unwrap()).collect();
    let mut want = vec!["sweep"; 12];
    want.extend(["hold"]);
    want.extend(["step"; 8]);
    want.extend(["drive"; 6]);
    assert_eq!(names, want);
    assert_eq!(s.stages, 27);

    // Stage k starts at the first pulse at or after t0 + Σ durations: within
    // one pulse interval (< 0.6 ms at ≥ 10 rad/s, PPR 1200) of it.
    let ctl = &ch["/control"];
    let t0 = f(&ctl[0], "t");
    let plan = Plan::default();
    let mut nominal = t0;
    for (k, m) in seq.iter().enumerate() {
        let late = f(m, "t") - nominal;
        assert!((0.0..6e-4).contains(&late), "stage {k}: {late} s late");
        let st = plan.stage(Selection::ALL, k as u32, 0.012).unwrap();
        nominal += f64::from(st.duration_s);
    }

    // During every held stage the commanded r is Eq. 185 of the held angle
    // (to 4 f32 ulps: the controller's f32 product), and the law does not move it.
    let bounds: Vec<(f64, f64, &Value)> = seq
        .iter()
        .enumerate()
        .map(|(k, m)| {
            // The last stage ends on schedule (then the sequencer is done
            // and the law runs on).
            let last = f(m, "t")
                + f64::from(
                    plan.stage(Selection::ALL, k as u32, 0.012)
                        .unwrap()
                        .duration_s,
                );
            let end = seq.get(k + 1).map_or(last, |n| f(n, "t"));
            (f(m, "t"), end, m)
        })
        .collect();
    let mut held = 0;
    for (a, b, m) in &bounds {
        if m["hold"] != true {
            continue;
        }
        let r_want = f(m, "theta_ct_deg") * M_PER_DEG;
        for c in ctl.iter().filter(|c| (*a..*b).contains(&f(c, "t"))) {
            assert!(
                (f(c, "r") - r_want).abs() <= 4.0 * f64::from(f32::EPSILON) * r_want,
                "{m}: r = {} vs Eq. 185 {r_want}",
                f(c, "r")
            );
            held += 1;
        }
    }
    assert!(held > 100_000, "{held}");

    // The hold logs every edge: as many edge times as pulses in the stage,
    // the same ticks as /control, in batches of at most 60. So do the holds
    // of the sweep and the step test (what identification fits), and no
    // other stage.
    let logged: Vec<(f64, u64)> = ch["/pulses"]
        .iter()
        .flat_map(|m| {
            assert!(m["ticks"].as_array().unwrap().len() <= 60);
            let t = m["t"].as_array().unwrap().clone();
            let k = m["ticks"].as_array().unwrap().clone();
            assert_eq!(t.len(), k.len());
            t.into_iter().zip(k)
        })
        .map(|(t, k)| (t.as_f64().unwrap(), k.as_u64().unwrap()))
        .collect();
    let edges_in = |a: f64, b: f64| -> (Vec<u64>, Vec<u64>) {
        let want = ctl
            .iter()
            .filter(|c| (a..b).contains(&f(c, "t")))
            .map(|c| c["ticks"].as_u64().unwrap())
            .collect();
        let got = logged
            .iter()
            .filter(|(t, _)| (a..b).contains(t))
            .map(|&(_, k)| k)
            .collect();
        (got, want)
    };
    let (a, b, _) = bounds.iter().find(|(_, _, m)| m["name"] == "hold").unwrap();
    let (in_hold, want) = edges_in(*a, *b);
    assert_eq!(in_hold, want);
    assert!(
        in_hold.len() > 15_000,
        "10 s at ~10 rad/s: {}",
        in_hold.len()
    );
    let mut logged_in_stages = 0;
    for (a, b, m) in &bounds {
        let (got, want) = edges_in(*a, *b);
        if m["hold"] == true && m["name"] != "drive" {
            assert_eq!(got, want, "{m}");
            assert!(!got.is_empty(), "{m}");
        } else {
            assert!(got.is_empty(), "{m}: {} edges logged", got.len());
        }
        logged_in_stages += got.len();
    }
    assert_eq!(logged_in_stages, logged.len());

    // The law stages (step test 6, 7; drive 1–4) end with ω_a within
    // 0.5 rpm of ω_r = 100 rpm: Eq. 190's recursion converges for
    // |1 − K₂T_out K| < 1.
    let omega_r = 100.0 * std::f64::consts::PI / 30.0;
    for (a, b, m) in bounds.iter().filter(|(_, _, m)| m["hold"] == false) {
        let last = ctl.iter().rfind(|c| (*a..*b).contains(&f(c, "t"))).unwrap();
        let err_rpm = (f(last, "omega_a") - omega_r) * 30.0 / std::f64::consts::PI;
        assert!(err_rpm.abs() < 0.5, "{m}: ω_a off by {err_rpm} rpm");
    }
    let _ = std::fs::remove_file(&out);
}

/// A short plan for the slower runs: the hold (pulse log) and a step test of
/// two angles with its law stages, 3.3 s in all.
fn short_plan() -> (Plan, Selection) {
    // The step test at the default set-points, on two angles.
    let mut plan = Plan::default();
    plan.step.range_deg = [300.0, 700.0];
    plan.step.points = 2;
    plan.step.hold_s = 0.6;
    plan.step.law_s = 0.8;
    plan.hold.hold_s = 0.5;
    plan.hold.theta_ct_deg = 600.0;
    let sel =
        Selection(Selection::only(SequenceName::Hold).0 | Selection::only(SequenceName::Step).0);
    (plan, sel)
}

#[test]
fn realistic_sensors_quantize_the_readings_and_keep_the_schedule() {
    let (plan, selection) = short_plan();
    let dir = tmp("noisy");
    let dir_plant = dir.join("perturbed.toml");
    std::fs::write(
        &dir_plant,
        "[plant]\npreset = \"printed\"\nk_t = 0.55\nj_u = 0.2\n",
    )
    .unwrap();
    let opts = CommissionOptions {
        plan,
        selection,
        plant: PlantSection::from_file(&dir_plant).unwrap(),
        sensors: SensorModel::Realistic,
        ..CommissionOptions::default()
    };
    let out = dir.join("noisy.mcap");
    run_sil(&opts, &out).unwrap();
    let (ch, meta) = read(&out);
    let plant: Value = serde_json::from_str(&meta["plant"]).unwrap();
    assert_eq!(
        (plant["k_t"].as_f64(), plant["j_u"].as_f64()),
        (Some(0.55), Some(0.2))
    );
    assert_eq!(ch["/sequence"].len(), 5);
    // Readings on the 5 mV / 10 mN·m quanta, scattered around the set-points.
    let sensors = &ch["/sensors"];
    let mut spread = 0.0f64;
    for m in sensors {
        let v = f(m, "v_m");
        assert!(((v / 0.005) - (v / 0.005).round()).abs() < 1e-6, "{v}");
        let t = f(m, "t_u");
        assert!(((t / 0.01) - (t / 0.01).round()).abs() < 1e-6, "{t}");
        spread = spread.max((v - 8.6).abs());
    }
    assert!(spread > 0.01 && spread < 0.1, "{spread}");

    // An unknown key in a plant file is refused with the file's name.
    std::fs::write(&dir_plant, "[plant]\nk_tt = 0.5\n").unwrap();
    let err = PlantSection::from_file(&dir_plant).unwrap_err().to_string();
    assert!(
        err.contains("perturbed.toml") && err.contains("k_tt"),
        "{err}"
    );
    let _ = std::fs::remove_file(&out);
}

#[test]
#[ignore = "needs qemu-system-arm and the firmware image; run by firmware/run-qemu.sh test"]
fn pil_commissioning_recording_equals_sil_byte_for_byte() {
    let (plan, selection) = short_plan();
    let opts = CommissionOptions {
        plan,
        selection,
        sensors: SensorModel::Realistic,
        ..CommissionOptions::default()
    };
    let dir = tmp("cmp");
    let (sil, pil) = (dir.join("cmp-sil.mcap"), dir.join("cmp-pil.mcap"));
    let s = run_sil(&opts, &sil).unwrap();
    let p = ivt_sim::pil::run_pil_commission(&opts, &pil).unwrap();
    assert_eq!(s.channels, p.channels);
    assert_eq!(s.stages, 5);
    assert!(s.channels["/pulses"] > 0 && s.channels["/control"] > 5_000);
    // Not vacuous: the law moved r in the law stages.
    let (ch, _) = read(&sil);
    let rs: Vec<f64> = ch["/control"].iter().map(|c| f(c, "r")).collect();
    let distinct = rs.windows(2).filter(|w| w[0] != w[1]).count();
    assert!(distinct > 10, "{distinct}");
    assert!(std::fs::read(&sil).unwrap() == std::fs::read(&pil).unwrap());
    let _ = std::fs::remove_file(&sil);
    let _ = std::fs::remove_file(&pil);
}
