//! `ivt reproduce --quick --json` end to end: every listed figure and table
//! row is produced, every verdict is one of the three words, every
//! "differs" carries a cause, and every drawn figure has its PNG and CSV.

use std::path::PathBuf;

/// Figures `ivt reproduce` always lists (drawn, or with the reason they are not).
const FIGURES: &[&str] = &[
    "Fig. 9(a)",
    "Fig. 9(b)",
    "Fig. 10",
    "Fig. 11",
    "Fig. 23(a)",
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
    "Fig. 43",
    "Fig. 44",
    "Fig. 45",
    "Fig. 51",
    "Fig. 47",
    "Fig. 48",
];

/// Quantities (prefixes of a row's `quantity`) the report always contains.
const ROWS: &[&str] = &[
    "J_a",
    "J_b",
    "J_c",
    "F_m",
    "f1",
    "f2",
    "Eq. 42 a1",
    "Eq. 42 a2",
    "Eq. 42 a3",
    "Eq. 42 a4",
    "R_avg slope",
    "A0",
    "β1",
    "β2",
    "β4",
    "IHB time, classic",
    "IHB time, modified",
    "r̄ at (6 V, 6 N·m)",
    "Eq. 158",
    "Eq. 159",
    "Fig. 42 multiplier (k = 0.01, k2 = 0.02)",
    "Fig. 42 multiplier (k = 0.06, k2 = 0.12)",
];
use std::process::Command;

#[test]
fn reproduce_quick_produces_every_row_and_figure() {
    let out: PathBuf = std::env::temp_dir().join(format!("ivt-repro-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let res = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .args(["reproduce", "--quick", "--json", "--out"])
        .arg(&out)
        .output()
        .expect("run ivt");
    assert!(
        res.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&res.stderr)
    );
    let stdout = String::from_utf8(res.stdout).expect("utf-8");
    // --json prints exactly one JSON object (no progress bar on stdout).
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON object");
    let report = PathBuf::from(v["report"].as_str().expect("report path"));
    assert!(report.ends_with("REPRODUCTION.md") && report.exists());
    let md = std::fs::read_to_string(&report).expect("report text");

    let rows = v["rows"].as_array().expect("rows");
    for want in ROWS {
        let row = rows
            .iter()
            .find(|r| r["quantity"].as_str().is_some_and(|q| q.starts_with(want)))
            .unwrap_or_else(|| panic!("row {want} missing"));
        for key in ["thesis", "ours", "difference", "verdict", "note"] {
            assert!(row[key].is_string(), "row {want}: key {key}");
        }
        assert!(
            md.contains(row["quantity"].as_str().unwrap()),
            "row {want} not in the report"
        );
    }
    for r in rows {
        let verdict = r["verdict"].as_str().unwrap();
        assert!(
            ["reproduced", "differs", "not computable"].contains(&verdict),
            "{verdict}"
        );
        if verdict != "reproduced" {
            assert!(
                r["note"].as_str().unwrap().len() > 20,
                "{} needs a cause: {r}",
                r["quantity"]
            );
        }
    }

    let figures = v["figures"].as_array().expect("figures");
    for want in FIGURES {
        let f = figures
            .iter()
            .find(|f| f["id"] == *want)
            .unwrap_or_else(|| panic!("figure {want} missing"));
        match (f["png"].as_str(), f["csv"].as_str()) {
            (Some(png), Some(csv)) => {
                let png = out.join(png);
                let bytes = std::fs::read(&png).expect("png");
                assert!(
                    bytes.starts_with(b"\x89PNG"),
                    "{} is not a PNG",
                    png.display()
                );
                let csv = std::fs::read_to_string(out.join(csv)).expect("csv");
                assert!(csv.lines().count() > 2, "{want}: CSV has no data");
            }
            _ => assert!(
                f["note"].as_str().unwrap().contains("not"),
                "{want} is neither drawn nor explained"
            ),
        }
    }
    // The kinematics and plant rows do not depend on any unfinished engine.
    for want in ["J_a", "J_b", "J_c", "F_m", "f1", "f2", "R_avg slope"] {
        let r = rows
            .iter()
            .find(|r| r["quantity"].as_str().unwrap().starts_with(want))
            .unwrap();
        assert_eq!(r["verdict"], "reproduced", "{r}");
    }
    // Eq. 42: the printed coefficients are 0.9× the exact Fourier ones.
    for k in 1..=4 {
        let r = rows
            .iter()
            .find(|r| {
                r["quantity"]
                    .as_str()
                    .unwrap()
                    .starts_with(&format!("Eq. 42 a{k}"))
            })
            .unwrap();
        assert_eq!(r["verdict"], "differs");
        assert!(r["note"].as_str().unwrap().contains("0.9"));
    }
    let _ = std::fs::remove_dir_all(&out);
}
