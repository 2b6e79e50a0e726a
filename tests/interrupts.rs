//! SIGINT during a run that writes files (moved from `tests/hardening.rs`,
//! which it made longer than 600 lines): under `--json` the one JSON error and
//! exit 130 (issue 43: 128 + SIGINT with or without `--json`), and nothing the
//! run created is left behind — neither its staged files nor the output
//! directory it made.
// A test may unwrap (the package's panic lints guard library code).
#![allow(clippy::unwrap_used)]

use ivt_sim::testing::{listing, scratch_dir};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const IVT: &str = env!("CARGO_BIN_EXE_ivt");

/// Run `args` (which write into `out`), send SIGINT as soon as the first
/// staged (temporary) file exists in `out`, and return the exit code and what
/// is left in `out`.
fn interrupt_once_staged(args: &[&str], out: &Path) -> (Option<i32>, Vec<String>) {
    let child = Command::new(IVT)
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
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let res = child.wait_with_output().unwrap();
    let left = if out.exists() { listing(out) } else { vec![] };
    (res.status.code(), left)
}

/// Ctrl-C during a simulation under `--json`: exit 130 (one JSON error of
/// kind `interrupted`) and no output (the partial MCAP and the output
/// directory this run created are removed).
#[test]
fn interrupted_sim_leaves_nothing() {
    let dir = scratch_dir("interrupts-sim");
    let out = dir.join("out");
    // The drive scene stretched to 30 min of simulated time (~1 s of work):
    // long enough to be interrupted while it runs on any machine.
    let drive = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/drive.toml"))
        .unwrap()
        .replace("duration_s = 60.0", "duration_s = 1800.0");
    let scene = dir.join("long_drive.toml");
    std::fs::write(&scene, drive).unwrap();
    let (scene, out_arg) = (scene.to_str().unwrap(), out.to_str().unwrap());
    let (code, left) = interrupt_once_staged(&["--json", "sim", scene, "--out", out_arg], &out);
    assert_eq!(code, Some(130));
    assert!(left.is_empty(), "left behind: {left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Ctrl-C during `reproduce`: every figure and CSV is staged until the report
/// is written, so an interrupted run leaves none of them (it used to leave
/// 20 files and no report).
#[test]
fn interrupted_reproduce_leaves_nothing() {
    let dir = scratch_dir("interrupts-reproduce");
    let out = dir.join("out");
    let out_arg = out.to_str().unwrap();
    let (code, left) =
        interrupt_once_staged(&["--json", "reproduce", "--quick", "--out", out_arg], &out);
    assert_eq!(code, Some(130));
    assert!(left.is_empty(), "left behind: {left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
