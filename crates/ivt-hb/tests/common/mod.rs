//! Helpers shared by the integration tests: the independent RK4 check of an HB
//! orbit, the one-line modified-IHB solve and the 2-DOF cubic chain (also with
//! call counters).
#![allow(dead_code)] // each test binary uses its own subset
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

pub mod brute;
pub mod chain;
pub mod counted;
pub mod quasi;
pub mod shooting;

use ivt_hb::orbit::aft::eval_series;
use ivt_hb::problem::ode::{first_order, rk4};
use ivt_hb::{
    c64, frequency_response, BackboneOptions, BroydenOptions, ClassicIhb, ContinuationOptions, Frc,
    FrcOptions, HbOptions, HbSolution, LimitCycle, ModifiedIhb, PeriodicProblem,
};
use std::f64::consts::PI;

/// Max over all DOFs and 64 points of one period of |x_RK − x_HB|, RK4 with `per`
/// steps per period started at the HB state `(x(0), ẋ(0))`: an orbit that solves
/// the ODE stays on itself up to the truncation of `sol` and RK4's O(h⁴).
pub fn orbit_defect<P: PeriodicProblem>(problem: &P, sol: &HbSolution, per: usize) -> f64 {
    let w = sol.omega_f;
    let nd = problem.n_dof();
    let x0 = (0..nd).map(|d| eval_series(sol.dof(d), 0.0, 0));
    let v0 = (0..nd).map(|d| w * eval_series(sol.dof(d), 0.0, 1));
    let mut y: Vec<f64> = x0.chain(v0).collect();
    let period = 2.0 * PI / w;
    let dt = period / per as f64;
    let mut err = 0.0f64;
    for j in 0..64 {
        for (d, x) in y[..nd].iter().enumerate() {
            let hb = eval_series(sol.dof(d), 2.0 * PI * j as f64 / 64.0, 0);
            err = err.max((x - hb).abs());
        }
        rk4(
            first_order(problem, w),
            j as f64 * period / 64.0,
            &mut y,
            dt,
            per / 64,
        );
    }
    err
}

/// The modified IHB solution of `problem` at `omega_f` from the linear guess
/// (panics if the solver cannot be built or does not converge).
pub fn solve_modified<P: PeriodicProblem>(problem: P, opts: HbOptions, omega_f: f64) -> HbSolution {
    ModifiedIhb::new(problem, opts)
        .unwrap()
        .solve(omega_f, None)
        .unwrap()
}

/// The classic (full Newton) IHB solution of `problem` at `omega_f` from the
/// linear guess (panics as [`solve_modified`]).
pub fn solve_classic<P: PeriodicProblem>(problem: P, opts: HbOptions, omega_f: f64) -> HbSolution {
    ClassicIhb::new(problem, opts)
        .unwrap()
        .solve(omega_f, None)
        .unwrap()
}

/// `max_i |a_i − b_i|`.
pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Largest distance |a_i − b_i| between two lists of multipliers, pairwise
/// in order.
pub fn max_distance(a: &[c64], b: &[c64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

/// The frequency-response curve of `problem` from ω_f = `from` to `to`, the
/// other options default.
pub fn frc_between<P: PeriodicProblem>(problem: &P, hb: &HbOptions, from: f64, to: f64) -> Frc {
    let opts = FrcOptions {
        from,
        to,
        ..FrcOptions::default()
    };
    frequency_response(problem, hb, &opts).unwrap()
}

/// The path options of the two-parameter curves: steps `ds` = 0.02 up to
/// `ds_max` = 0.05, at most `max_points` points.
pub fn curve_steps(max_points: usize) -> ContinuationOptions {
    ContinuationOptions {
        ds: 0.02,
        ds_max: 0.05,
        max_points,
        ..ContinuationOptions::default()
    }
}

/// Backbone (or damped-mode) options from amplitude `from` to `to` in
/// arclength steps `ds` up to `ds_max`, each point converged to ‖r‖₂ ≤ 1e-12
/// in at most 25 iterations.
pub fn tight_backbone(from: f64, to: f64, ds: f64, ds_max: f64) -> BackboneOptions {
    BackboneOptions {
        amplitude_from: from,
        amplitude_to: to,
        continuation: ContinuationOptions {
            ds,
            ds_max,
            broyden: BroydenOptions {
                tol: 1e-12,
                max_iter: 25,
                ..BroydenOptions::default()
            },
            ..ContinuationOptions::default()
        },
        ..BackboneOptions::default()
    }
}

/// `lc`'s period within 1e-8 relative of the shooting period `t_ref`
/// (printed with the Newton steps under `label`).
pub fn assert_period(lc: &LimitCycle, t_ref: f64, label: &str) {
    let rel = (lc.period() - t_ref).abs() / t_ref;
    eprintln!(
        "{label}: HB period {:.13}, shooting {t_ref:.13}, rel {rel:.1e}, {} Newton steps",
        lc.period(),
        lc.solution.stats.iterations
    );
    assert!(rel < 1e-8, "{label}: {} vs {t_ref}", lc.period());
}
