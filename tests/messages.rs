//! Issue 43, part A, messages: every number-taking option of the command
//! line (found in the parser, not listed by hand) accepts a negative number
//! as its value (`--xi -0.5` was read as a flag `-0`), and a refusal prints
//! numbers in the shortest round-trip form (`hb switch --step 1e300` printed
//! 301 digits). The issue's other message examples: `rig commission --k-prop
//! 1e300` named an internal generated file, `--pil` showed the build
//! machine's path, `ctrl replay --omega0-rpm 1e-30` was accepted.
// A test may index and unwrap (the package's panic lints guard library code).
#![allow(
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic,
    clippy::unwrap_used
)]

#[path = "common/contract.rs"]
mod contract;
#[path = "common/cores.rs"]
mod cores;

use contract::{contract, replay_log, serial, tmp};
use cores::on_every_core;
use std::any::TypeId;
use std::time::Duration;

/// The example model file of `ivt hb frc MODEL` and `ivt hb solve MODEL`.
const MODEL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/models/two-mass.toml");

/// Every `(subcommand path, --option)` whose value is an `f64`.
fn number_options() -> Vec<(Vec<String>, String)> {
    fn walk(cmd: &clap::Command, path: &mut Vec<String>, out: &mut Vec<(Vec<String>, String)>) {
        for a in cmd.get_arguments() {
            if let Some(long) = a.get_long() {
                if a.get_value_parser().type_id() == TypeId::of::<f64>() {
                    out.push((path.clone(), format!("--{long}")));
                }
            }
        }
        for sub in cmd.get_subcommands() {
            path.push(sub.get_name().to_string());
            walk(sub, path, out);
            path.pop();
        }
    }
    let mut out = vec![];
    walk(&ivt::cli::command(), &mut vec![], &mut out);
    out
}

/// The arguments a subcommand needs besides the option under test (a
/// number-taking subcommand missing here fails the test).
/// Outputs go to `out` (a scratch directory).
fn base(path: &[String], log: &str, scene: &str, out: &str) -> Option<Vec<String>> {
    let path: Vec<&str> = path.iter().map(String::as_str).collect();
    let mcap = format!("{out}/unused.mcap");
    let extra: &[&str] = match path.as_slice() {
        // the torus and the diagram at a low resolution (4 s and 2 s, not 30 s)
        ["hb", "torus"] => &[
            "--n",
            "8",
            "--samples",
            "24",
            "--h1",
            "3",
            "--h2",
            "6",
            "--at",
            "0.93",
            "--omega-to",
            "0.92",
        ],
        ["hb", "diagram"] => &["--n", "5", "--samples", "16", "--depth", "0"],
        // a user's model file (the guide's example)
        ["hb", "frc"] => &[MODEL],
        ["hb", "solve"] => &[MODEL, "--omega", "1.1"],
        ["kin", _] | ["hb", _] | ["ol", "table" | "fit"] | ["stability-map"] => &[],
        ["ol", "solve"] | ["stability"] => &["--vm", "8", "--tu", "4"],
        ["ctrl", "replay"] => &[log],
        ["sim"] => &[scene, "--out", out],
        ["rig", "record"] => &["--port", "/dev/null", "--out", &mcap],
        ["rig", "commission"] => &["--sim", "--sequence", "hold", "--out", &mcap],
        ["bench", "work-precision"] => &[],
        _ => return None,
    };
    Some(path.iter().chain(extra).map(|s| s.to_string()).collect())
}

/// Values an option takes: `stability-map --vm FROM STEP TO`, `stability
/// --design K_MAX K2_MAX`, else one.
fn arity(path: &[String], opt: &str) -> usize {
    match (path.last().map(String::as_str), opt) {
        (Some("stability-map"), "--vm" | "--tu") => 3,
        (Some("stability"), "--design") => 2,
        _ => 1,
    }
}

/// `argv` with `opt` set to `value` (as many times as it takes values),
/// replacing the base's own setting of it.
fn with_option(argv: Vec<String>, path: &[String], opt: &str, value: &str) -> Vec<String> {
    let n = arity(path, opt);
    let mut out = vec![];
    let mut it = argv.into_iter();
    while let Some(a) = it.next() {
        if a == opt {
            it.nth(n - 1);
        } else {
            out.push(a);
        }
    }
    out.push(opt.to_string());
    out.extend(std::iter::repeat_n(value.to_string(), n));
    out
}

/// Runs known to take longer than the limit with a valid extreme value
/// (harmonic-balance continuations over a huge or tiny range: bounded by
/// their point limits, but slow); their messages are checked by the other
/// values.
const SLOW: &[(&str, &str, &str)] = &[
    ("string", "--to", "1e300"),
    ("string", "--cd", "1e-300"),
    ("string", "--ds-max", "1e-300"),
    ("switch", "--branch-to", "-1e300"),
    ("switch", "--branch-to", "1e-300"),
    ("switch", "--damping", "1e-300"),
    ("torus", "--omega-to", "1e-300"),
    ("diagram", "--from", "1e-300"),
    ("diagram", "--to", "1e300"),
];

