//! `ivt reproduce --quick --json` end to end, every row pinned: its verdict,
//! a window for our value, and for each "differs" the test that demonstrates
//! the cause (which must exist). A row that is not listed here, a listed row
//! that is missing, or a "not computable" row that is not declared fails.
//! Every listed figure is drawn (PNG + CSV) or says why not.

mod common;

use std::path::{Path, PathBuf};

const R: &str = "reproduced";
const D: &str = "differs";
const NC: &str = "not computable";

/// One pinned row: section, quantity prefix, verdict, window [lo, hi] on the
/// first number of `ours` (None where `ours` is not a single number), and the
/// demonstrating test of a "differs" (`file::fn`).
struct Pin(
    &'static str,
    &'static str,
    &'static str,
    Option<(f64, f64)>,
    Option<&'static str>,
);

// Report sections.
const KIN: &str = "kinematics";
const HB: &str = "hb";
const STHB: &str = "sthb";
const PR: &str = "design/printed";
const CH4: &str = "design/thesis-ch4";
const DES: &str = "design";
const CL4: &str = "closed_loop/thesis-ch4";
const RIG: &str = "rig";

// Row prefixes too long for one pinned line.
const MU1_MM: &str = "Fig. 42 multiplier (k = 0.01, k2 = 0.02), mm";
const MU1_SI: &str = "Fig. 42 multiplier (k = 0.01, k2 = 0.02), printed";
const MU2_MM: &str = "Fig. 42 multiplier (k = 0.06, k2 = 0.12), mm";
const MU2_SI: &str = "Fig. 42 multiplier (k = 0.06, k2 = 0.12), printed";
const STEP_ERR: &str = "static error of ω_a after V_m 8 → 7 V";
const OPEN_7V: &str = "static error of ω_a with the printed u_ol alone at V_m = 7 V";
const OPEN_8V: &str = "static error of ω_a with the printed u_ol alone at V_m = 8 V";
const ARC_SMOOTH: &str = "Fig. 23(b) arc profiles: max radial deviation away";
const ARC_CORNER: &str = "Fig. 23(b) arc profiles: max radial deviation at";

// The tests that demonstrate each "differs" row's cause.
const NCG: &str = "crates/ivt-kin/src/ncg.rs::fourier_fit_of_eq38";
const BAND: &str = "crates/ivt-design/tests/ivt_design.rs::verdicts_follow_the_band";
const BETA: &str = "crates/ivt-hb/tests/mathieu.rs::cascade_matches_thesis_and_is_converged_in_n";
const AUDIT: &str = "tests/ch4_plant.rs::thesis_ch4_r_bar_matches_the_audit_values";
const DIGITS: &str = "src/reproduce/design.rs::printed_digits_limit_eq158";
const A0: &str = "src/reproduce/hb.rs::a0_differs_in_a8_sign_and_b3";
const GAMMA: &str = "src/reproduce/design.rs::gamma_hat_crosses_only_on_thesis_ch4";
const EQ159: &str = "src/reproduce/design.rs::eq159_is_the_thesis_ch4_boundary_to_the_grid_step";
const INF_F: &str = "src/reproduce/ch4_findings.rs::inf_f_is_pi_over_4";
const OVER_DRIVE: &str = "src/reproduce/ch4_findings.rs::seven_volts_two_nm_is_over_drive";
const RIPPLE: &str = "src/reproduce/rig.rs::ripple_of_printed_gears_is_twice_the_fourier_one";
const SAMPLING: &str = "src/reproduce/rig.rs::sampling_interval_is_4_5_degrees";
const EQ192: &str = "src/reproduce/rig.rs::eq192_needs_exponent_k_plus_1";
const FIG42: &str = "tests/ch4_plant.rs::fig42_multipliers_on_thesis_ch4_confirmed_by_simulation";
const HSU: &str = "tests/ch4_causes.rs::hsu_transformation_matrix_is_not_the_cause";
const RATIO: &str =
    "tests/ch4_causes_law.rs::printed_gain_ratio_floors_the_multiplier_at_exp_minus_half";

