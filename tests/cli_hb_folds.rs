//! `ivt hb duffing-folds`: the fold curve of the thesis Duffing in (ω, F)
//! through the cusp. References by shooting in crates/ivt-hb/tests/fold_curve.rs:
//! folds at F = 0.2 and 0.3 at ω = 1.2589591460 and 1.3297591465, the cusp at
//! F = 0.0120510724.

use std::process::Command;

fn run(args: &str) -> (i32, serde_json::Value) {
    let out = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .args(args.split_whitespace())
        .output()
        .expect("binary runs");
    let text = String::from_utf8(out.stdout).expect("utf-8");
    let value = serde_json::from_str(text.trim())
        .unwrap_or_else(|e| panic!("one JSON object, got {text:?}: {e}"));
    (out.status.code().unwrap_or(-1), value)
}

#[test]
fn duffing_folds_reach_the_cusp() {
    let (code, v) = run("--json hb duffing-folds --n 15 --at 0.2,0.3");
    assert_eq!(code, 0, "{v}");
    assert_eq!(v["kind"], "fold");
    assert_eq!(v["termination"], "left_interval");
    let special = v["special"].as_array().unwrap();
    assert_eq!(special.len(), 1);
    assert_eq!(special[0]["kind"], "cusp");
    let f = special[0]["force"].as_f64().unwrap();
    assert!((f / 0.0120510724 - 1.0).abs() < 1e-6, "{f}");
    let at: Vec<(f64, f64)> = v["at"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| (a["force"].as_f64().unwrap(), a["omega"].as_f64().unwrap()))
        .collect();
    assert_eq!(at.len(), 2, "{at:?}");
    for ((force, omega), want) in at.iter().zip([1.2589591460, 1.3297591465]) {
        assert!(
            (omega - want).abs() < 1e-7,
            "F = {force}: {omega} vs {want}"
        );
    }
}

#[test]
fn a_curve_without_a_fold_is_a_json_error() {
    let (code, v) = run("--json hb duffing-folds --force 0.001");
    assert_eq!(code, 2);
    assert!(
        v["error"].as_str().unwrap().contains("no located fold"),
        "{v}"
    );
}
