//! `ivt rig commission --sim`: the recording and its JSON summary, and clean
//! errors (exit 2, one `{"error", "kind"}` object, no file) for a bad plant
//! file and contradictory options.
// A test may unwrap (the package's panic lints guard library code).
#![allow(clippy::unwrap_used)]

#[path = "common/rig.rs"]
mod rig;
use rig::{commission_sim, ivt};

#[test]
fn sim_commissioning_writes_the_recording_and_refuses_bad_input() {
    let dir = ivt_sim::testing::scratch_dir("rig-commission");
    let out = dir.join("hold.mcap");
    let o = out.to_str().unwrap();
    let (code, v) = ivt(&[
        "rig",
        "commission",
        "--sim",
        "--sequence",
        "hold",
        "--out",
        o,
    ]);
    assert_eq!(code, 0, "{v}");
    assert_eq!(v["mode"], "sil");
    assert_eq!(v["stages"], 1);
    assert_eq!(v["channels"]["/sequence"], 1);
    // The 10 s hold logs every edge: ≥ 15 000 at ≥ 10 rad/s, ≤ 60 per batch.
    let pulses = v["channels"]["/pulses"].as_u64().unwrap();
    assert!(pulses * 60 >= 15_000, "{v}");
    assert!(out.is_file());

    let plant = dir.join("bad.toml");
    std::fs::write(&plant, "[plant]\nk_t = -1.0\n").unwrap();
    let bad = dir.join("bad.mcap");
    let (code, v) = commission_sim(&plant, &bad, &[]);
    assert_eq!((code, v["kind"].as_str()), (2, Some("input")), "{v}");
    assert!(v["error"].as_str().unwrap().contains("bad.toml"), "{v}");
    assert!(!bad.exists());

    // --pil needs --sim; --port excludes --sim.
    let (code, _) = ivt(&["rig", "commission", "--pil", "--out", bad.to_str().unwrap()]);
    assert_eq!(code, 2);
    let (code, _) = ivt(&[
        "rig",
        "commission",
        "--sim",
        "--port",
        "/dev/null",
        "--out",
        o,
    ]);
    assert_eq!(code, 2);
    let _ = std::fs::remove_dir_all(&dir);
}
