//! `ivt hb cycle-branch`, `ivt hb all-solutions` and `ivt hb switch` (issue
//! 27): their JSON keys and values (closed forms where there are; the
//! independent references of the jobs are in crates/ivt-hb/tests), and one
//! JSON error with exit 2 for bad flags.
#![allow(clippy::panic)]

#[path = "common/contract.rs"]
mod contract;

use std::time::Duration;

/// `ivt --json` with the whitespace-separated arguments of `cmd_line`, its
/// SPEC §6 contract checked: (exit status, the one JSON object).
fn run(cmd_line: &str) -> (i32, serde_json::Value) {
    let args: Vec<&str> = ["--json"]
        .into_iter()
        .chain(cmd_line.split_whitespace())
        .collect();
    contract::contract(&args, Duration::from_secs(300)).unwrap_or_else(|e| panic!("{e}"))
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn cycle_branch_has_the_subcritical_hopf_point_and_the_fold_of_averaging() {
    let (code, v) = run("hb cycle-branch");
    assert_eq!(code, 0, "{v}");
    // ẍ − (μ + x² − x⁴)ẋ + x = 0: eigenvalues μ/2 ± i√(1 − μ²/4), Hopf at
    // μ = 0 with ω = 1; l1 > 0 (the x² term destabilises).
    let hopf = &v["hopf"][0];
    assert!(f(&hopf["p"]).abs() < 1e-8 && (f(&hopf["omega"]) - 1.0).abs() < 1e-8);
    assert_eq!(hopf["subcritical"], true);
    // Averaging: r' = (r/2)(μ + r²/4 − r⁴/8), the cycles' fold at μ = −1/8,
    // r = 1, to O(μ²) (measured −0.1249932; tests/cycle_branch.rs in ivt-hb
    // checks it against time integration to 1e-8).
    let fold = &v["bifurcations"][0];
    assert_eq!(fold["kind"], "fold");
    assert!((f(&fold["p"]) + 0.125).abs() < 1e-4, "{fold}");
    assert!((f(&fold["amplitude"]) - 1.0).abs() < 1e-3, "{fold}");
    // At μ = −0.1 both cycles: averaging's r² = 1 ∓ √(1 + 8μ) (0.553, 1.447);
    // the small one unstable, the large one stable.
    let at = v["at"].as_array().unwrap();
    assert_eq!(at.len(), 2, "{v}");
    let mut cycles: Vec<(f64, bool)> = at
        .iter()
        .map(|c| (f(&c["amplitude"]), c["stable"].as_bool().unwrap()))
        .collect();
    cycles.sort_by(|a, b| a.0.total_cmp(&b.0));
    let r = |s: f64| (1.0 + s * (1.0f64 - 0.8).sqrt()).sqrt();
    assert!(
        (cycles[0].0 - r(-1.0)).abs() < 2e-2 && !cycles[0].1,
        "{cycles:?}"
    );
    assert!(
        (cycles[1].0 - r(1.0)).abs() < 2e-2 && cycles[1].1,
        "{cycles:?}"
    );
    assert_eq!(v["termination"], "left_interval");
    for key in [
        "p",
        "omega",
        "period",
        "amplitude",
        "stable",
        "stability",
        "multipliers",
        "coeffs",
    ] {
        assert!(v["points"][0].get(key).is_some(), "missing {key}");
    }
}

#[test]
fn all_solutions_finds_the_three_duffing_orbits_at_1_4() {
    let (code, v) = run("hb all-solutions");
    assert_eq!(code, 0, "{v}");
    let sols = v["solutions"].as_array().unwrap();
    let stable: Vec<bool> = sols
        .iter()
        .map(|s| s["stable"].as_bool().unwrap())
        .collect();
    // Small and large stable, the middle one a saddle (ivt-hb's
    // tests/all_solutions.rs checks the three by shooting).
    assert_eq!(stable, [true, false, true], "{v}");
    assert_eq!(v["search"]["exhausted"], true);
    for key in ["starts", "runs", "max_amplitude", "newton_steps"] {
        assert!(v["search"].get(key).is_some(), "missing {key}");
    }
}

#[test]
fn switch_continues_the_period_two_branch_of_the_well() {
    let (code, v) = run("hb switch --n 10 --samples 32");
    assert_eq!(code, 0, "{v}");
    assert_eq!(v["kind"], "period_doubling");
    assert_eq!(
        (v["subharmonic"].as_u64(), v["harmonics"].as_u64()),
        (Some(2), Some(20))
    );
    // The period doubling of ivt-hb's tests/switch.rs (2.93667, checked there
    // by shooting over 2T).
    assert!(
        (f(&v["start_omega"]) - 2.93667).abs() < 1e-4,
        "{}",
        v["start_omega"]
    );
    for key in [
        "points",
        "folds",
        "bifurcations",
        "termination",
        "omega",
        "amplitude",
        "stable",
        "time_s",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["termination"], "left_interval");
}

#[test]
fn bad_flags_are_one_json_error_with_exit_2() {
    for (cmd, kind) in [
        ("hb switch --step 0", "input"),
        ("hb switch --n 10 --samples 32 --branch-to 3.6", "input"),
        ("hb switch --from 1 --to 1", "input"),
        ("hb cycle-branch --mu-from 0.1", "input"),
        ("hb cycle-branch --at nan", "input"),
        ("hb all-solutions --omega nan", "input"),
        ("hb all-solutions --samples 10", "input"),
        ("hb all-solutions --bogus 1", "usage"),
    ] {
        let (code, v) = run(cmd);
        assert_eq!((code, v["kind"].as_str()), (2, Some(kind)), "{cmd}: {v}");
        assert!(v["error"].is_string(), "{cmd}: {v}");
    }
}
