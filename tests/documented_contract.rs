//! The contract as documented is the contract as run (issue 43): this test
//! reads the exit statuses and the error kinds from the guide's Limits and
//! errors chapter (`docs/guide/src/limits.md`, the paragraphs **Exit
//! status.** and **JSON error schema.**) and from `ivt --help`, requires the
//! two to list the same, and runs a command for every status and kind,
//! checking that it ends with it. A status or kind documented without a
//! command here, or a command whose ending differs, fails.
// A test may index and unwrap (the package's panic lints guard library code).
#![allow(
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic,
    clippy::unwrap_used
)]

#[path = "common/interrupt.rs"]
mod interrupt;
#[path = "common/rig.rs"]
mod rig;

use interrupt::interrupt_once_staged;
use ivt_sim::testing::scratch_dir;
use serde_json::Value;
use std::collections::BTreeSet;
use std::process::Command;

const IVT: &str = env!("CARGO_BIN_EXE_ivt");
const LIMITS: &str = include_str!("../docs/guide/src/limits.md");

/// The paragraph of limits.md that starts with `**{title}.**`.
fn paragraph(title: &str) -> String {
    let start = LIMITS
        .find(&format!("**{title}.**"))
        .unwrap_or_else(|| panic!("no paragraph **{title}.** in limits.md"));
    let rest = &LIMITS[start..];
    rest[..rest.find("\n\n").unwrap_or(rest.len())].replace('\n', " ")
}

/// The numbers written as `N:` in `text` (the statuses of **Exit status.**).
fn statuses(text: &str) -> BTreeSet<i32> {
    text.split_whitespace()
        .filter_map(|w| w.strip_suffix(':'))
        .filter_map(|w| w.parse().ok())
        .collect()
}

/// The quoted words of the `"kind": "a" | "b" | …` list in `text`.
fn kinds(text: &str) -> BTreeSet<String> {
    let list = text
        .split("\"kind\": ")
        .nth(1)
        .expect("a \"kind\": list")
        .split('}')
        .next()
        .unwrap();
    list.split('|')
        .map(|k| k.trim().trim_matches('"').to_string())
        .collect()
}

/// Exit status and the JSON object of `ivt --json ARGS`.
fn run(args: &[&str]) -> (i32, Value) {
    let out = Command::new(IVT).arg("--json").args(args).output().unwrap();
    let v = serde_json::from_slice(&out.stdout).unwrap_or(Value::Null);
    (out.status.code().unwrap_or(-1), v)
}

/// `ivt --json sim` on a long scene, interrupted with `signal` as soon as
/// it has staged a file: its exit status and JSON object.
fn interrupted(signal: &str) -> (i32, Value) {
    let dir = scratch_dir(&format!("documented-contract-{signal}"));
    let scene = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/drive.toml"))
        .unwrap()
        .replace("duration_s = 60.0", "duration_s = 1800.0");
    let path = dir.join("long.toml");
    std::fs::write(&path, scene).unwrap();
    let out = dir.join("out");
    let args = [
        "--json",
        "sim",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    let (code, stdout, _) = interrupt_once_staged(&args, &out, signal);
    std::fs::remove_dir_all(&dir).unwrap();
    (
        code.unwrap_or(-1),
        serde_json::from_str(&stdout).unwrap_or(Value::Null),
    )
}

#[test]
fn the_documented_statuses_and_kinds_are_what_the_commands_end_with() {
    let status_text = paragraph("Exit status");
    let schema_text = paragraph("JSON error schema");
    let documented_statuses = statuses(&status_text);
    let documented_kinds = kinds(&schema_text);
    assert_eq!(
        documented_statuses,
        BTreeSet::from([0, 2, 130]),
        "{status_text}"
    );
    // `ivt --help` says the same
    let help = Command::new(IVT).arg("--help").output().unwrap();
    let help = String::from_utf8_lossy(&help.stdout).replace('\n', " ");
    let epilog = help
        .split("Exit status:")
        .nth(1)
        .expect("exit statuses in --help");
    for s in &documented_statuses {
        assert!(
            epilog.contains(&format!(" {s} ")),
            "--help lacks {s}: {epilog}"
        );
    }
    for k in &documented_kinds {
        assert!(
            epilog.contains(&format!("\"{k}\"")),
            "--help lacks {k}: {epilog}"
        );
    }

    let dir = scratch_dir("documented-contract");
    let d = dir.to_str().unwrap();
    // one command per documented kind (and the status it exits with)
    let mut seen_statuses = BTreeSet::new();
    let mut seen_kinds = BTreeSet::new();
    let (code, v) = run(&["kin", "plant"]);
    assert_eq!(code, 0, "{v}");
    seen_statuses.insert(code);
    for (kind, args) in [
        ("usage", vec!["ol", "solve", "--vm", "eight", "--tu", "4"]),
        (
            "input",
            vec!["stability", "--vm", "8", "--tu", "4", "--n", "3"],
        ),
        ("failed", vec!["hb", "duffing", "--tol", "1e-300"]),
        ("io", vec!["sim", d]),
    ] {
        let (code, v) = run(&args);
        assert_eq!((code, v["kind"].as_str()), (2, Some(kind)), "{args:?}: {v}");
        seen_statuses.insert(code);
        seen_kinds.insert(kind.to_string());
    }
    // unidentifiable: the thesis-ch4 preset's commissioning run under the
    // default plan does not determine J_a (docs/guide/src/rig/identification.md)
    let plant = dir.join("ch4_plant.toml");
    std::fs::write(&plant, "[plant]\npreset = \"thesis-ch4\"\n").unwrap();
    let rec = dir.join("ch4.mcap");
    let (code, v) = rig::commission_sim(&plant, &rec, &[]);
    assert_eq!(code, 0, "{v}");
    let identified = dir.join("ch4_identified.toml");
    let args = [
        "rig",
        "identify",
        rec.to_str().unwrap(),
        "--out",
        identified.to_str().unwrap(),
    ];
    let (code, v) = run(&args);
    assert_eq!(
        (code, v["kind"].as_str()),
        (2, Some("unidentifiable")),
        "{v}"
    );
    seen_statuses.insert(code);
    seen_kinds.insert("unidentifiable".to_string());
    for signal in ["INT", "TERM"] {
        let (code, v) = interrupted(signal);
        assert_eq!(
            (code, v["kind"].as_str()),
            (130, Some("interrupted")),
            "{v}"
        );
        seen_statuses.insert(code);
        seen_kinds.insert("interrupted".to_string());
    }
    assert_eq!(seen_statuses, documented_statuses);
    assert_eq!(seen_kinds, documented_kinds);
    std::fs::remove_dir_all(&dir).unwrap();
}
