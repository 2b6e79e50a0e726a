//! What the rig-loop tests share: running `ivt --json` for its exit status
//! and JSON object, and `ivt rig commission --sim` on a plant file.
//! Included by `tests/rig_commission.rs` and `tests/rig_identify.rs`
//! (`#[path]`).
// A test may unwrap (the package's panic lints guard library code).
#![allow(clippy::unwrap_used)]

use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// `ivt --json ARGS` → (exit status, JSON; `Null` when stdout holds none).
pub fn ivt(args: &[&str]) -> (i32, Value) {
    let out = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .arg("--json")
        .args(args)
        .output()
        .unwrap();
    let v = serde_json::from_slice(&out.stdout).unwrap_or(Value::Null);
    (out.status.code().unwrap_or(-1), v)
}

/// `ivt --json rig commission --sim --plant-file PLANT --out OUT EXTRA…` →
/// (exit status, JSON).
pub fn commission_sim(plant: &Path, out: &Path, extra: &[&str]) -> (i32, Value) {
    let mut args = vec![
        "rig",
        "commission",
        "--sim",
        "--plant-file",
        plant.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    ivt(&args)
}
