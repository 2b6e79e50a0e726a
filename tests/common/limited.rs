//! A hostile input's run of the `ivt` binary: under `ulimit -v` (a run that
//! would grow past the limit aborts instead) and coreutils' `timeout` (a run
//! past the time limit is killed and exits 124), and the refusal it must end
//! in. Included by `tests/hostile.rs` and `tests/hostile_readers.rs`
//! (`#[path]`), each with its own memory limit.
#![allow(dead_code)]

use serde_json::Value;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const IVT: &str = env!("CARGO_BIN_EXE_ivt");
/// The time one hostile input may take.
pub const TIME_LIMIT: Duration = Duration::from_secs(20);

/// `ivt ARGS` within [`TIME_LIMIT`] and `memory_kb` of address space, with
/// `shell_tail` appended to the command (e.g. `>&-`); the exit code, stdout,
/// stderr and the wall time.
pub fn run_limited(
    args: &[&str],
    shell_tail: &str,
    memory_kb: u64,
) -> (Option<i32>, String, String, Duration) {
    let secs = TIME_LIMIT.as_secs();
    let script =
        format!("ulimit -v {memory_kb}; exec timeout -s KILL {secs} \"$0\" \"$@\" {shell_tail}");
    let t0 = Instant::now();
    let out = Command::new("sh")
        .args(["-c", &script, IVT])
        .args(args)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    let took = t0.elapsed();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (
        out.status.code(),
        text(&out.stdout),
        text(&out.stderr),
        took,
    )
}

/// `ivt --json ARGS` must refuse with `kind`: exit 2, one JSON object with a
/// string `error` and `kind`, nothing else on stdout, no panic, within the
/// limits; returns the error.
pub fn refused(args: &[&str], kind: &str, memory_kb: u64) -> String {
    let mut argv = vec!["--json"];
    argv.extend(args);
    let (code, out, err, took) = run_limited(&argv, "", memory_kb);
    assert!(!err.contains("panicked"), "{argv:?}: {err}");
    assert_eq!(code, Some(2), "{argv:?}: stdout {out:?} stderr {err:?}");
    let lines: Vec<&str> = out.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{argv:?}: {out:?}");
    let v: Value = serde_json::from_str(lines[0]).unwrap();
    assert_eq!(v["kind"], kind, "{argv:?}: {v}");
    assert!(took < TIME_LIMIT, "{argv:?}: {took:?}");
    v["error"].as_str().unwrap().to_string()
}
