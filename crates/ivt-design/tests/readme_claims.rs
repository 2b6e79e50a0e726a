//! The numbers the guide (docs/guide/src/reproducing.md, "On the printed
//! plant") states for the open-loop law on the printed plant
//! ("Refit" and "ω_a error of the printed THESIS law"): how many thesis grid
//! points are feasible, the refit's residuals and boundary line, and the ω_a
//! error of each law, measured by θ-shooting of the open-loop periodic orbit at
//! r = u_ol (`fit::law_error`: the plant is integrated, not the IHB series).
//! Each printed figure is asserted to half a unit of its last printed digit.

use ivt_design::fit::{fit_boundary, fit_polynomial, law_error, OpenLoopLaw, PolyForm};
use ivt_design::steady::IhbOptions;
use ivt_design::sweep::{sweep_serial, Grid};
use ivt_design::Verdict;
use ivt_kin::plant::PlantParams;

/// `|value − printed| ≤ half_unit`, with the value in the message.
fn assert_printed(what: &str, value: f64, printed: f64, half_unit: f64) {
    assert!(
        (value - printed).abs() <= half_unit,
        "{what}: {value} vs printed {printed} (± {half_unit})"
    );
}

#[test]
fn refit_and_thesis_law_errors_on_the_printed_plant() {
    let plant = PlantParams::printed();
    let grid = Grid::thesis();
    let pts = sweep_serial(&plant, &grid, IhbOptions::default()).unwrap();
    assert_eq!(pts.len(), 416);
    let feasible: Vec<_> = pts
        .iter()
        .filter(|p| matches!(&p.result, Ok(s) if s.verdict == Verdict::Feasible))
        .collect();
    assert_eq!(feasible.len(), 35);
    // "V_m = 8.0…9.2 V"; "V_m ≤ 7.6 V is under-drive at every load".
    let v_min = feasible
        .iter()
        .map(|p| p.op.v_m)
        .fold(f64::INFINITY, f64::min);
    let v_max = feasible.iter().map(|p| p.op.v_m).fold(0.0, f64::max);
    assert!(
        (v_min - 8.0).abs() < 1e-9 && (v_max - 9.2).abs() < 1e-9,
        "{v_min} … {v_max}"
    );
    assert!(pts
        .iter()
        .filter(|p| p.op.v_m <= 7.6 + 1e-9)
        .all(|p| matches!(&p.result, Ok(s) if s.verdict == Verdict::UnderDrive)));

    let pf = fit_polynomial(&pts, plant.r_max, PolyForm::Eq158).unwrap();
    assert_eq!(pf.points, 35);
    assert_printed("fit RMS in r [m]", pf.rms_r, 4.0e-5, 5e-7);
    assert_printed("fit max in r [m]", pf.max_r, 1.26e-4, 5e-7);

    let (alpha, beta, dev) = fit_boundary(
        &plant,
        &grid.t_u,
        grid.omega0,
        plant.r_max,
        IhbOptions::default(),
    )
    .unwrap();
    assert_printed("boundary slope [V/(N·m)]", alpha, 0.15368, 5e-6);
    assert_printed("boundary offset [V]", beta, 7.87354, 5e-6);
    assert!(dev < 1e-3, "r̄ = r_max is a line to < 1 mV: {dev}");

    let refit = law_error(&plant, &OpenLoopLaw::from_coeffs(&ivt_ctrl::REFIT), &pts).unwrap();
    eprintln!(
        "REFIT: max {} rpm, RMS {} rpm",
        refit.max_abs_rpm, refit.rms_rpm
    );
    assert_eq!((refit.points.len(), refit.stalled), (35, 0));
    assert_printed("REFIT max |ω_a − ω0| [rpm]", refit.max_abs_rpm, 0.114, 5e-4);
    assert_printed("REFIT RMS [rpm]", refit.rms_rpm, 0.059, 5e-4);

    let thesis = law_error(&plant, &OpenLoopLaw::thesis(), &pts).unwrap();
    eprintln!(
        "THESIS: max {} rpm, RMS {} rpm",
        thesis.max_abs_rpm, thesis.rms_rpm
    );
    assert_eq!((thesis.points.len(), thesis.stalled), (35, 0));
    assert_printed(
        "THESIS max |ω_a − ω0| [rpm]",
        thesis.max_abs_rpm,
        7.90,
        5e-3,
    );
    assert_printed("THESIS RMS [rpm]", thesis.rms_rpm, 4.81, 5e-3);
}
