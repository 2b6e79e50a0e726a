//! `ivt hb ...` honours the SPEC §6 JSON contract.
// A test may expect and panic (the package's panic lints guard library code).
#![allow(clippy::expect_used, clippy::panic)]

use std::process::Command;

/// Runs `ivt` with the whitespace-separated arguments of `cmd_line`.
fn run(cmd_line: &str) -> (i32, serde_json::Value) {
    run_args(&cmd_line.split_whitespace().collect::<Vec<_>>())
}

/// Runs `ivt` with `args` (one may be a path holding spaces).
fn run_args(args: &[&str]) -> (i32, serde_json::Value) {
    let out = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .args(args)
        .output()
        .expect("binary runs");
    let text = String::from_utf8(out.stdout).expect("utf-8");
    let value = serde_json::from_str(text.trim())
        .unwrap_or_else(|e| panic!("one JSON object, got {text:?}: {e}"));
    (out.status.code().unwrap_or(-1), value)
}

#[test]
fn duffing_json_keys() {
    let (code, v) = run("--json hb duffing");
    assert_eq!(code, 0);
    for key in [
        "coeffs",
        "iterations",
        "residual_norm",
        "solve_time_s",
        "floquet",
        "stable",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    assert_eq!(v["coeffs"].as_array().unwrap().len(), 41); // a0, a1..a20, b1..b20
    assert!(v["residual_norm"].as_f64().unwrap() <= 1e-10);
    assert_eq!(v["stable"], true);
    let (code, v) = run("--json hb duffing --method classic");
    assert_eq!(code, 0, "{v}");
}

#[test]
fn bad_input_is_a_json_error() {
    let (code, v) = run("--json hb duffing --samples 10");
    assert_eq!(code, 2);
    assert!(v["error"].as_str().unwrap().contains("N > n"));
}

#[test]
fn frc_and_mathieu_json_keys() {
    let (code, v) = run("--json hb duffing-frc --from 0.2 --to 3.0");
    assert_eq!(code, 0);
    let p = &v["points"][0];
    assert!(p.get("omega").is_some() && p.get("amplitude").is_some() && p.get("stable").is_some());
    // Folds located by the extended system: the shooting values (ivt-hb
    // tests/frc.rs checks them against its own shooting to 1e-8).
    let folds = v["folds"].as_array().unwrap();
    assert_eq!(folds.len(), 2, "{folds:?}");
    for (f, want) in folds.iter().zip([1.6548121, 1.1687244]) {
        assert!((f.as_f64().unwrap() - want).abs() < 1e-7, "{f} vs {want}");
    }
    let (code, v) = run("--json hb mathieu-duffing");
    assert_eq!(code, 0);
    let betas = v["period_doubling_beta"].as_array().unwrap();
    assert_eq!(betas.len(), 3);
    // Thesis §3.2.5 to its printed digits: β2, β4 within half a unit, β1
    // (4.82577) within one (crates/ivt-hb/tests/mathieu.rs).
    for ((b, want), tol) in betas
        .iter()
        .zip([4.825, 5.194, 5.253])
        .zip([1e-3, 5e-4, 5e-4])
    {
        let b = b.as_f64().unwrap();
        assert!((b - want).abs() <= tol, "β = {b} vs thesis {want}");
    }
}

#[test]
fn string_json_keys_and_png_plot() {
    // SPEC §6: points [{omega, norm, stable}]; --plot writes a PNG.
    let png = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_hb_string.png");
    let _ = std::fs::remove_file(&png);
    let mut args: Vec<&str> = "--json hb string --kd 30 --from 3 --to 5 --plot"
        .split_whitespace()
        .collect();
    args.push(png.to_str().unwrap());
    let (code, v) = run_args(&args);
    assert_eq!(code, 0, "{v}");
    let pts = v["points"].as_array().unwrap();
    assert!(pts.len() > 10);
    for p in pts {
        assert!(p["omega"].is_f64() && p["norm"].is_f64() && p["stable"].is_boolean());
    }
    // k_d = 30: the middle branch between the folds is unstable (Fig. 35).
    assert!(pts.iter().any(|p| p["stable"] == false));
    let bytes = std::fs::read(&png).expect("plot written");
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    // IHDR: width and height as drawn by ivt-plot (1000 × 640).
    assert_eq!(&bytes[12..16], b"IHDR");
    assert_eq!(u32::from_be_bytes(bytes[16..20].try_into().unwrap()), 1000);
    assert_eq!(u32::from_be_bytes(bytes[20..24].try_into().unwrap()), 640);
}

#[test]
fn string_spring_boundary_reports_stability() {
    // The spring boundary is no longer `"stable": null`; k0 = 1e4 behaves like
    // fixed–fixed (unstable points between the folds of the k_d = 30 curve).
    let (code, v) = run("--json hb string --boundary spring --k0 10000 --kd 30 --from 3 --to 5");
    assert_eq!(code, 0, "{v}");
    let pts = v["points"].as_array().unwrap();
    assert!(pts.iter().all(|p| p["stable"].is_boolean()));
    assert!(pts.iter().any(|p| p["stable"] == false));
    assert!(pts.iter().any(|p| p["stable"] == true));
    // Eq. 132 as printed is a negative spring for k0 > 1: said so in the output.
    assert!(v["boundary_note"]
        .as_str()
        .unwrap()
        .contains("negative spring"));
}

#[test]
fn string_cold_start_on_the_peak_flank_says_how_to_start() {
    // k_d = 30: ω = 4 is on the flank of the hardening peak (folds near 4.29
    // and 4.44), where Newton from a = 0 does not reach the large-amplitude
    // solution; the error carries the residual history and the remedy.
    let (code, v) = run("--json hb string --kd 30 --modes 5 --harmonics 19 --from 4 --to 4.6");
    assert_eq!(code, 2, "{v}");
    let msg = v["error"].as_str().unwrap();
    assert!(
        msg.contains("residual norms") && msg.contains("start below the resonance"),
        "{msg}"
    );
}

/// `ivt hb duffing-folds`: the fold curve of the thesis Duffing in (ω, F)
/// through the cusp, and both folds at each F of `--at`. References by
/// shooting in crates/ivt-hb/tests/fold_curve.rs: folds at F = 0.2 at
/// ω = 1.2589591460 and 2.2115927040, at F = 0.3 at 1.3297591465 and
/// 2.6572119678, the cusp at F = 0.0120510724.
#[test]
fn duffing_folds_reach_the_cusp() {
    let (code, v) = run("--json hb duffing-folds --n 15 --at 0.2,0.3");
    assert_eq!(code, 0, "{v}");
    assert_eq!(v["kind"], "fold");
    assert_eq!(v["termination"], "left_interval");
    let special = v["special"].as_array().unwrap();
    assert_eq!(special.len(), 1);
    assert_eq!(special[0]["kind"], "cusp");
    let f = special[0]["p"].as_f64().unwrap();
    assert!((f / 0.0120510724 - 1.0).abs() < 1e-6, "{f}");
    let mut at: Vec<(f64, f64)> = v["at"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| (a["p"].as_f64().unwrap(), a["omega"].as_f64().unwrap()))
        .collect();
    at.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert_eq!(at.len(), 4, "{at:?}");
    let want = [
        (0.2, 1.2589591460),
        (0.2, 2.2115927040),
        (0.3, 1.3297591465),
        (0.3, 2.6572119678),
    ];
    for ((force, omega), (f, w)) in at.iter().zip(want) {
        assert!(
            *force == f && (omega - w).abs() < 1e-7,
            "F = {force}: {omega} vs {w}"
        );
    }
}

/// `ivt hb limit-cycle`: the Van der Pol cycle at μ = 1 has the period
/// 6.6632868593 (the classical value, e.g. by high-precision shooting; our
/// own shooting check is crates/ivt-hb/tests/limit_cycle.rs) and is stable;
/// differentiating Rayleigh's ÿ − μ(ẏ − ẏ³/3) + y = 0 shows that x = ẏ
/// solves Van der Pol's equation with the same μ, so the periods agree.
#[test]
fn limit_cycles_of_van_der_pol_and_rayleigh() {
    let (code, vdp) = run("--json hb limit-cycle --mu 1");
    assert_eq!(code, 0, "{vdp}");
    let period = vdp["period"].as_f64().unwrap();
    assert!((period - 6.6632868593).abs() < 1e-9, "{period}");
    assert_eq!(vdp["stability"], "stable");
    let (code, ray) = run("--json hb limit-cycle --model rayleigh --mu 1");
    assert_eq!(code, 0, "{ray}");
    let other = ray["period"].as_f64().unwrap();
    assert!((other - period).abs() < 1e-9, "{other} vs {period}");
    let (code, v) = run("--json hb limit-cycle --model duffing");
    assert_eq!((code, v["kind"].as_str()), (2, Some("usage")), "{v}");
}

/// `ivt hb duffing-backbone`: u'' + u + u³ = 0 has ω² = 1 + 3a²/4 + O(a⁴)
/// (Lindstedt); at a1 = 0.1 the rest is below 1e-5.
#[test]
fn duffing_backbone_follows_lindstedt() {
    let (code, v) = run("--json hb duffing-backbone --to 0.1");
    assert_eq!(code, 0, "{v}");
    assert_eq!(v["termination"], "left_interval");
    let last = v["points"].as_array().unwrap().last().unwrap().clone();
    let (a, omega) = (
        last["amplitude"].as_f64().unwrap(),
        last["omega"].as_f64().unwrap(),
    );
    assert!((a - 0.1).abs() < 1e-9, "{a}");
    assert!(
        (omega - (1.0 + 0.75 * a * a).sqrt()).abs() < 1e-5,
        "{omega}"
    );
}

#[test]
fn a_curve_without_a_fold_is_a_json_error() {
    let (code, v) = run("--json hb duffing-folds --force 0.001");
    assert_eq!(code, 2);
    assert!(
        v["error"].as_str().unwrap().contains("no located fold"),
        "{v}"
    );
}

/// `ivt hb vdp-torus`: the Neimark–Sacker curve of the forced Van der Pol
/// oscillator (μ = 0.2) from the point (0.94525643, 0.2). References
/// by shooting in crates/ivt-hb/tests/ns_curve.rs: the NS point at F = 0.3
/// at ω = 0.8980504973, the 1:1 end at F = 0.1924005859.
#[test]
fn vdp_torus_curve_ends_at_the_one_to_one_resonance() {
    let (code, v) = run("--json hb vdp-torus --n 9 --samples 32 --force-to 0.3 --at 0.2,0.3");
    assert_eq!(code, 0, "{v}");
    let words = [&v["kind"], &v["termination"], &v["special"][0]["kind"]];
    assert_eq!(words, ["neimark_sacker", "left_interval", "resonance_1_1"]);
    assert_eq!(v["special"].as_array().map(Vec::len), Some(1));
    // (F, ω) of the 1:1 end and of the two `at` points against shooting.
    let want = [
        (&v["special"][0], 0.1924005859, None),
        (&v["at"][0], 0.2, Some(0.94525643)),
        (&v["at"][1], 0.3, Some(0.8980504973)),
    ];
    for (point, force, omega) in want {
        let got = |key: &str| point[key].as_f64().unwrap_or(f64::NAN);
        assert!((got("p") - force).abs() < 1e-7, "{point}");
        assert!(
            omega.is_none_or(|w| (got("omega") - w).abs() < 1e-7),
            "{point}"
        );
    }
}

/// Every `ivt hb` job that returns a curve, a branch or orbits draws it with
/// `--plot` (small resolutions, to stay quick): a PNG of ivt-plot's size,
/// written through the staged writer (nothing else left in the directory),
/// and the same JSON as without `--plot`.
#[test]
fn every_curve_job_draws_its_picture_with_plot() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_hb_plots");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let jobs = [
        ("duffing", "hb duffing --n 8 --samples 32"),
        ("duffing-frc", "hb duffing-frc --n 8 --samples 32 --events"),
        (
            "duffing-folds",
            "hb duffing-folds --n 8 --samples 32 --at 0.2",
        ),
        ("cycle-branch", "hb cycle-branch --n 10 --samples 48"),
        ("duffing-backbone", "hb duffing-backbone --n 8 --samples 32"),
        ("all-solutions", "hb all-solutions --n 8 --samples 32"),
        ("limit-cycle", "hb limit-cycle --n 12 --samples 48"),
        (
            "string",
            "hb string --modes 3 --harmonics 5 --ns 32 --ms 32 --from 3 --to 4",
        ),
        ("switch", "hb switch --n 6 --samples 24"),
        (
            "vdp-torus",
            "hb vdp-torus --n 7 --samples 24 --force-to 0.25 --at 0.25",
        ),
        ("mathieu-duffing", "hb mathieu-duffing --n 8"),
    ];
    for (name, cmd) in jobs {
        let png = dir.join(format!("{name}.png"));
        let mut args: Vec<&str> = cmd.split_whitespace().collect();
        args.insert(0, "--json");
        let (code, plain) = run_args(&args);
        assert_eq!(code, 0, "{name}: {plain}");
        args.extend(["--plot", png.to_str().unwrap()]);
        let (code, drawn) = run_args(&args);
        assert_eq!(code, 0, "{name}: {drawn}");
        let strip = |mut v: serde_json::Value| {
            for key in ["time_s", "solve_time_s"] {
                v.as_object_mut().map(|o| o.remove(key));
            }
            v
        };
        assert_eq!(
            strip(plain),
            strip(drawn),
            "{name}: --plot changed the answer"
        );
        let bytes = std::fs::read(&png).unwrap_or_else(|e| panic!("{name}: no PNG: {e}"));
        assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "{name}: not a PNG");
        assert_eq!(u32::from_be_bytes(bytes[16..20].try_into().unwrap()), 1000);
        assert_eq!(u32::from_be_bytes(bytes[20..24].try_into().unwrap()), 640);
    }
    let mut left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    left.sort();
    let mut want: Vec<_> = jobs.iter().map(|(n, _)| format!("{n}.png")).collect();
    want.sort();
    assert_eq!(left, want, "only the PNGs, no staged temporary");
}
