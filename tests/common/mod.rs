//! What the integration tests of the `ivt` binary share: running it under
//! `--json` and reading its one JSON object.
// A test may expect (the package's panic lints guard library code).
#![allow(clippy::expect_used)]

use std::ffi::OsStr;
use std::process::Command;

/// `ivt --json ARGS`: requires exit status 0 and returns the one JSON object
/// printed on stdout (the CLI contract of SPEC §6).
pub fn ivt_json<S: AsRef<OsStr>>(args: &[S]) -> serde_json::Value {
    let out = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .arg("--json")
        .args(args)
        .output()
        .expect("run ivt");
    let shown: Vec<_> = args.iter().map(|a| a.as_ref().to_string_lossy()).collect();
    assert!(
        out.status.success(),
        "ivt {shown:?}: {}\nstderr: {}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}
