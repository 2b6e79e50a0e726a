//! One validated boundary (issue 30 item 2): every number of
//! `ivt_kin::params::KEYS` is refused out of range by the boundaries that set
//! it — a scene under its key, the CLI under each flag of `ALIASES` — with
//! the same text after the name (`= 2000 V is outside [-1000, 1000] V`), the
//! value as typed. Table-driven: a key or flag added to the table without a
//! way to reach it here fails `every_cli_alias_has_a_command`.
//! (Python's arguments: crates/ivt-py/tests/test_boundary.py.)
#![allow(clippy::expect_used)]

#[path = "common/contract.rs"]
mod contract;

use contract::{contract, replay_log, serial, tmp, QUICK};
use ivt_kin::params::{check, Bound, Boundary, Key, ALIASES, KEYS};
use ivt_sim::scene::Scene;

/// Values of `key`'s quantity just outside its range, on both sides, and NaN.
fn outside(key: &Key) -> [f64; 3] {
    let below = match key.min {
        Bound::Closed(m) => m - m.abs().max(1.0),
        Bound::Open(m) => m,
    };
    let above = match key.max {
        Bound::Closed(m) => m * 10.0,
        Bound::Open(m) => m,
    };
    [below, above, f64::NAN]
}

/// The refusal text of `key` for `value`: what every boundary prints after
/// the name it was given under.
fn refusal(key: &str, value: f64) -> String {
    check(key, value)
        .expect_err("outside the range")
        .to_string()
}

/// `v` as TOML spells it (`nan`; Rust's `{:?}` round-trips the rest).
fn toml_number(v: f64) -> String {
    if v.is_nan() {
        "nan".into()
    } else {
        format!("{v:?}")
    }
}

/// A minimal valid scene with scene key `key` set to `v`, and where the
/// refusal is reported (`at`, and the words before the refusal). A profile's
/// key (`inputs.v_m[]`, `….t` for its times) sets its one knot.
fn scene_with(key: &str, v: f64) -> (String, String, &'static str) {
    let v = toml_number(v);
    let mut inputs = [
        ("v_m", "[[0.0, 8.0]]".to_string()),
        ("t_u", "[[0.0, 6.0]]".to_string()),
    ];
    let (mut top, mut sections) = (String::from("duration_s = 1.0\n"), String::new());
    let profile = match key.strip_suffix("[].t") {
        Some(p) => Some((p, format!("[[{v}, 0.0]]"), "knot 0: time ")),
        None => key
            .strip_suffix("[]")
            .map(|p| (p, format!("[[0.0, {v}]]"), "knot 0: value ")),
    };
    let (at, words) = if let Some((profile, knot, words)) = profile {
        let (section, field) = profile.split_once('.').expect("section.field");
        match inputs
            .iter_mut()
            .find(|(name, _)| section == "inputs" && *name == field)
        {
            Some(slot) => slot.1 = knot,
            // controller.r_schedule: a schedule only law "none" reads
            None => sections = format!("[{section}]\nlaw = \"none\"\n{field} = {knot}\n"),
        }
        (format!("{profile}[0]"), words)
    } else if let Some((section, field)) = key.split_once('.') {
        sections = format!("[{section}]\n{field} = {v}\n");
        (key.to_string(), "")
    } else {
        top = format!("{key} = {v}\n");
        (key.to_string(), "")
    };
    let [(_, v_m), (_, t_u)] = inputs;
    let text = format!("{top}[inputs]\nv_m = {v_m}\nt_u = {t_u}\n{sections}");
    (text, at, words)
}

/// Every scene key, on both sides of its range and NaN, refused by the
/// scene parser under its key with the table's text.
#[test]
fn every_scene_key_is_refused_by_the_scene() {
    let (base, _, _) = scene_with("duration_s", 1.0);
    Scene::parse(&base, "s.toml").expect("the base scene is valid");
    for key in KEYS.iter().filter(|k| k.scene) {
        for v in outside(key) {
            let (text, at, words) = scene_with(key.name, v);
            let e = Scene::parse(&text, "s.toml")
                .expect_err(&format!("{} = {v} accepted", key.name))
                .to_string();
            let want = format!("`{at}` {words}{}", refusal(key.name, v));
            assert!(e.ends_with(&want), "{}: got {e}, want …{want}", key.name);
        }
    }
}

