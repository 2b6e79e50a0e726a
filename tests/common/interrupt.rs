//! A run of the `ivt` binary interrupted while it writes: ARGS (which write
//! into `out`) run until the first staged (temporary) file exists in `out`,
//! then get `signal`. Included by `tests/interrupts.rs` and
//! `tests/documented_contract.rs` (`#[path]`).
#![allow(dead_code)]

use ivt_sim::testing::listing;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The exit code, stdout and what is left in `out` after `kill -SIGNAL`
/// (`INT`, `TERM`) reached `ivt ARGS` as soon as it had staged a file.
pub fn interrupt_once_staged(
    args: &[&str],
    out: &Path,
    signal: &str,
) -> (Option<i32>, String, Vec<String>) {
    let child = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !out.exists() || listing(out).is_empty() {
        assert!(t0.elapsed() < Duration::from_secs(60), "no staged output");
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(
        listing(out).iter().all(|f| f.starts_with(".tmp-")),
        "{:?}",
        listing(out)
    );
    let status = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let res = child.wait_with_output().unwrap();
    let left = if out.exists() { listing(out) } else { vec![] };
    (
        res.status.code(),
        String::from_utf8_lossy(&res.stdout).into_owned(),
        left,
    )
}
