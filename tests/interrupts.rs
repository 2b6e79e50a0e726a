//! SIGINT during a run that writes files (moved from `tests/hardening.rs`,
//! which it made longer than 600 lines): under `--json` the one JSON error and
//! exit 130 (issue 43: 128 + SIGINT with or without `--json`), and nothing the
//! run created is left behind — neither its staged files nor the output
//! directory it made.
// A test may unwrap (the package's panic lints guard library code).
#![allow(clippy::unwrap_used)]

#[path = "common/interrupt.rs"]
mod interrupt;

use interrupt::interrupt_once_staged;
use ivt_sim::testing::scratch_dir;

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
    let (code, _, left) =
        interrupt_once_staged(&["--json", "sim", scene, "--out", out_arg], &out, "INT");
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
    let (code, _, left) = interrupt_once_staged(
        &["--json", "reproduce", "--quick", "--out", out_arg],
        &out,
        "INT",
    );
    assert_eq!(code, Some(130));
    assert!(left.is_empty(), "left behind: {left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
