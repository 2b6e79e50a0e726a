//! `ivt hb ...` honours the SPEC §6 JSON contract.

use std::process::Command;

fn run(args: &[&str]) -> (i32, serde_json::Value) {
    let out = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .args(args)
        .output()
        .expect("binary runs");
    let text = String::from_utf8(out.stdout).expect("utf-8");
    let value = serde_json::from_str(text.trim())
        .unwrap_or_else(|e| panic!("one JSON object, got {text:?}: {e}"));
    (out.status.code().unwrap_or(-1), value)
}

#[test]
fn duffing_json_keys() {
    let (code, v) = run(&["--json", "hb", "duffing"]);
    assert_eq!(code, 0);
    for key in [
        "coeffs",
        "iterations",
        "residual_norm",
        "solve_time_s",
        "floquet",
        "stable",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    assert_eq!(v["coeffs"].as_array().unwrap().len(), 41); // a0, a1..a20, b1..b20
    assert!(v["residual_norm"].as_f64().unwrap() <= 1e-10);
    assert_eq!(v["stable"], true);
    let (code, v) = run(&["--json", "hb", "duffing", "--method", "classic"]);
    assert_eq!(code, 0, "{v}");
}

#[test]
fn bad_input_is_a_json_error() {
    let (code, v) = run(&["--json", "hb", "duffing", "--samples", "10"]);
    assert_eq!(code, 2);
    assert!(v["error"].as_str().unwrap().contains("N > n"));
}

#[test]
fn frc_and_mathieu_json_keys() {
    let (code, v) = run(&[
        "--json",
        "hb",
        "duffing-frc",
        "--from",
        "0.2",
        "--to",
        "3.0",
    ]);
    assert_eq!(code, 0);
    let p = &v["points"][0];
    assert!(p.get("omega").is_some() && p.get("amplitude").is_some() && p.get("stable").is_some());
    let (code, v) = run(&["--json", "hb", "mathieu-duffing"]);
    assert_eq!(code, 0);
    let betas = v["period_doubling_beta"].as_array().unwrap();
    assert_eq!(betas.len(), 3);
    for (b, want) in betas.iter().zip([4.825, 5.194, 5.253]) {
        assert!((b.as_f64().unwrap() - want).abs() <= 0.005);
    }
}
