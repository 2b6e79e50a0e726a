//! Issue 43, part A: one output stage that knows the run's inputs. No
//! output replaces a file the run read — compared by device and inode, so a
//! hard link or another spelling of its path is caught too, and an output
//! that does not exist yet is never one; `rig identify` writes its plant
//! file and figures all or none, refuses a symlinked figure, and escapes the
//! recording's path in the plant file's comment; a file that cannot be
//! written is kind `io`.
// A test may index and unwrap (the package's panic lints guard library code).
#![allow(
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic,
    clippy::unwrap_used
)]

#[path = "common/rig.rs"]
mod rig;

use ivt_sim::testing::{listing, scratch_dir};
use rig::{commission_sim, ivt};
use serde_json::Value;
use std::path::Path;

/// A commissioning recording of the printed plant (every sequence, ideal
/// sensors) at `dir/name`.
fn recording(dir: &Path, name: &str) -> std::path::PathBuf {
    let plant = dir.join("rig_plant.toml");
    std::fs::write(&plant, "[plant]\n").unwrap();
    let out = dir.join(name);
    let (code, v) = commission_sim(&plant, &out, &[]);
    assert_eq!(code, 0, "{v}");
    std::fs::remove_file(&plant).unwrap();
    out
}

/// `ivt --json ARGS` must refuse with kind `io` naming `what`.
fn refused_io(args: &[&str], what: &str) -> Value {
    let (code, v) = ivt(args);
    assert_eq!(code, 2, "{args:?}: {v}");
    assert_eq!(v["kind"], "io", "{args:?}: {v}");
    assert!(v["error"].as_str().unwrap().contains(what), "{args:?}: {v}");
    v
}

