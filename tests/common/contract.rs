//! The `--json` contract of SPEC §6 as the hardening tests check it: run
//! the `ivt` binary with a time limit, one test at a time, and check its exit
//! status and its one JSON object. Included by `tests/hardening.rs` and
//! `tests/hardening_fuzz.rs` (`#[path]`), which use different parts of it.
#![allow(dead_code)]
// A test may index and unwrap (the package's panic lints guard library code).
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_sim::testing::scratch_dir;
use serde_json::Value;
use std::io::Read as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

pub const IVT: &str = env!("CARGO_BIN_EXE_ivt");

/// The tests of this file run one at a time: a reader that closes its pipe
/// (EPIPE) or a signal sent to a child must not race with another test
/// forking children at the same moment (a forked child holds copies of every
/// descriptor until it execs).
pub fn serial() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    LOCK.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Exit code, stdout, stderr; the command is killed after `limit`.
pub fn spawn(args: &[&str], limit: Duration) -> (Option<i32>, String, String) {
    let mut child = Command::new(IVT)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out_pipe = child.stdout.take().unwrap();
    let mut err_pipe = child.stderr.take().unwrap();
    let out_thread = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out_pipe.read_to_string(&mut s);
        s
    });
    let err_thread = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err_pipe.read_to_string(&mut s);
        s
    });
    let t0 = Instant::now();
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    (code, out_thread.join().unwrap(), err_thread.join().unwrap())
}

/// Checks the SPEC §6 contract of one `--json` run and returns (code, object):
/// it ended within `limit`, with 0 or 2, no panic, exactly one JSON object on
/// stdout, `{"error", "kind"}` exactly when the status is 2.
pub fn contract(args: &[&str], limit: Duration) -> Result<(i32, Value), String> {
    let (code, out, err) = spawn(args, limit);
    let code = code.ok_or_else(|| format!("{args:?}: no exit within {limit:?}"))?;
    if err.contains("panicked") || !(code == 0 || code == 2) {
        return Err(format!("{args:?}: exit {code}, stderr {err}"));
    }
    let lines: Vec<&str> = out.lines().filter(|l| !l.trim().is_empty()).collect();
    if lines.len() != 1 {
        return Err(format!(
            "{args:?}: {} lines on stdout: {out:?}",
            lines.len()
        ));
    }
    let v: Value = serde_json::from_str(lines[0]).map_err(|e| format!("{args:?}: {e}"))?;
    let is_error = v.get("error").is_some();
    if is_error != (code == 2) {
        return Err(format!("{args:?}: exit {code} with {v}"));
    }
    if is_error && !v["kind"].is_string() {
        return Err(format!("{args:?}: error without kind: {v}"));
    }
    Ok((code, v))
}

/// A fresh scratch directory for one test of this file.
pub fn tmp(name: &str) -> ivt_sim::testing::Scratch {
    scratch_dir(&format!("hardening-{name}"))
}

/// 200 pulses of a steady 100 rpm at PPR 1200 and 1 MHz.
pub fn replay_log(dir: &Path) -> String {
    let mut text = String::from("ticks\n");
    for k in 0..200u32 {
        text.push_str(&format!("{}\n", 1000 + k * 500));
    }
    let p = dir.join("log.csv");
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

pub const QUICK: Duration = Duration::from_secs(60);
