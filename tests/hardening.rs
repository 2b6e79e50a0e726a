//! Nothing crashes, nothing lies: every hostile command of the regression
//! corpus ends in exit 2 with exactly one `{"error", "kind"}` object under
//! `--json` (or a correct answer), closed pipes and full disks end in exit 2
//! without a panic, failed commands leave no file behind (interrupted ones:
//! `tests/interrupts.rs`), and
//! `ol solve` is accurate by default. Bounded proptests keep it so: over
//! argument vectors, over shipped scenes with values replaced or deleted
//! (counted: an eighth must pass validation and run), and over hostile pulse
//! logs for `ctrl replay` (`IVT_FUZZ_CASES` sets the number of argument
//! vectors, default 48, and half as many scenes and logs; well under two
//! minutes together).

use ivt_sim::testing::{listing, scratch_dir};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use serde_json::Value;
use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const IVT: &str = env!("CARGO_BIN_EXE_ivt");

/// The tests of this file run one at a time: a reader that closes its pipe
/// (EPIPE) or a signal sent to a child must not race with another test
/// forking children at the same moment (a forked child holds copies of every
/// descriptor until it execs).
fn serial() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    LOCK.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Exit code, stdout, stderr; the command is killed after `limit`.
fn spawn(args: &[&str], limit: Duration) -> (Option<i32>, String, String) {
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
fn contract(args: &[&str], limit: Duration) -> Result<(i32, Value), String> {
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
fn tmp(name: &str) -> PathBuf {
    scratch_dir(&format!("hardening-{name}"))
}

/// 200 pulses of a steady 100 rpm at PPR 1200 and 1 MHz.
fn replay_log(dir: &Path) -> String {
    let mut text = String::from("ticks\n");
    for k in 0..200u32 {
        text.push_str(&format!("{}\n", 1000 + k * 500));
    }
    let p = dir.join("log.csv");
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

const QUICK: Duration = Duration::from_secs(60);

/// Every command of the issue's list, each refused cleanly (by kind and with
/// the offending argument named), within a minute, before any allocation.
#[test]
fn regression_corpus_is_refused_by_name() {
    let _serial = serial();
    let dir = tmp("corpus");
    let log = replay_log(&dir);
    let mcap = dir.join("r.mcap").to_string_lossy().into_owned();
    #[rustfmt::skip]
    let cases: Vec<(Vec<&str>, &str, &str)> = vec![
        (vec!["stability-map", "--vm", "2", "1e-300", "12"], "input", "--vm"),
        (vec!["stability-map", "--vm", "2", "1e-6", "12"], "input", "--vm"),
        (vec!["ol", "table", "--vm-step", "1e-300"], "input", "--vm-step"),
        (vec!["ol", "table", "--tu-step", "0"], "input", "--tu-step"),
        (vec!["ol", "fit", "--quiet", "--tu-step", "0"], "input", "--tu-step"),
        (vec!["ol", "fit", "--quiet", "--vm-from", "7.6", "--vm-to", "8", "--tu-from", "2", "--tu-to", "2.5"], "input", "fewer feasible points"),
        (vec!["hb", "mathieu-duffing", "--n", "4294967296"], "input", "unknowns"),
        (vec!["stability", "--vm", "8", "--tu", "1.5", "--n", "4294967296"], "input", "chebyshev_order"),
        (vec!["rig", "record", "--port", "/nonexistent", "--out", &mcap, "--idle-timeout-s", "1e308"], "input", "--idle-timeout-s"),
        (vec!["hb", "duffing", "--samples", "4294967296"], "input", "samples"),
        (vec!["hb", "mathieu-duffing", "--n", "5000"], "input", "unknowns"),
        (vec!["hb", "string", "--ms", "4294967296"], "input", "ms"),
        (vec!["hb", "string", "--modes", "100000"], "input", "unknowns"),
        (vec!["kin", "sgivt-ratio", "--points", "4294967296"], "input", "--points"),
        (vec!["kin", "givt-ratio", "--points", "100000000"], "input", "--points"),
        (vec!["hb", "duffing", "--n", "abc"], "usage", "--n"),
        (vec!["ol", "solve"], "usage", "--vm"),
        (vec!["ol"], "usage", "subcommand"),
        (vec!["ctrl", "replay", &log, "--f-timer", "0"], "input", "--f-timer"),
        (vec!["ctrl", "replay", &log, "--decimation", "0"], "input", "--decimation"),
        (vec!["ctrl", "replay", &log, "--stall-timeout", "0"], "input", "--stall-timeout"),
        (vec!["ctrl", "replay", &log, "--k", "NaN"], "input", "--k"),
        (vec!["hb", "duffing", "--tol", "inf"], "input", "tol must be finite and > 0"),
        (vec!["hb", "duffing", "--omega-f", "1e-6"], "failed", "not finite"),
        (vec!["stability", "--vm", "8", "--tu", "1.5", "--design", "1e308", "1e308"], "failed", "|multiplier| < 1"),
        (vec!["stability", "--vm", "8", "--tu", "1.5", "--design", "1", "1", "--design-steps", "100000"], "input", "--design-steps"),
        (vec!["ol", "solve", "--vm", "8", "--tu", "1.5", "--harmonics", "100000"], "input", "harmonics"),
        (vec!["stability-map", "--vm", "8", "1", "9", "--tu", "1.5", "1", "2.5", "--k", "1e6"], "failed", "every one"),
    ];
    for (args, kind, needle) in cases {
        let mut argv = vec!["--json"];
        argv.extend(&args);
        let (code, v) = contract(&argv, QUICK).unwrap();
        assert_eq!(code, 2, "{argv:?}: {v}");
        assert_eq!(v["kind"], kind, "{argv:?}: {v}");
        let msg = v["error"].as_str().unwrap();
        assert!(
            msg.contains(needle),
            "{argv:?}: {msg:?} does not name {needle:?}"
        );
    }
    assert!(!Path::new(&mcap).exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn help_and_version_succeed() {
    let _serial = serial();
    for flag in ["--help", "--version"] {
        let (code, out, _) = spawn(&["--json", flag], QUICK);
        assert_eq!(code, Some(0), "{flag}");
        assert!(out.contains("ivt"), "{flag}: {out}");
    }
}

/// A reader that went away (EPIPE) and a full disk (ENOSPC) end in exit 2,
/// never a panic; the full disk is reported on stderr.
#[test]
fn closed_pipe_and_full_disk_exit_2() {
    let _serial = serial();
    // The reader end is closed before the spawn, so the answer is always
    // written into a pipe without a reader (EPIPE), whatever the timing.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(IVT)
        .args(["--json", "hb", "duffing"])
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!err.contains("panicked"), "{err}");

    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let out = Command::new(IVT)
        .args(["--json", "hb", "duffing"])
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("stdout") && err.contains("No space left"),
        "{err}"
    );
}

/// A write that fails leaves the directory as it was (no partial or
/// temporary file), and the error is an `io` error naming the path.
#[test]
fn failed_write_leaves_the_directory_as_it_was() {
    let _serial = serial();
    let dir = tmp("atomic");
    let log = replay_log(&dir);
    let target = dir.join("taken");
    std::fs::create_dir(&target).unwrap(); // rename onto a directory fails
    let before = listing(&dir);
    let (code, v) = contract(
        &[
            "--json",
            "ctrl",
            "replay",
            &log,
            "--out",
            target.to_str().unwrap(),
        ],
        QUICK,
    )
    .unwrap();
    assert_eq!(code, 2, "{v}");
    assert_eq!(v["kind"], "io", "{v}");
    assert!(v["error"].as_str().unwrap().contains("taken"), "{v}");
    assert_eq!(listing(&dir), before);
    std::fs::remove_dir_all(&dir).unwrap();
}

fn r_of(args: &[&str]) -> Value {
    let (code, v) = contract(args, Duration::from_secs(120)).unwrap();
    assert_eq!(code, 0, "{v}");
    v
}

/// `ol solve` by default: r̄ within 1e-6 relative of an independent method
/// (the IHB with n = 383, 8.7e-9 from θ-shooting per crates/ivt-design/README.md)
/// and of the θ-shooting value the issue quotes (0.0068038 m, 5 digits); the
/// error estimate in the JSON is ≤ 1e-6 relative. The thesis's n = 7 is an
/// explicit option, labelled, and its estimate is as large as its real error.
#[test]
fn ol_solve_is_accurate_by_default() {
    let _serial = serial();
    let base = ["--json", "ol", "solve", "--vm", "8", "--tu", "1.5"];
    let d = r_of(&base);
    let r = d["r"].as_f64().unwrap();
    let mut fine = base.to_vec();
    fine.extend(["--method", "ihb", "--harmonics", "383"]);
    let r_fine = r_of(&fine)["r"].as_f64().unwrap();
    assert!((r - r_fine).abs() <= 1e-6 * r_fine.abs(), "{r} vs {r_fine}");
    assert!((r - 0.0068038).abs() <= 5e-8, "{r}");
    let est = d["error_estimate"]["r_rel"].as_f64().unwrap();
    assert!(est > 0.0 && est <= 1e-6, "{est}");
    assert_eq!(d["thesis_choice"], false);

    let mut thesis = base.to_vec();
    thesis.extend(["--method", "ihb"]);
    let t = r_of(&thesis);
    assert_eq!(t["thesis_choice"], true);
    assert_eq!(t["harmonics"], 7);
    let r7 = t["r"].as_f64().unwrap();
    let real = (r7 - r_fine).abs() / r_fine;
    let est7 = t["error_estimate"]["r_rel"].as_f64().unwrap();
    assert!(real > 0.02, "n = 7 is ~3 % off: {real}");
    // |r(7) − r(15)| vs the true error: same order (r(n) ~ n⁻³).
    assert!(est7 > 0.5 * real && est7 < 2.0 * real, "{est7} vs {real}");
}

/// Argument tokens a hostile user types: extremes, non-numbers, nothing.
fn value() -> impl Strategy<Value = String> {
    prop::sample::select(vec![
        "0",
        "-1",
        "1",
        "2",
        "7",
        "0.5",
        "1e-300",
        "1e308",
        "-1e308",
        "NaN",
        "inf",
        "-inf",
        "4294967296",
        "18446744073709551616",
        "abc",
        "",
        "1e-6",
        "100000",
        "12",
    ])
    .prop_map(str::to_string)
}

/// A quick subcommand and its options.
fn command() -> impl Strategy<Value = (Vec<&'static str>, Vec<&'static str>)> {
    prop::sample::select(vec![
        (
            vec!["hb", "duffing"],
            vec![
                "--n",
                "--samples",
                "--xi",
                "--alpha",
                "--eps",
                "--force",
                "--tol",
                "--omega-f",
            ],
        ),
        (
            vec!["hb", "mathieu-duffing"],
            vec!["--n", "--xi", "--alpha", "--omega", "--gamma"],
        ),
        (vec!["kin", "sgivt-ratio"], vec!["--points", "--theta-ct"]),
        (vec!["kin", "fourier-fit"], vec!["--harmonics"]),
        (
            vec!["ol", "solve", "--vm", "8", "--tu", "1.5"],
            vec!["--vm", "--tu", "--omega0-rpm", "--harmonics", "--method"],
        ),
        (
            vec!["stability", "--vm", "8", "--tu", "1.5"],
            vec!["--k", "--k2", "--n", "--omega0-rpm", "--vm", "--tu"],
        ),
        (
            vec!["ctrl", "replay", "LOG"],
            vec![
                "--ppr",
                "--decimation",
                "--f-timer",
                "--omega0-rpm",
                "--k",
                "--k2",
                "--stall-timeout",
                "--vm",
                "--tu",
                "--prop-period",
            ],
        ),
    ])
}

/// The bounded run in `./scripts/test` is reproducible: a fixed seed, so CI
/// checks the same 48 argument vectors every time (a failure found there is a
/// regression, not luck). `IVT_FUZZ_SEED=random` (or a number) explores.
fn seed() -> RngSeed {
    match std::env::var("IVT_FUZZ_SEED").as_deref() {
        Ok("random") => RngSeed::Random,
        Ok(s) => s
            .parse()
            .map(RngSeed::Fixed)
            .unwrap_or(RngSeed::Fixed(20_261_123)),
        Err(_) => RngSeed::Fixed(20_261_123),
    }
}

fn cases() -> u32 {
    std::env::var("IVT_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(48)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), rng_seed: seed(), failure_persistence: None, ..ProptestConfig::default() })]

    /// Any argument vector: exit 0 or 2 within 60 s, one JSON object, never
    /// a panic.
    #[test]
    fn any_argv_keeps_the_contract(
        (base, opts) in command(),
        picks in prop::collection::vec((any::<prop::sample::Index>(), value()), 0..4),
    ) {
        let _serial = serial();
        let dir = tmp("fuzz");
        let log = replay_log(&dir);
        let mut argv: Vec<String> = vec!["--json".into()];
        argv.extend(base.iter().map(|a| if *a == "LOG" { log.clone() } else { (*a).to_string() }));
        for (i, v) in &picks {
            argv.push(opts[i.index(opts.len())].to_string());
            argv.push(v.clone());
        }
        let argv: Vec<&str> = argv.iter().map(String::as_str).collect();
        if let Err(e) = contract(&argv, QUICK) {
            prop_assert!(false, "{}", e);
        }
    }
}

/// Hostile replacements for one value of a scene file (TOML literals).
fn scene_value() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec![
        "0",
        "-1",
        "0.5",
        "2",
        "1e-300",
        "1e308",
        "-1e308",
        "nan",
        "inf",
        "-inf",
        "4294967296",
        "\"abc\"",
        "\"\"",
        "[]",
        "[[0.0, 1.0]]",
        "true",
        "{}",
        // Type-preserving edits: the number scaled (an integer stays one).
        "*0.5",
        "*2",
        "*1.1",
        "*0.1",
        "*3",
    ])
}

/// `value` with a `*factor` edit applied: a number scaled (integers stay
/// integers); anything else unchanged.
fn scaled(value: &str, edit: &str) -> Option<String> {
    let factor: f64 = edit.strip_prefix('*')?.parse().ok()?;
    let number = value.split('#').next()?.trim();
    if let Ok(i) = number.parse::<i64>() {
        return Some(format!("{}", (i as f64 * factor).round() as i64));
    }
    number
        .parse::<f64>()
        .ok()
        .map(|x| format!("{:?}", x * factor))
}

/// A shipped scene with `edits` of its `key = value` lines replaced (or, for
/// `None`, deleted): structure-aware mutations that keep the TOML mostly
/// parseable, so that they reach the scene validation and the run.
fn mutated_scene(name: &str, edits: &[(prop::sample::Index, Option<&str>)]) -> String {
    let path = format!("{}/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let assignments: Vec<usize> = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| !l.trim_start().starts_with('#') && l.contains(" = "))
        .map(|(i, _)| i)
        .collect();
    for (at, value) in edits {
        let i = assignments[at.index(assignments.len())];
        let key = lines[i].split(" = ").next().unwrap().to_string();
        let old_value = lines[i].split(" = ").nth(1).unwrap_or("").to_string();
        lines[i] = match value {
            Some(v) if v.starts_with('*') => match scaled(&old_value, v) {
                Some(x) => format!("{key} = {x}"),
                None => lines[i].clone(),
            },
            Some(v) => format!("{key} = {v}"),
            None => String::new(),
        };
    }
    lines.join("\n")
}

/// Hostile pulse-log rows: a tick column (numbers out of range, negative,
/// non-numbers, decreasing) with optional V_m and T_U columns.
fn csv_cell() -> impl Strategy<Value = String> {
    prop_oneof![
        (0u64..5_000_000u64).prop_map(|t| t.to_string()),
        prop::sample::select(vec![
            "-1",
            "4294967296",
            "1e308",
            "nan",
            "inf",
            "abc",
            "",
            "0.5",
            "8.4",
            "6.0",
            " 12 ",
        ])
        .prop_map(str::to_string),
    ]
}

/// A shipped scene with one to three values replaced or deleted: exit 0 or
/// 2 within 60 s, one JSON object, and a refused scene writes nothing. The
/// cases are counted: at least an eighth must pass validation and run (half
/// the edits keep the type: a number scaled), so that the mutations reach the
/// simulator and not only the TOML parser.
#[test]
fn mutated_scenes_keep_the_contract() {
    use proptest::test_runner::{Config, TestRunner};
    let strategy = (
        prop::sample::select(vec![
            "drive",
            "steady_state",
            "load_step_delay",
            "saturation",
            "voltage_step_open",
        ]),
        prop::collection::vec(
            (
                any::<prop::sample::Index>(),
                prop::option::weighted(0.85, scene_value()),
            ),
            1..3,
        ),
    );
    let config = Config {
        cases: cases() / 2,
        rng_seed: seed(),
        failure_persistence: None,
        ..Config::default()
    };
    let (ran, refused) = (std::cell::Cell::new(0u32), std::cell::Cell::new(0u32));
    let dir = tmp("scene");
    TestRunner::new(config)
        .run(&strategy, |(name, edits)| {
            let _serial = serial();
            let scene = dir.join("scene.toml");
            std::fs::write(&scene, mutated_scene(name, &edits)).unwrap();
            let out = dir.join("out");
            let _ = std::fs::remove_dir_all(&out);
            let argv = [
                "--json",
                "sim",
                scene.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ];
            match contract(&argv, QUICK) {
                Err(e) => prop_assert!(false, "{}", e),
                Ok((2, _)) => {
                    let left = if out.exists() { listing(&out) } else { vec![] };
                    prop_assert!(left.is_empty(), "refused scene left {:?}", left);
                    refused.set(refused.get() + 1);
                }
                Ok(_) => ran.set(ran.get() + 1),
            }
            Ok(())
        })
        .unwrap();
    eprintln!(
        "mutated scenes: {} ran, {} refused",
        ran.get(),
        refused.get()
    );
    assert!(
        8 * ran.get() >= ran.get() + refused.get(),
        "{} ran, {} refused",
        ran.get(),
        refused.get()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases() / 2, rng_seed: seed(), failure_persistence: None, ..ProptestConfig::default() })]

    /// A pulse log of hostile rows: exit 0 or 2, one JSON object, no panic.
    #[test]
    fn hostile_replay_logs_keep_the_contract(
        header in prop::sample::select(vec!["ticks", "ticks,vm,tu", "t", ""]),
        rows in prop::collection::vec(prop::collection::vec(csv_cell(), 1..4), 0..40),
    ) {
        let _serial = serial();
        let dir = tmp("csv");
        let log = dir.join("log.csv");
        let body: Vec<String> = rows.iter().map(|r| r.join(",")).collect();
        std::fs::write(&log, format!("{header}\n{}\n", body.join("\n"))).unwrap();
        if let Err(e) = contract(&["--json", "ctrl", "replay", log.to_str().unwrap()], QUICK) {
            prop_assert!(false, "{}", e);
        }
    }
}