/// `rig identify run.mcap --out run.mcap` replaced the recording with a
/// plant file; a recording named like a figure was replaced by the figure.
/// The same file under another name (a hard link, `./`) is the input too.
/// Nothing is written when one output is refused.
#[test]
fn identify_never_replaces_its_recording() {
    let dir = scratch_dir("outputs43-identify");
    let rec = recording(&dir, "run.mcap");
    let bytes = std::fs::read(&rec).unwrap();
    let r = rec.to_str().unwrap();
    refused_io(
        &["rig", "identify", r, "--out", r],
        "is an input of this run",
    );
    let dotted = dir.join(".").join("run.mcap");
    refused_io(
        &["rig", "identify", r, "--out", dotted.to_str().unwrap()],
        "is an input of this run",
    );
    let link = dir.join("hard-link.toml");
    std::fs::hard_link(&rec, &link).unwrap();
    refused_io(
        &["rig", "identify", r, "--out", link.to_str().unwrap()],
        "is an input of this run",
    );
    std::fs::remove_file(&link).unwrap();
    // a recording named like one of the figures
    let fig = dir.join("fig47_average_ratio.png");
    std::fs::rename(&rec, &fig).unwrap();
    let plant = dir.join("plant.toml");
    refused_io(
        &[
            "rig",
            "identify",
            fig.to_str().unwrap(),
            "--out",
            plant.to_str().unwrap(),
        ],
        "fig47_average_ratio.png: is an input of this run",
    );
    assert_eq!(
        std::fs::read(&fig).unwrap(),
        bytes,
        "the recording is intact"
    );
    assert_eq!(
        listing(&dir),
        ["fig47_average_ratio.png"],
        "nothing written"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The plant file was written before the figures, so a refused figure left
/// it behind; a figure target that is a symlink was replaced. Now the plant
/// file and the figures are one set: a symlinked (or directory) figure is
/// refused, nothing is written, the symlink and its target are untouched.
#[test]
fn identify_writes_all_or_none_and_never_through_a_symlink() {
    let dir = scratch_dir("outputs43-all-or-none");
    let rec = recording(&dir, "run.mcap");
    let figs = dir.join("figs");
    std::fs::create_dir(&figs).unwrap();
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, "keep").unwrap();
    std::os::unix::fs::symlink(&victim, figs.join("fig48_speed_over_theta_in.png")).unwrap();
    let plant = dir.join("plant.toml");
    let args = |figs: &Path| {
        vec![
            "rig".to_string(),
            "identify".into(),
            rec.to_str().unwrap().into(),
            "--out".into(),
            plant.to_str().unwrap().into(),
            "--figures".into(),
            figs.to_str().unwrap().into(),
        ]
    };
    let a = args(&figs);
    let refs: Vec<&str> = a.iter().map(String::as_str).collect();
    refused_io(&refs, "symbolic link");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
    assert!(!plant.exists(), "the plant file is not left behind");
    assert_eq!(listing(&figs), ["fig48_speed_over_theta_in.png"]);
    // a figure that is a directory: refused the same way
    std::fs::remove_file(figs.join("fig48_speed_over_theta_in.png")).unwrap();
    std::fs::create_dir(figs.join("fig50_motor_speed.png")).unwrap();
    refused_io(&refs, "a directory");
    assert!(!plant.exists());
    // figures into a directory the run creates, removed when it fails
    let made = dir.join("made").join("figs");
    std::fs::write(&plant, "not a plant: replaced only on success").unwrap();
    let a = args(&made);
    let refs: Vec<&str> = a.iter().map(String::as_str).collect();
    let (code, v) = ivt(&refs);
    assert_eq!(code, 0, "{v}");
    assert_eq!(
        listing(&made),
        [
            "fig47_average_ratio.png",
            "fig48_speed_over_theta_in.png",
            "fig50_motor_speed.png"
        ]
    );
    assert!(std::fs::read_to_string(&plant)
        .unwrap()
        .starts_with("# Identified"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The recording's path was pasted raw into the plant file's comment: a
/// newline in it started a line of its own (`[controller]` here). It is
/// written as a quoted, escaped string: one comment line, and the file reads
/// back as a plant file.
#[test]
fn the_recordings_path_is_escaped_in_the_plant_file() {
    let dir = scratch_dir("outputs43-escape");
    let rec = recording(&dir, "run\n[controller]\nx = \"1\".mcap");
    let plant = dir.join("plant.toml");
    let (code, v) = ivt(&[
        "rig",
        "identify",
        rec.to_str().unwrap(),
        "--out",
        plant.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{v}");
    let text = std::fs::read_to_string(&plant).unwrap();
    let first = text.lines().next().unwrap();
    assert!(
        first.starts_with("# Identified by `ivt rig identify \"")
            && first.contains(r#"run\n[controller]\nx = \"1\".mcap"#),
        "{text}"
    );
    assert_eq!(text.lines().filter(|l| l.starts_with('#')).count(), 1);
    assert!(
        !text.lines().any(|l| l.starts_with("[controller]")),
        "{text}"
    );
    let (code, v) = ivt(&[
        "ol",
        "solve",
        "--vm",
        "8",
        "--tu",
        "4",
        "--plant-file",
        plant.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{v}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Every command with an output refuses one that is an input of the same
/// run: `rig commission --sim --plant-file p.toml --out p.toml` replaced the
/// plant file; the replay's CSV, the emitted Rust, a stability map's figure
/// and a scene's outputs likewise. The inputs stay as they were.
#[test]
fn no_output_replaces_an_input_of_the_same_run() {
    let dir = scratch_dir("outputs43-inputs");
    let plant = dir.join("p.toml");
    std::fs::write(&plant, "[plant]\nk_t = 0.7\n").unwrap();
    let p = plant.to_str().unwrap();
    let log = dir.join("log.csv");
    std::fs::write(&log, "ticks\n100\n50100\n100100\n").unwrap();
    let l = log.to_str().unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec!["rig", "commission", "--sim", "--plant-file", p, "--out", p],
        vec!["ctrl", "replay", l, "--out", l],
        vec!["ol", "fit", "--quiet", "--plant-file", p, "--emit-rust", p],
        vec![
            "stability-map",
            "--plant-file",
            p,
            "--vm",
            "8",
            "1",
            "8",
            "--tu",
            "4",
            "1",
            "4",
            "--plot",
            p,
        ],
    ];
    for args in &cases {
        refused_io(args, "is an input of this run");
    }
    assert_eq!(
        std::fs::read_to_string(&plant).unwrap(),
        "[plant]\nk_t = 0.7\n"
    );
    assert_eq!(
        std::fs::read_to_string(&log).unwrap(),
        "ticks\n100\n50100\n100100\n"
    );
    // a scene kept where its own summary goes
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    let scene = out.join("s_summary.json");
    let text = "name = \"s\"\nduration_s = 0.5\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n\
                [outputs]\nsummary = true\n";
    std::fs::write(&scene, text).unwrap();
    refused_io(
        &[
            "sim",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        "is an input of this run",
    );
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
    assert_eq!(listing(&out), ["s_summary.json"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// I/O failures carry kind `io` (they were `failed` or `input`): an output
/// that is a directory or a file where a directory goes, a port that does
/// not exist, a missing or directory plant file.
#[test]
fn files_that_cannot_be_written_or_read_are_kind_io() {
    let dir = scratch_dir("outputs43-kinds");
    let file = dir.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let f = file.to_str().unwrap();
    let d = dir.to_str().unwrap();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/steady_state.toml");
    let missing = dir.join("missing.toml");
    let m = missing.to_str().unwrap();
    for (args, what) in [
        (
            vec![
                "rig",
                "commission",
                "--sim",
                "--sequence",
                "hold",
                "--out",
                d,
            ],
            "is a directory",
        ),
        (
            vec![
                "rig",
                "commission",
                "--port",
                "/dev/ttyNOPE",
                "--out",
                "x.mcap",
            ],
            "/dev/ttyNOPE",
        ),
        (
            vec!["rig", "record", "--port", "/dev/ttyNOPE", "--out", "x.mcap"],
            "/dev/ttyNOPE",
        ),
        (vec!["sim", scene, "--out", f], "is not a directory"),
        (
            vec!["reproduce", "--quick", "--out", f],
            "is not a directory",
        ),
        (
            vec!["ol", "solve", "--vm", "8", "--tu", "4", "--plant-file", m],
            "missing.toml",
        ),
        (
            vec!["ol", "solve", "--vm", "8", "--tu", "4", "--plant-file", d],
            "a directory",
        ),
        (
            vec!["stability", "--vm", "8", "--tu", "4", "--plant-file", m],
            "missing.toml",
        ),
        (
            vec![
                "rig",
                "commission",
                "--sim",
                "--plant-file",
                d,
                "--out",
                "x.mcap",
            ],
            "a directory",
        ),
        (vec!["sim", m], "missing.toml"),
        (vec!["rig", "identify", m], "missing.toml"),
    ] {
        refused_io(&args, what);
    }
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
    assert!(!Path::new("x.mcap").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
