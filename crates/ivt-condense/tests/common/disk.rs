//! pyHarm's 72-DOF bladed disk (tutorial 006, `ivt_condense::models::bladed_disk`)
//! with the cubic spring 5e10 x³ from sector 0's blade tip to ground: the
//! local problem of the condensed disk and the uncondensed disk the tests
//! compare with (`#[path]`-included by the condense tests).
#![allow(dead_code)] // each test binary uses its own subset
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use super::beam::dense;
use ivt_condense::models::bladed_disk;
use ivt_hb::{GeneralProblem, PeriodicProblem};

/// Cubic spring constant at the blade tip.
pub const K3: f64 = 5e10;

/// The tip's spring as the local problem of the condensed disk (no force:
/// the load vector carries it).
pub fn tip_problem() -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![0.0],
        vec![0.0],
        vec![0.0],
        |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| g[0] = K3 * x[0].powi(3),
        |_t: f64, f: &mut [f64]| f[0] = 0.0,
    )
    .with_velocity_dependent(false)
}

/// The uncondensed disk: dense M, C, K, the tip spring and its Jacobian,
/// `F = cos θ` at the tip.
pub fn full_disk() -> impl PeriodicProblem {
    let disk = bladed_disk().unwrap();
    let s = &disk.model;
    let (nd, tip) = (s.n_dof(), disk.tip);
    GeneralProblem::new(
        nd,
        dense(&s.m),
        dense(&s.c),
        dense(&s.k),
        move |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
            g.fill(0.0);
            g[tip] = K3 * x[tip].powi(3);
        },
        move |theta: f64, f: &mut [f64]| {
            f.fill(0.0);
            f[tip] = theta.cos();
        },
    )
    .with_velocity_dependent(false)
    .with_jacobian(move |x: &[f64], _v: &[f64], _t: f64, dg: &mut [f64]| {
        dg.fill(0.0);
        dg[tip * nd + tip] = 3.0 * K3 * x[tip] * x[tip];
    })
}
