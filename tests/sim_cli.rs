//! `ivt sim` from the outside: the JSON contract of SPEC §6 and one-line
//! scene errors with exit status 2 (never a panic).
// A test may unwrap (the package's panic lints guard library code).
#![allow(clippy::unwrap_used)]

use std::process::Command;

fn ivt(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn tmp(name: &str) -> ivt_sim::testing::Scratch {
    ivt_sim::testing::scratch_dir(&format!("sim-cli-{name}"))
}

#[test]
fn sim_json_has_summary_and_outputs() {
    let dir = tmp("ok");
    let scene = dir.join("s.toml");
    std::fs::write(
        &scene,
        "name = \"short\"\nduration_s = 2.0\n[inputs]\nv_m = [[0.0, 8.6]]\nt_u = [[0.0, 6.0]]\n\
         [initial]\nomega = 10.0\n[outputs]\nsummary = true\nmcap = true\n\
         [[outputs.channels]]\nname = \"control\"\nevery = 50\n",
    )
    .unwrap();
    let out = dir.join("out");
    let (code, stdout, _) = ivt(&[
        "sim",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0);
    assert_eq!(stdout.trim().lines().count(), 1, "{stdout}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert!(v["summary"]["pulses"].as_u64().unwrap() > 1000);
    let outputs = v["outputs"].as_array().unwrap();
    assert_eq!(outputs.len(), 2);
    for p in outputs {
        assert!(std::path::Path::new(p.as_str().unwrap()).exists());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scene_errors_are_one_line_with_status_2() {
    let dir = tmp("bad");
    let cases = [
        ("unknown.toml", "duration_s = 1.0\ncolour = 3\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n", "colour"),
        ("type.toml", "duration_s = \"x\"\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n", "duration_s"),
        ("neg.toml", "duration_s = -3.0\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n", "duration_s"),
        ("order.toml", "duration_s = 1.0\n[inputs]\nv_m = [[1.0, 8.0], [0.5, 8.0]]\nt_u = [[0.0, 4.0]]\n", "inputs.v_m"),
        ("range.toml", "duration_s = 1.0\n[inputs]\nv_m = [[0.0, 8.0]]\nt_u = [[0.0, 4.0]]\n[stepper]\nmiss_prob = 2.0\n", "stepper.miss_prob"),
    ];
    for (file, src, key) in cases {
        let p = dir.join(file);
        std::fs::write(&p, src).unwrap();
        let (code, stdout, stderr) = ivt(&["sim", p.to_str().unwrap(), "--json"]);
        assert_eq!(code, 2, "{file}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert_eq!(stdout.trim().lines().count(), 1);
        let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        let msg = v["error"].as_str().unwrap();
        assert!(msg.contains(key) && !msg.contains('\n'), "{file}: {msg}");
    }
    let (code, _, stderr) = ivt(&["sim", "/nonexistent/scene.toml"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("/nonexistent/scene.toml"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The shipped steady-state scene takes the IHB route (no transient) and says
/// so in the JSON and in the summary file; `--route time_integration` forces
/// the simulation of the same scene; a scene that logs channels cannot be
/// forced onto the IHB route (exit status 1 with a one-line reason).
#[test]
fn steady_state_scene_reports_its_route() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/steady_state.toml");
    let dir = tmp("steady");
    let out = dir.to_str().unwrap();
    let (code, stdout, _) = ivt(&["--json", "sim", scene, "--out", out]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["summary"]["route"], "ihb_steady_state");
    assert_eq!(v["summary"]["steady_state"]["verdict"], "feasible");
    let file: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("steady_state_summary.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(file["route"], "ihb_steady_state");
    let (code, stdout, _) = ivt(&[
        "--json",
        "sim",
        scene,
        "--out",
        out,
        "--route",
        "time_integration",
    ]);
    assert_eq!(code, 0);
    let t: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(t["summary"]["route"], "time_integration");
    assert!(t["summary"]["pulses"].as_u64().unwrap() > 30_000);
    let other = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/load_step_delay.toml");
    let (code, _, stderr) = ivt(&["sim", other, "--out", out, "--route", "ihb_steady_state"]);
    assert_ne!(code, 0);
    assert!(
        stderr.contains("ihb_steady_state") && stderr.lines().count() == 1,
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
