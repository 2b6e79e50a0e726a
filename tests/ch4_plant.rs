//! `--plant thesis-ch4` end to end: `ivt ol solve` (modified IHB) against an
//! independent θ-shooting of Eq. 151 (RK6 + Newton, `ivt_design::shooting`),
//! and the plant name echoed in the JSON of every command that takes a plant.
// A test may expect (the package's panic lints guard library code).
#![allow(clippy::expect_used)]

use ivt_design::shooting::{shoot_steady_state, ShootingOptions};
use ivt_design::OperatingPoint;
use ivt_kin::plant::PlantPreset;
use std::process::Command;

mod common;
use common::ivt_json;

/// The 100-rpm steady state of thesis-ch4 at (V_m, T_U) by θ-shooting of
/// Eq. 151 (RK6 + Newton), independent of the IHB.
fn r_bar_by_shooting(vm: f64, tu: f64) -> ivt_design::shooting::PeriodicOrbit {
    shoot_steady_state(
        &PlantPreset::ThesisCh4.params(),
        &OperatingPoint::at_100_rpm(vm, tu),
        None,
        &ShootingOptions::default(),
    )
    .expect("shooting converges")
}

/// Ten feasible points spread over the thesis grid (V_m 2–12 V, T_U 1.5–9 N·m)
/// of the thesis-ch4 plant, 0 ≤ r̄ ≤ r_max at each (checked below).
const POINTS: [(f64, f64); 10] = [
    (2.0, 1.5),
    (3.2, 2.5),
    (4.0, 6.0),
    (5.0, 3.0),
    (6.0, 6.0),
    (8.0, 8.0),
    (9.2, 5.5),
    (10.0, 9.0),
    (12.0, 7.5),
    (7.2, 4.5),
];

/// n = 31 harmonics: on thesis-ch4 the IHB r̄ moves by ≤ 3e-7 relative from
/// n = 31 to n = 63 at (5 V, 3 N·m), (6 V, 6 N·m), (8 V, 8 N·m), so 1e-5 is
/// met with margin (the default n = 7 is ~2e-5 off at (5 V, 3 N·m)).
#[test]
fn ol_solve_on_thesis_ch4_agrees_with_shooting() {
    for (vm, tu) in POINTS {
        let (vs, ts) = (vm.to_string(), tu.to_string());
        let v = ivt_json(&[
            "ol",
            "solve",
            "--plant",
            "thesis-ch4",
            "--vm",
            &vs,
            "--tu",
            &ts,
            "--harmonics",
            "31",
        ]);
        assert_eq!(v["plant"], "thesis-ch4");
        assert_eq!(v["verdict"], "feasible", "({vm}, {tu}): {v}");
        let r_ihb = v["r"].as_f64().expect("r");
        let shot = r_bar_by_shooting(vm, tu);
        let rel = (r_ihb - shot.r).abs() / shot.r;
        assert!(
            rel <= 1e-5,
            "({vm} V, {tu} N·m): IHB {r_ihb} vs shooting {} (rel {rel:.1e})",
            shot.r
        );
    }
}

/// The audit's three r̄ values on thesis-ch4 (issue text: 0.0068, 0.02422,
/// 0.00704 m) by shooting, to the digits quoted.
#[test]
fn thesis_ch4_r_bar_matches_the_audit_values() {
    for (vm, tu, want, half_ulp) in [
        (6.0, 6.0, 0.0068, 5e-5),
        (7.0, 2.0, 0.02422, 5e-6),
        (8.0, 8.0, 0.00704, 5e-6),
    ] {
        let o = r_bar_by_shooting(vm, tu);
        assert!((o.r - want).abs() <= half_ulp, "({vm}, {tu}): {}", o.r);
    }
}

#[test]
fn every_plant_command_echoes_the_plant() {
    let printed = ivt_json(&["ol", "solve", "--vm", "8", "--tu", "5"]);
    assert_eq!(printed["plant"], "printed");
    let ch4 = ["--plant", "thesis-ch4"];
    let grid = ["--vm", "6", "1", "7", "--tu", "6", "1", "6"];
    let one = [
        "--vm-from",
        "6",
        "--vm-to",
        "6",
        "--tu-from",
        "6",
        "--tu-to",
        "6",
    ];
    let mut table = serde_json::Value::Null;
    for args in [
        [&["stability"][..], &ch4, &["--vm", "8", "--tu", "8"]].concat(),
        [&["stability-map"][..], &ch4, &grid].concat(),
        [&["ol", "table"][..], &ch4, &["--quiet"], &one].concat(),
    ] {
        let v = ivt_json(&args);
        assert_eq!(v["plant"], "thesis-ch4", "{args:?}");
        table = v;
    }
    // The same point on the two plants gives two different orbits.
    let r_ch4 = table["points"][0]["r"].as_f64().expect("r");
    assert!((r_ch4 - 0.006_777_5).abs() < 1e-6, "{r_ch4}");
    let bad = Command::new(env!("CARGO_BIN_EXE_ivt"))
        .args([
            "--json", "ol", "solve", "--plant", "roller", "--vm", "8", "--tu", "5",
        ])
        .output()
        .expect("run ivt");
    assert_eq!(bad.status.code(), Some(2));
}