/// Reproduced rows carry the thesis value ± half a printed unit (the
/// reproduce criterion itself); "differs" rows a window around ours that
/// excludes the printed value.
#[rustfmt::skip]
const PINS: &[Pin] = &[
    Pin(KIN, "J_a", R, Some((0.02365, 0.02375)), None),
    Pin(KIN, "J_b", R, Some((2.12635, 2.12645)), None),
    Pin(KIN, "J_c", R, Some((0.33875, 0.33885)), None),
    Pin(KIN, "F_m", R, Some((2.3745, 2.3755)), None),
    Pin(KIN, "f1", R, Some((3.16665, 3.16675)), None),
    Pin(KIN, "f2", R, Some((40.55475, 40.55485)), None),
    Pin(KIN, "Eq. 42 a1", D, Some((0.13333, 0.13334)), Some(NCG)),
    Pin(KIN, "Eq. 42 a2", D, Some((-0.031747, -0.031745)), Some(NCG)),
    Pin(KIN, "Eq. 42 a3", D, Some((0.013985, 0.013987)), Some(NCG)),
    Pin(KIN, "Eq. 42 a4", D, Some((-0.0078432, -0.007843)), Some(NCG)),
    Pin(KIN, "R_avg slope", R, Some((2.5461e-4, 2.5463e-4)), None),
    // §2.2.4's bounds on the arc-approximated profiles (Fig. 23(b)).
    Pin(KIN, ARC_SMOOTH, R, Some((0.0, 1.0)), None),
    Pin(KIN, ARC_CORNER, R, Some((0.0, 5.0)), None),
    // Wall-clock times: the thesis's machine is unknown (declared).
    Pin(HB, "IHB time, classic", NC, None, None),
    Pin(HB, "IHB time, modified", NC, None, None),
    Pin(HB, "A0", D, None, Some(A0)),
    Pin(HB, "β1", D, Some((4.8255, 4.8260)), Some(BETA)),
    Pin(HB, "β2", R, Some((5.1935, 5.1945)), None),
    Pin(HB, "β4", R, Some((5.2525, 5.2535)), None),
    // Fig. 36: the spring boundary against fixed–fixed.
    Pin(STHB, "Fig. 36: k0 = 10000", R, Some((0.0, 0.01)), None),
    Pin(STHB, "Fig. 36: k0 = 10 ", R, Some((0.01, 1.0)), None),
    // Chapter 4 on the printed plant: the SPEC §5 band.
    Pin(PR, "r̄ at (6 V", D, Some((-0.0245, -0.0242)), Some(BAND)),
    Pin(PR, "r̄ at (7 V", D, Some((-0.0342, -0.0339)), Some(BAND)),
    Pin(PR, "r̄ at (8 V", D, Some((0.00126, 0.00129)), Some(BAND)),
    Pin(PR, "Eq. 158", D, None, Some(BAND)),
    Pin(PR, "Eq. 159", D, Some((0.153, 0.155)), Some(BAND)),
    Pin(PR, "Γ̂ = 0", D, None, Some(GAMMA)),
    Pin(PR, MU1_MM, D, Some((0.997, 0.999)), Some(BAND)),
    Pin(PR, MU1_SI, D, Some((0.72, 0.74)), Some(BAND)),
    Pin(PR, MU2_MM, D, Some((0.985, 0.99)), Some(BAND)),
    Pin(PR, MU2_SI, D, Some((1.01, 1.03)), Some(BAND)),
    // Chapter 4 on thesis-ch4 (k_t, k_e ÷ 10).
    Pin(CH4, "r̄ at (6 V", D, Some((0.006775, 0.00678)), Some(AUDIT)),
    Pin(CH4, "r̄ at (7 V", R, Some((0.02415, 0.02425)), None),
    Pin(CH4, "r̄ at (8 V", D, Some((0.007033, 0.007037)), Some(DIGITS)),
    Pin(CH4, "Eq. 158", D, None, Some(DIGITS)),
    Pin(CH4, "Eq. 159", D, Some((1.53, 1.545)), Some(EQ159)),
    Pin(CH4, "Γ̂ = 0", R, None, None),
    Pin(CH4, MU1_MM, D, Some((0.7856, 0.7876)), Some(HSU)),
    Pin(CH4, MU1_SI, D, Some((3.0, 4.0)), Some(FIG42)),
    Pin(CH4, MU2_MM, D, Some((0.6034, 0.6054)), Some(RATIO)),
    Pin(CH4, MU2_SI, D, Some((20.0, 25.0)), Some(FIG42)),
    // Findings on the printed text.
    Pin(DES, "inf f", D, Some((0.785397, 0.785399)), Some(INF_F)),
    Pin(DES, "f_B(7 V, 2 N·m)", D, Some((3.205, 3.215)), Some(OVER_DRIVE)),
    Pin(DES, "Eq. 158 r_f at (6 V", D, Some((0.007437, 0.007439)), Some(DIGITS)),
    // The printed controller on thesis-ch4 (scenes/ch4_*.toml).
    Pin(CL4, STEP_ERR, R, Some((-0.01, 0.01)), None),
    Pin(CL4, OPEN_7V, R, Some((0.5, 1.5)), None),
    Pin(CL4, OPEN_8V, D, Some((0.3, 1.0)), Some(AUDIT)),
    Pin(CL4, "RMS dr/dt", R, Some((100.0, 2000.0)), None),
    // §4.4, the rig.
    Pin(RIG, "speed-ratio ripple", D, Some((1.2175, 1.2195)), Some(RIPPLE)),
    Pin(RIG, "sampling interval", D, Some((4.5, 4.5)), Some(SAMPLING)),
    Pin(RIG, "K = 1/(K₂T_out)", R, Some((77.5, 78.5)), None),
    Pin(RIG, "stability bound on K", R, Some((155.5, 156.5)), None),
    Pin(RIG, "error contraction per sample", R, Some((0.355, 0.365)), None),
    Pin(RIG, "Eq. 192", D, None, Some(EQ192)),
];

