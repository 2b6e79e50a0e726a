//! Bounded proptests of the `--json` contract (SPEC §6): over argument
//! vectors, over shipped scenes with values replaced or deleted (counted: an
//! eighth must pass validation and run), and over hostile pulse logs for
//! `ctrl replay` (`IVT_FUZZ_CASES` sets the number of argument vectors,
//! default 48, and half as many scenes and logs; well under two minutes
//! together). Exit 0 or 2, one JSON object, never a panic.
// A test may index and unwrap (the package's panic lints guard library code).
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

#[path = "common/contract.rs"]
mod contract;

use contract::{contract, replay_log, serial, tmp, QUICK};
use ivt_sim::testing::listing;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

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
