//! The feasible band on the printed plant by direct integration: for each
//! T_U, the V_m at which the steady ω_a equals ω0 = 100 rpm with r = 0 and
//! with r = r_max (bisection on V_m; steady ω_a from the angle-domain run).
// An example may unwrap (the package's panic lints guard library code).
#![allow(clippy::unwrap_used)]
use ivt_kin::plant::PlantParams;
use ivt_sim::integrate::{ConstantInputs, Method, PlantIntegrator, Tolerance};
use ivt_sim::plant::Plant;
use std::f64::consts::TAU;

fn omega_a(v_m: f64, t_u: f64, r: f64) -> f64 {
    let plant = Plant::new(PlantParams::printed());
    let tol = Tolerance::uniform(1e-9);
    let mut it = PlantIntegrator::new(plant, Method::Dp5(tol), 0.0, 0.0, 10.0, 0.0);
    let prof = ConstantInputs { v_m, t_u };
    it.advance(&prof, r, 10.0 * TAU, 1e9).unwrap();
    let t0 = it.t;
    it.advance(&prof, r, 11.0 * TAU, 1e9).unwrap();
    TAU / (it.t - t0)
}

fn main() {
    let w0 = 100.0 * TAU / 60.0;
    let r_max = 0.012;
    println!("T_U   V(r=0)   V(r=r_max)   [SPEC §5 averaged: 7.93, 7.93+0.154 T_U]");
    for t_u in [1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0] {
        let solve = |r: f64| {
            let (mut lo, mut hi) = (2.0, 20.0);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if omega_a(mid, t_u, r) > w0 {
                    hi = mid
                } else {
                    lo = mid
                }
            }
            0.5 * (lo + hi)
        };
        println!(
            "{t_u:4.1}  {:7.4}  {:7.4}   [{:.3}, {:.3}]",
            solve(0.0),
            solve(r_max),
            7.93,
            7.93 + 0.154 * t_u
        );
    }
}