/// `-0.5` is a value for every number option (clap read it as the flag
/// `-0`): the parser accepts it; the command then checks its range.
#[test]
fn every_number_option_takes_a_negative_value() {
    let options = number_options();
    assert!(options.len() > 80, "{} options", options.len());
    for (path, opt) in &options {
        let mut argv = vec!["ivt".to_string()];
        let head = base(path, "log.csv", "s.toml", "out").unwrap_or_else(|| path.clone());
        argv.extend(with_option(head, path, opt, "-0.5"));
        let parsed = ivt::cli::command().try_get_matches_from(&argv);
        assert!(parsed.is_ok(), "{argv:?}: {}", parsed.unwrap_err());
    }
}

/// Every number option at ±1e300 and 1e-300: the run keeps the `--json`
/// contract, and a refusal shows no number of 25 digits or more.
#[test]
fn refusals_print_numbers_in_their_shortest_form() {
    let dir = tmp("messages");
    let log = replay_log(&dir);
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/drive.toml");
    let _serial = serial();
    let mut runs: Vec<Vec<String>> = vec![];
    for (path, opt) in number_options() {
        let argv = base(&path, &log, scene, dir.to_str().unwrap())
            .unwrap_or_else(|| panic!("{path:?} {opt}: no base arguments in tests/messages.rs"));
        for v in ["1e300", "-1e300", "1e-300"] {
            let last = path.last().map_or("", String::as_str);
            if SLOW.contains(&(last, opt.as_str(), v)) {
                continue;
            }
            let mut args: Vec<String> = vec!["--json".into()];
            args.extend(with_option(argv.clone(), &path, &opt, v));
            runs.push(args);
        }
    }
    // One `ivt` process a run, as many at a time as there are cores.
    on_every_core(&runs, |args| {
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, obj) = contract(&refs, Duration::from_secs(60)).unwrap();
        if code == 2 {
            let e = obj["error"].as_str().unwrap();
            assert!(long_digit_run(e).is_none(), "{refs:?}: {e}");
        }
    });
    let _ = std::fs::remove_dir_all(&dir);
}

/// The first run of 25 or more digits in `text` (a number printed in full).
fn long_digit_run(text: &str) -> Option<String> {
    let mut run = String::new();
    for c in text.chars() {
        if c.is_ascii_digit() {
            run.push(c);
            if run.len() >= 25 {
                return Some(run);
            }
        } else if c != '.' {
            run.clear();
        }
    }
    None
}

/// The issue's examples, each with its expected text.
#[test]
fn the_issues_message_examples() {
    let dir = tmp("messages-examples");
    let log = replay_log(&dir);
    let _serial = serial();
    let limit = Duration::from_secs(60);
    let run = |args: &[&str]| contract(args, limit).unwrap();
    let (code, v) = run(&["--json", "hb", "switch", "--step", "1e300"]);
    assert_eq!(code, 2);
    assert!(
        v["error"].as_str().unwrap().contains("`step` = 1e300"),
        "{v}"
    );
    let (code, v) = run(&["--json", "hb", "string", "--kd", "1e300"]);
    assert_eq!(code, 2);
    assert!(v["error"].as_str().unwrap().contains("`kd` = 1e300"), "{v}");
    // named by the option the user typed, not the generated scene
    let out = dir.join("k.mcap");
    for (value, refusal) in [
        (
            "1e300",
            "--k-prop = 1e300 deg/rpm does not fit the controller's f32",
        ),
        ("-5", "--k-prop = -5 deg/rpm must be > 0"),
    ] {
        let o = out.to_str().unwrap();
        let (code, v) = run(&[
            "--json",
            "rig",
            "commission",
            "--sim",
            "--k-prop",
            value,
            "--out",
            o,
        ]);
        assert_eq!((code, v["kind"].as_str()), (2, Some("input")), "{v}");
        assert!(v["error"].as_str().unwrap().starts_with(refusal), "{v}");
    }
    // a negative damping ratio is a value, and a valid problem
    let (code, v) = run(&["--json", "hb", "duffing", "--xi", "-0.5"]);
    assert_eq!(code, 0, "{v}");
    // a set speed no rig holds
    for (flag, v) in [("--omega0-rpm", "1e-30"), ("--omega0-rpm", "0.09")] {
        let (code, obj) = run(&["--json", "ctrl", "replay", &log, flag, v]);
        assert_eq!(code, 2, "{obj}");
        assert_eq!(
            obj["error"],
            format!("{flag} = {v} rpm is outside [0.1, 10000) rpm"),
            "{obj}"
        );
    }
    let (code, _) = run(&["--json", "ctrl", "replay", &log, "--omega0-rpm", "0.1"]);
    assert_eq!(code, 0);
    // --pil without the firmware image: the image named within the source
    // tree, not by this machine's path
    let (code, v) = run(&[
        "--json",
        "rig",
        "commission",
        "--sim",
        "--pil",
        "--sequence",
        "hold",
        "--out",
        out.to_str().unwrap(),
    ]);
    if code == 2 {
        let e = v["error"].as_str().unwrap();
        assert!(!e.contains(env!("CARGO_MANIFEST_DIR")), "{e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
