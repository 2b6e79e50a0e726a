//! The "Outputs:" examples of issue #30, from the outside: every file the CLI
//! writes goes through the one output writer (`ivt_sim::atomic`), so a device
//! or a symlink is never replaced or written through, a failed figure leaves
//! the old one whole, concurrent runs into one directory all succeed, an
//! interrupted `--json` run prints one JSON error and removes what it
//! created, and `--version`/`help` answer in JSON under `--json`.
// A test may panic and unwrap (the package's panic lints guard library code).
#![allow(clippy::panic, clippy::unwrap_used)]

use ivt_sim::testing::{listing, scratch_dir};
use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const IVT: &str = env!("CARGO_BIN_EXE_ivt");

/// Exit code and the one JSON object on stdout of `ivt --json ARGS`.
fn json_run(args: &[&str]) -> (Option<i32>, Value, String) {
    let out = Command::new(IVT).arg("--json").args(args).output().unwrap();
    parse(&out)
}

fn parse(out: &Output) -> (Option<i32>, Value, String) {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let mut objects = serde_json::Deserializer::from_str(&stdout).into_iter::<Value>();
    let v = objects
        .next()
        .unwrap_or_else(|| panic!("no JSON object: {stdout:?} {stderr}"))
        .unwrap();
    assert!(objects.next().is_none(), "more than one object: {stdout}");
    (out.status.code(), v, stderr)
}

/// A short scene asking for MCAP, CSV, summary and plots.
fn short_scene(dir: &Path) -> String {
    let scene = dir.join("short.toml");
    std::fs::write(
        &scene,
        "name = \"short\"\nduration_s = 1.0\n[inputs]\nv_m = [[0.0, 8.6]]\nt_u = [[0.0, 6.0]]\n\
         [initial]\nomega = 10.0\n[outputs]\nsummary = true\nmcap = true\ncsv = true\n\
         plots = [\"omega_a\", \"r\"]\n[[outputs.channels]]\nname = \"control\"\nevery = 10\n",
    )
    .unwrap();
    scene.to_str().unwrap().to_string()
}

