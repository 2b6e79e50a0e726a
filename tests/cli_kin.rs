//! `ivt kin ... --json` prints exactly one JSON object with the documented keys
//! (SPEC §6 style); out-of-domain arguments exit with status 2 and `{"error"}`.
// A test may expect and unwrap (the package's panic lints guard library code).
#![allow(clippy::expect_used, clippy::unwrap_used)]

use serde_json::Value;
use std::process::Command;

fn ivt(args: &[&str]) -> (i32, Value) {
    let out = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .args(args)
        .arg("--json")
        .output()
        .expect("run ivt");
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.trim().lines().count(), 1, "one JSON line: {text}");
    (
        out.status.code().unwrap(),
        serde_json::from_str(&text).unwrap(),
    )
}

/// §4.4.2: at θ_CT = 3600°, e = 7π/51840·3600 in and R_avg = (2√2/π) e/r_OG.
#[test]
fn sgivt_ratio_json() {
    let (code, v) = ivt(&["kin", "sgivt-ratio", "--theta-ct", "3600"]);
    assert_eq!(code, 0);
    let e_inch = 7.0 * std::f64::consts::PI / 51840.0 * 3600.0;
    assert!((v["e_inch"].as_f64().unwrap() - e_inch).abs() < 1e-12);
    let r_avg = 2.0 * 2f64.sqrt() / std::f64::consts::PI * e_inch / 1.5;
    assert!((v["r_avg"].as_f64().unwrap() - r_avg).abs() < 1e-12);
    assert!((v["r_avg_printed"].as_f64().unwrap() - 7.0 * 3600.0 / 27492.0).abs() < 1e-12);
}

#[test]
fn fourier_and_direction_json() {
    let (_, v) = ivt(&["kin", "fourier-fit"]);
    let c = v["coefficients"].as_array().unwrap();
    assert!((c[1]["exact"].as_f64().unwrap() - 2.0 / 15.0).abs() < 1e-15);
    assert_eq!(c[1]["printed"].as_f64().unwrap(), 0.12);
    let (_, v) = ivt(&["kin", "direction"]);
    assert!((v["forward_ratio"].as_f64().unwrap() + 0.75).abs() < 1e-15);
    assert!((v["reverse_ratio"].as_f64().unwrap() - 0.5625).abs() < 1e-15);
}

#[test]
fn profile_and_arcs_json() {
    let (_, v) = ivt(&["kin", "pitch-profile", "--design", "sgivt", "--points", "5"]);
    assert_eq!(v["points"].as_array().unwrap().len(), 5);
    assert!(v["closure_error"].as_f64().unwrap().abs() < 1e-12);
    let (_, v) = ivt(&["kin", "arcs", "--design", "sgivt"]);
    for key in ["driven", "driving"] {
        assert!(v[key]["max_deviation"].as_f64().unwrap() <= 0.01);
        let n = v[key]["count"].as_u64().unwrap() as usize;
        assert_eq!(v[key]["arcs"].as_array().unwrap().len(), n);
    }
    let (_, v) = ivt(&["kin", "givt-ratio", "--r-mm", "10"]);
    assert!(v["average_final_ratio"].as_f64().unwrap() > 0.0);
}

#[test]
fn out_of_domain_exits_2_with_error_object() {
    let (code, v) = ivt(&["kin", "givt-ratio", "--r-mm", "60"]);
    assert_eq!(code, 2);
    assert!(v["error"].as_str().unwrap().contains("out of domain"));
    let (code, _) = ivt(&["kin", "sgivt-ratio", "--theta-ct", "4000"]);
    assert_eq!(code, 2);
    let (code, _) = ivt(&["kin", "pitch-profile", "--points", "1"]);
    assert_eq!(code, 2);
}