/// Figures `ivt reproduce` always lists (drawn, or with the reason they are not).
const FIGURES: &[&str] = &[
    "Fig. 9(a)",
    "Fig. 9(b)",
    "Fig. 10",
    "Fig. 11",
    "Fig. 23(a)",
    "Fig. 23(b)",
    "Fig. 24",
    "Fig. 37",
    "Fig. 28",
    "Fig. 29",
    "Fig. 30",
    "Fig. 31",
    "Fig. 32",
    "Fig. 33",
    "Fig. 34",
    "Fig. 35",
    "Fig. 36",
    "Fig. 38(a)",
    "Fig. 38(b)",
    "Fig. 39",
    "Fig. 40",
    "Fig. 42",
    "Fig. 38(a) (thesis-ch4)",
    "Fig. 38(b) (thesis-ch4)",
    "Fig. 39 (thesis-ch4)",
    "Fig. 40 (thesis-ch4)",
    "Fig. 42 (thesis-ch4)",
    "Fig. 43",
    "Fig. 44",
    "Fig. 45",
    "Fig. 43 (thesis-ch4)",
    "Fig. 44 (thesis-ch4)",
    "Fig. 45 (thesis-ch4)",
    "Fig. 51",
    "Fig. 51 (Eq. 187)",
    "Fig. 47",
    "Fig. 48",
];