/// `ivt --json ol fit --emit-rust /dev/full` used to exit 0 and replace the
/// device by a regular file: now exit 2 and the device stays; a symlink is not
/// written through; a regular path is written whole.
#[cfg(unix)]
#[test]
fn emitted_rust_never_replaces_a_device_or_follows_a_symlink() {
    use std::os::unix::fs::FileTypeExt as _;
    let (code, v, _) = json_run(&["ol", "fit", "--emit-rust", "/dev/full"]);
    assert_eq!(code, Some(2), "{v}");
    assert_eq!(v["kind"], "io", "{v}");
    let e = v["error"].as_str().unwrap();
    assert!(
        e.contains("/dev/full") && e.contains("not a regular file"),
        "{v}"
    );
    let meta = std::fs::symlink_metadata("/dev/full").unwrap();
    assert!(meta.file_type().is_char_device());

    let dir = scratch_dir("outputs-emit");
    let victim = dir.join("victim.rs");
    std::fs::write(&victim, "// keep").unwrap();
    std::os::unix::fs::symlink(&victim, dir.join("law.rs")).unwrap();
    let link = dir.join("law.rs");
    let (code, v, _) = json_run(&["ol", "fit", "--emit-rust", link.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{v}");
    assert!(
        v["error"].as_str().unwrap().contains("symbolic link"),
        "{v}"
    );
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "// keep");
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());

    let real = dir.join("real.rs");
    let (code, v, _) = json_run(&["ol", "fit", "--emit-rust", real.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{v}");
    assert!(std::fs::read_to_string(&real).unwrap().contains("REFIT"));
    assert_eq!(listing(&dir), ["law.rs", "real.rs", "victim.rs"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--plot` used to write the PNG in place: under a file-size limit an
/// existing figure was left truncated. Now the figure is drawn into a staged
/// file: the write fails (EFBIG; SIGXFSZ ignored as `trap '' XFSZ` does), the
/// command exits 2 and the old figure is whole, with no temporary file left.
#[cfg(unix)]
#[test]
fn a_failed_figure_leaves_the_old_one_whole() {
    let dir = scratch_dir("outputs-plot");
    let fig = dir.join("fig.png");
    std::fs::write(&fig, "the old figure").unwrap();
    let out = Command::new("sh")
        .args([
            "-c",
            "trap '' XFSZ; ulimit -f 16; exec \"$0\" \"$@\"",
            IVT,
            "--json",
            "hb",
            "duffing",
            "--plot",
            fig.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let (code, v, _) = parse(&out);
    assert_eq!(code, Some(2), "{v}");
    assert!(v["error"].as_str().unwrap().contains("fig.png"), "{v}");
    assert_eq!(std::fs::read_to_string(&fig).unwrap(), "the old figure");
    assert_eq!(listing(&dir), ["fig.png"]);
    // without the limit the figure is replaced by a PNG
    let (code, v, _) = json_run(&["hb", "duffing", "--plot", fig.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{v}");
    assert!(std::fs::read(&fig).unwrap().starts_with(b"\x89PNG"));
    assert_eq!(listing(&dir), ["fig.png"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scene output that is a symlink (or a device) is refused before the run
/// writes anything; `--out` naming a regular file is an `io` error.
#[cfg(unix)]
#[test]
fn sim_outputs_are_never_written_through_a_symlink() {
    let dir = scratch_dir("outputs-sim-symlink");
    let scene = short_scene(&dir);
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    let victim = dir.join("victim.mcap");
    std::fs::write(&victim, "keep").unwrap();
    std::os::unix::fs::symlink(&victim, out.join("short.mcap")).unwrap();
    let (code, v, _) = json_run(&["sim", &scene, "--out", out.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{v}");
    assert!(
        v["error"].as_str().unwrap().contains("symbolic link"),
        "{v}"
    );
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
    assert_eq!(listing(&out), ["short.mcap"]);

    let file = dir.join("not-a-dir");
    std::fs::write(&file, "x").unwrap();
    let (code, v, _) = json_run(&["sim", &scene, "--out", file.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{v}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Four runs at once into one (new) directory: every run succeeds, the
/// directory holds exactly one complete set and no temporary file.
#[test]
fn concurrent_runs_into_one_directory_all_succeed() {
    let dir = scratch_dir("outputs-concurrent");
    let scene = short_scene(&dir);
    let out = dir.join("shared").join("out");
    let out_arg = out.to_str().unwrap().to_string();
    let children: Vec<_> = (0..4)
        .map(|_| {
            Command::new(IVT)
                .args(["--json", "sim", &scene, "--out", &out_arg])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    for child in children {
        let (code, v, err) = parse(&child.wait_with_output().unwrap());
        assert_eq!(code, Some(0), "{v} {err}");
        assert_eq!(v["outputs"].as_array().unwrap().len(), 4, "{v}");
    }
    assert_eq!(
        listing(&out),
        [
            "short.mcap",
            "short.png",
            "short_control.csv",
            "short_summary.json"
        ]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// SIGINT during `ivt --json sim`: one `{"error", "kind": "interrupted"}`
/// object on stdout, exit 130 (the shell's 128 + SIGINT, as without
/// `--json`; issue 43), and the output directory the run created is gone
/// with its staged files.
#[cfg(unix)]
#[test]
fn interrupted_json_sim_prints_one_error_and_removes_its_directory() {
    let dir = scratch_dir("outputs-sigint");
    let long = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/drive.toml"))
        .unwrap()
        .replace("duration_s = 60.0", "duration_s = 1800.0");
    let scene = dir.join("long.toml");
    std::fs::write(&scene, long).unwrap();
    let out = dir.join("made").join("by").join("run");
    let child = Command::new(IVT)
        .args(["--json", "sim", scene.to_str().unwrap(), "--out"])
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !out.exists() || listing(&out).is_empty() {
        assert!(t0.elapsed() < Duration::from_secs(60), "no staged output");
        std::thread::sleep(Duration::from_millis(10));
    }
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let (code, v, _) = parse(&child.wait_with_output().unwrap());
    assert_eq!(code, Some(130), "{v}");
    assert_eq!(v["kind"], "interrupted", "{v}");
    assert!(v["error"].as_str().unwrap().contains("interrupted"), "{v}");
    assert_eq!(
        listing(&dir),
        ["long.toml"],
        "the run's directories are removed"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `ivt --json --version`, `ivt --json help` and `ivt --json --help` print
/// one JSON object (they printed text).
#[test]
fn version_and_help_answer_in_json() {
    let (code, v, _) = json_run(&["--version"]);
    assert_eq!(code, Some(0));
    assert_eq!(v["name"], "ivt");
    assert_eq!(v["version"], env!("CARGO_PKG_VERSION"));
    for args in [&["help"][..], &["--help"], &["sim", "--help"]] {
        let (code, v, _) = json_run(args);
        assert_eq!(code, Some(0), "{args:?}");
        assert!(
            v["help"].as_str().unwrap().contains("Usage:"),
            "{args:?}: {v}"
        );
    }
    // without --json: text, as before
    let out = Command::new(IVT).arg("--version").output().unwrap();
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        format!("ivt {}", env!("CARGO_PKG_VERSION"))
    );
}
