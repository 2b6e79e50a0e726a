//! Two coupled DOFs through the general interface: M, C, K matrices plus a cubic
//! spring on DOF 0 and a force on DOF 1. Checked against one RK4 period started on
//! the HB orbit, and Hsu vs Hill for the 4×4 state-space Θ.
mod common;

use common::{orbit_defect, solve_modified};
use ivt_hb::{GeneralProblem, HbOptions, HsuRule, StabilityAnalyzer};

#[test]
fn coupled_two_dof_orbit_and_stability() {
    let problem = GeneralProblem::new(
        2,
        vec![1.0, 0.0, 0.0, 2.0],
        vec![0.05, -0.01, -0.01, 0.04],
        vec![2.0, -1.0, -1.0, 1.5],
        |x: &[f64], v: &[f64], _t: f64, out: &mut [f64]| {
            out[0] = 0.5 * x[0] * x[0] * x[0] + 0.02 * v[0] * x[0] * x[0];
            out[1] = 0.0;
        },
        |theta: f64, out: &mut [f64]| {
            out[0] = 0.0;
            out[1] = 0.3 * theta.cos();
        },
    );
    let omega_f = 0.9;
    let sol = solve_modified(&problem, HbOptions::new(24, 64), omega_f);
    let err = orbit_defect(&problem, &sol, 1 << 14);
    eprintln!(
        "2-DOF orbit defect {err:.2e}, amplitudes {:.4} {:.4}",
        sol.amplitude(0),
        sol.amplitude(1)
    );
    assert!(err < 1e-8, "{err:e}");
    let mut an = StabilityAnalyzer::new(&problem, 24, 4096).unwrap();
    let hsu = an.hsu(&problem, &sol, HsuRule::Magnus4);
    let hill = an.hill(&problem, &sol, 24).unwrap();
    // Sorted by modulus, the two members of a conjugate pair tie and may come in
    // either order: pair them by imaginary part instead (all four are distinct).
    let by_im = |mu: &[ivt_hb::c64]| {
        let mut v = mu.to_vec();
        v.sort_by(|a, b| a.im.total_cmp(&b.im));
        v
    };
    assert_eq!(hsu.multipliers.len(), hill.multipliers.len());
    let d = by_im(&hsu.multipliers)
        .iter()
        .zip(&by_im(&hill.multipliers))
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    eprintln!("Hsu {:?}\nHill {:?}", hsu.multipliers, hill.multipliers);
    eprintln!("Hsu vs Hill {d:.2e}");
    assert!(d < 1e-12, "{d:e}");
}