/// The first number in `s` (optionally signed, decimal or exponent form).
fn first_number(s: &str) -> Option<f64> {
    let start = s.find(|c: char| c.is_ascii_digit() || c == '-' || c == '+')?;
    let tail = &s[start..];
    let end = tail
        .char_indices()
        .skip(1)
        .find(|&(_, c)| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-' || c == '+'))
        .map_or(tail.len(), |(i, _)| i);
    tail[..end].parse().ok()
}

/// `file::fn_name` names a test function that exists in the repository.
fn test_exists(root: &Path, cause: &str) -> bool {
    let Some((file, name)) = cause.split_once("::") else {
        return false;
    };
    std::fs::read_to_string(root.join(file)).is_ok_and(|src| src.contains(&format!("fn {name}(")))
}

#[test]
fn reproduce_quick_pins_every_row_and_figure() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out: PathBuf = std::env::temp_dir().join(format!("ivt-repro-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    // --json prints exactly one JSON object (no progress bar on stdout).
    let v = common::ivt_json(&[
        "reproduce".as_ref(),
        "--quick".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let report = PathBuf::from(v["report"].as_str().expect("report path"));
    assert!(report.ends_with("REPRODUCTION.md") && report.exists());
    let md = std::fs::read_to_string(&report).expect("report text");

    let rows = v["rows"].as_array().expect("rows");
    let pin_of = |r: &serde_json::Value| -> Option<&Pin> {
        let (s, q) = (r["section"].as_str()?, r["quantity"].as_str()?);
        let mut hits = PINS.iter().filter(|p| p.0 == s && q.starts_with(p.1));
        let hit = hits.next();
        assert!(hits.next().is_none(), "{s} / {q} matches two pins");
        hit
    };
    for r in rows {
        let q = r["quantity"].as_str().unwrap();
        let pin = pin_of(r).unwrap_or_else(|| panic!("unpinned row: {r}"));
        assert_eq!(r["verdict"], pin.2, "{q}: {r}");
        // The markdown table escapes `|` inside a cell.
        assert!(md.contains(&q.replace('|', "\\|")), "{q} not in the report");
        if let Some((lo, hi)) = pin.3 {
            let ours = first_number(r["ours"].as_str().unwrap())
                .unwrap_or_else(|| panic!("{q}: no number in {}", r["ours"]));
            assert!(
                (lo..=hi).contains(&ours),
                "{q}: ours {ours} outside [{lo}, {hi}]"
            );
        }
        match pin.4 {
            Some(cause) => {
                assert_eq!(r["cause_test"], cause, "{q}");
                assert!(test_exists(root, cause), "{q}: no test {cause}");
                assert!(r["note"].as_str().unwrap().contains(cause), "{q}");
            }
            None => assert!(r["cause_test"].is_null(), "{q}: {r}"),
        }
    }
    for p in PINS {
        assert!(
            rows.iter()
                .any(|r| pin_of(r).is_some_and(|q| std::ptr::eq(q, p))),
            "pinned row missing: {} / {}",
            p.0,
            p.1
        );
    }
    let count = |w: &str| rows.iter().filter(|r| r["verdict"] == w).count();
    assert_eq!(rows.len(), PINS.len());
    assert_eq!(count(R), 21);
    assert_eq!(count(D), 31);
    assert_eq!(count(NC), 2);

    // Outputs are staged and renamed once the report is complete: no
    // temporary file is left after a successful run.
    let names: Vec<String> = std::fs::read_dir(&out)
        .expect("out dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.starts_with(".tmp-")), "{names:?}");
    assert!(names.iter().any(|n| n == "REPRODUCTION.md"), "{names:?}");

    let figures = v["figures"].as_array().expect("figures");
    for want in FIGURES {
        let f = figures
            .iter()
            .find(|f| f["id"] == *want)
            .unwrap_or_else(|| panic!("figure {want} missing"));
        let (png, csv) = (f["png"].as_str(), f["csv"].as_str());
        let (png, csv) = (png.expect(want), csv.expect(want));
        let bytes = std::fs::read(out.join(png)).expect("png");
        assert!(bytes.starts_with(b"\x89PNG"), "{png} is not a PNG");
        let csv = std::fs::read_to_string(out.join(csv)).expect("csv");
        assert!(csv.lines().count() > 2, "{want}: CSV has no data");
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn first_number_reads_signed_and_exponent_forms() {
    assert_eq!(first_number("+0.620"), Some(0.62));
    assert_eq!(first_number("-0.0317460"), Some(-0.031746));
    assert_eq!(first_number("2.2e-5"), Some(2.2e-5));
    assert_eq!(first_number("α = 1.537, β = 0.79 V"), Some(1.537));
    assert_eq!(first_number("—"), None);
}