/// Commands that take CLI alias `(flag, key)`, with `{}` where its value goes.
fn commands(flag: &str, key: &str, log: &str, scene: &str) -> Vec<Vec<String>> {
    let point = ["--vm=8", "--tu=1.5"];
    let with = |head: &[&str], rest: &[&str]| -> Vec<String> {
        head.iter()
            .chain(rest)
            .map(|s| s.to_string())
            .chain([format!("{flag}={{}}")])
            .collect()
    };
    let replay = with(&["ctrl", "replay", log], &[]);
    match (flag, key) {
        ("--theta-ct", _) => vec![with(&["kin", "sgivt-ratio"], &[])],
        ("--r-mm" | "--l1-mm" | "--r-output-mm", _) => vec![with(&["kin", "givt-ratio"], &[])],
        ("--tolerance" | "--corner-deg", _) => vec![with(&["kin", "arcs"], &[])],
        ("--r-sun" | "--r-planet", _) => vec![with(&["kin", "direction"], &[])],
        ("--vm", _) => vec![
            with(&["ol", "solve", "--tu=1.5"], &[]),
            with(&["stability", "--tu=1.5"], &[]),
            replay,
        ],
        ("--tu", _) => vec![
            with(&["ol", "solve", "--vm=8"], &[]),
            with(&["stability", "--vm=8"], &[]),
            replay,
        ],
        ("--vm-from" | "--vm-to" | "--tu-from" | "--tu-to", _) => {
            vec![with(&["ol", "table", "--quiet"], &[])]
        }
        ("--omega0-rpm", _) => vec![
            with(&["ol", "solve"], &point),
            with(&["ol", "fit", "--quiet"], &[]),
            with(&["stability"], &point),
            with(&["stability-map"], &[]),
            replay,
        ],
        ("--k" | "--k2", "controller.k_si" | "controller.k2_si") => {
            vec![with(&["stability", "--si"], &point)]
        }
        ("--k" | "--k2", _) => vec![with(&["stability"], &point), replay],
        ("--k-prop", _) => vec![
            replay,
            with(&["rig", "commission", "--sim", "--out", "unused.mcap"], &[]),
        ],
        ("--prop-period" | "--f-timer" | "--stall-timeout", _) => vec![replay],
        // checked before the port is opened
        ("--f-timer-hz", _) => vec![
            with(
                &[
                    "rig",
                    "record",
                    "--port",
                    "/dev/null",
                    "--out",
                    "unused.mcap",
                ],
                &[],
            ),
            with(
                &[
                    "rig",
                    "commission",
                    "--port",
                    "/dev/null",
                    "--out",
                    "unused.mcap",
                ],
                &[],
            ),
        ],
        ("--max-events", _) => vec![with(&["sim", scene], &[])],
        _ => vec![],
    }
}

/// Every flag of the table has a command here.
#[test]
fn every_cli_alias_has_a_command() {
    for a in ALIASES.iter().filter(|a| a.boundary == Boundary::Cli) {
        assert!(
            !commands(a.name, a.key, "log", "scene").is_empty(),
            "{a:?} has no command in tests/boundary.rs"
        );
    }
}

// Every CLI flag, out of range on both sides and NaN, is refused as input
// with `{flag} {refusal}` (the flag and the value as typed; for a scene's
// quantity the very text the scene prints after its key).
#[test]
fn every_cli_flag_is_refused_with_the_tables_text() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/drive.toml");
    let dir = tmp("boundary");
    let log = replay_log(&dir);
    let _serial = serial();
    for a in ALIASES.iter().filter(|a| a.boundary == Boundary::Cli) {
        let key = ivt_kin::params::find(a.key).expect("alias of a key");
        for v in outside(key) {
            let shown = ivt_kin::params::Typed(v).to_string();
            let text = refusal(a.key, v);
            if key.scene {
                let (toml, _, _) = scene_with(a.key, v);
                let e = Scene::parse(&toml, "s.toml").unwrap_err().to_string();
                assert!(e.ends_with(&text), "scene {}: {e} vs {text}", a.key);
            }
            for argv in commands(a.name, a.key, &log, scene) {
                let mut args: Vec<String> = vec!["--json".into()];
                args.extend(argv.iter().map(|s| s.replace("{}", &shown)));
                let refs: Vec<&str> = args.iter().map(String::as_str).collect();
                let (code, obj) = contract(&refs, QUICK).unwrap();
                assert_eq!(code, 2, "{refs:?}: {obj}");
                assert_eq!(obj["kind"], "input", "{refs:?}: {obj}");
                assert_eq!(
                    obj["error"].as_str().unwrap(),
                    format!("{} {text}", a.name),
                    "{refs:?}"
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The GIVT's r < l1 (Eq. 8 divides by |l1 − r|) is relational, so not a
/// range: refused naming both flags in the unit typed (it was reported in
/// metres as `r`); the widest l1 of the table still gives a finite answer.
#[test]
fn givt_r_below_l1_in_the_unit_typed() {
    let _serial = serial();
    let (code, obj) = contract(&["--json", "kin", "givt-ratio", "--r-mm", "60"], QUICK).unwrap();
    assert_eq!(code, 2);
    assert_eq!(
        obj["error"],
        "--r-mm = 60 mm is out of domain: must be < --l1-mm = 50 mm (Eq. 8 divides by |l1 − r|)"
    );
    let args = ["--json", "kin", "givt-ratio", "--l1-mm", "1000"];
    let (code, obj) = contract(&args, QUICK).unwrap();
    assert_eq!(code, 0, "{obj}");
    let avg = obj["average_module_ratio"].as_f64().unwrap();
    assert!(avg.is_finite() && avg > 0.0, "{obj}");
}