/// Fig. 42's example point (7 V, 2 N·m) on thesis-ch4: with the gains read as
/// mm·rad⁻¹ (k_SI = 1e-3 k) the Floquet multipliers are 0.787 (k = 0.01,
/// k2 = 0.02; printed 0.7776) and 0.604 (k = 0.06, k2 = 0.12; printed 0.4871),
/// each confirmed by simulating the delay loop (contraction per revolution)
/// to 1e-3; read as SI the loop is unstable (3.5 and 22), unlike the thesis.
#[test]
fn fig42_multipliers_on_thesis_ch4_confirmed_by_simulation() {
    use ivt_design::delay::{delay_stability, DelayOptions, FeedbackGains};
    use ivt_design::delay_sim::{check_prediction, DelaySimOptions};
    let plant = PlantPreset::ThesisCh4.params();
    let op = OperatingPoint::at_100_rpm(7.0, 2.0);
    for (k, k2, want) in [(0.01, 0.02, 0.7866), (0.06, 0.12, 0.6044)] {
        let g = FeedbackGains::from_thesis_mm_per_rad(k, k2);
        let s = delay_stability(&plant, &op, g, &DelayOptions::default()).unwrap();
        assert!(
            (s.max_abs_multiplier - want).abs() < 1e-3,
            "{k}: {}",
            s.max_abs_multiplier
        );
        let (c, rel) = check_prediction(&plant, &op, g, &s, &DelaySimOptions::default()).unwrap();
        assert!(
            rel < 1e-3,
            "{k}: predicted {} simulated {}",
            s.max_abs_multiplier,
            c.measured
        );
        let si = delay_stability(
            &plant,
            &op,
            FeedbackGains { k, k2 },
            &DelayOptions::default(),
        )
        .unwrap();
        assert!(
            si.max_abs_multiplier > 3.0,
            "{k}: SI {}",
            si.max_abs_multiplier
        );
    }
}

/// What does not explain Fig. 42's printed 0.7776 / 0.4871 on thesis-ch4 at
/// (7 V, 2 N·m) (ours 0.787 / 0.604, gains in mm·rad⁻¹):
/// - the Chebyshev order: N = 4…16 stays within 5e-3 of 0.7866 and 0.6044;
/// - a scale slip of the gains: over ×0.05…×20 the (0.06, 0.12) pair never
///   gets max |μ| below 0.60 (what floors it is the feedback law's zero at
///   e^{−k/k2}, `tests/ch4_causes.rs`); the plant's own open-loop Floquet
///   multiplier on this orbit, 0.593, found here independently as the
///   return-map derivative dω(2π)/dω(0) at r = r̄ by finite differences, is
///   near that floor (0.607), which depends on k/k2 only, not on the plant;
/// - the (7 V, 7 N·m) reading of §4.3's garbled "T_U = 7 V 2 Nm": 0.63 / 1.02.
#[test]
fn fig42_gap_is_not_gain_scale_order_or_point() {
    use ivt_design::delay::{delay_stability_about, steady_orbit, DelayOptions, FeedbackGains};
    use ivt_design::shooting::omega_at_angles;
    let plant = PlantPreset::ThesisCh4.params();
    let opts = DelayOptions::default();
    let op = OperatingPoint::at_100_rpm(7.0, 2.0);
    let orbit = steady_orbit(&plant, &op, None, &opts).unwrap();
    let mu = |k: f64, k2: f64, o: &DelayOptions| {
        let g = FeedbackGains::from_thesis_mm_per_rad(k, k2);
        delay_stability_about(&plant, &op, g, &orbit, o)
            .unwrap()
            .max_abs_multiplier
    };
    for n in [4, 6, 8, 10, 12, 16] {
        let o = DelayOptions {
            chebyshev_order: n,
            ..opts
        };
        assert!((mu(0.01, 0.02, &o) - 0.7866).abs() < 5e-3, "N = {n}");
        assert!((mu(0.06, 0.12, &o) - 0.6044).abs() < 5e-3, "N = {n}");
    }
    // Return map over all but the last 1/20000 of a revolution (the missing
    // piece changes the multiplier by O(1e-4)).
    let samples = 20_000;
    let end = |w0: f64| {
        *omega_at_angles(&plant, 7.0, 2.0, orbit.r, w0, samples, 1)
            .unwrap()
            .last()
            .unwrap()
    };
    let h = 1e-6 * orbit.omega_start;
    let plant_mu = (end(orbit.omega_start + h) - end(orbit.omega_start - h)) / (2.0 * h);
    let open = delay_stability_about(
        &plant,
        &op,
        FeedbackGains { k: 0.0, k2: 0.0 },
        &orbit,
        &opts,
    )
    .unwrap();
    let open_mu = open.multipliers[2].0.hypot(open.multipliers[2].1);
    assert!((plant_mu - 0.593).abs() < 1e-3, "plant {plant_mu}");
    assert!((plant_mu - open_mu).abs() < 1e-3, "{plant_mu} vs {open_mu}");
    let floor = (0..=40)
        .map(|i| 0.05 * 400f64.powf(i as f64 / 40.0))
        .map(|s| mu(0.06 * s, 0.12 * s, &opts))
        .fold(f64::INFINITY, f64::min);
    // 0.60 is 0.11 above the printed 0.4871.
    assert!(floor > 0.60, "floor {floor}");
    let at_7_7 = OperatingPoint::at_100_rpm(7.0, 7.0);
    let o77 = steady_orbit(&plant, &at_7_7, None, &opts).unwrap();
    for (k, k2, printed) in [(0.01, 0.02, 0.7776), (0.06, 0.12, 0.4871)] {
        let g = FeedbackGains::from_thesis_mm_per_rad(k, k2);
        let m = delay_stability_about(&plant, &at_7_7, g, &o77, &opts).unwrap();
        assert!(
            (m.max_abs_multiplier - printed).abs() > 0.1,
            "(7, 7): {}",
            m.max_abs_multiplier
        );
    }
}
