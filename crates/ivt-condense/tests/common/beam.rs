//! The cantilever of issue 28 condensed onto its tip: k3 = 200 cubic spring
//! from the tip to ground, the tip forced by `F cos ωt`, and the uncondensed
//! beam the tests compare with (`#[path]`-included by the condense tests).
#![allow(dead_code)] // each test binary uses its own subset
#![allow(clippy::expect_used, clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_condense::models::{cantilever, BeamProperties};
use ivt_condense::{CondensedBranch, Structure};
use ivt_hb::{GeneralProblem, HbOptions, PeriodicProblem};

/// Cubic spring constant at the tip (issue 28).
pub const K3: f64 = 200.0;
/// Tip force amplitude of the tests: the peak near 1.15 ω₁, two folds.
pub const FORCE: f64 = 0.005;
/// ω₁ of the continuous cantilever, (1.8751041)².
pub const OMEGA1: f64 = 3.516_015_268_066_119;

/// `g = k3 x³` on the local DOF.
pub fn spring(x: &[f64], _v: &[f64], _theta: f64, g: &mut [f64]) {
    g[0] = K3 * x[0] * x[0] * x[0];
}

/// `∂g/∂x = 3 k3 x²`.
pub fn spring_jacobian(x: &[f64], _v: &[f64], _theta: f64, dg: &mut [f64]) {
    dg[0] = 3.0 * K3 * x[0] * x[0];
    dg[1] = 0.0;
}

fn unforced(_theta: f64, f: &mut [f64]) {
    f[0] = 0.0;
}

/// The local problem on the tip: zero matrices, the spring, no excitation.
pub fn tip_problem() -> impl ivt_hb::PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![0.0],
        vec![0.0],
        vec![0.0],
        spring as fn(&[f64], &[f64], f64, &mut [f64]),
        unforced as fn(f64, &mut [f64]),
    )
    .with_velocity_dependent(false)
    .with_jacobian(spring_jacobian)
}

/// The condensed beam of `n_elements`, tip forced by `force`.
pub fn beam(
    n_elements: usize,
    force: f64,
    hb: &HbOptions,
) -> CondensedBranch<impl ivt_hb::PeriodicProblem> {
    let model = cantilever(n_elements, &BeamProperties::default()).expect("valid beam");
    let s = &model.model;
    let structure = Structure::new(s.m.as_ref(), s.c.as_ref(), s.k.as_ref()).expect("structure");
    let mut load = vec![0.0; s.n_dof()];
    load[model.tip] = force;
    CondensedBranch::new(structure, vec![model.tip], &load, &[], tip_problem(), hb)
        .expect("valid branch")
}

/// The uncondensed beam of `n` elements: dense M, C, K, the tip spring, the
/// tip force.
pub fn full_beam(n: usize) -> (impl PeriodicProblem, usize) {
    let b = cantilever(n, &BeamProperties::default()).unwrap();
    let nd = b.model.n_dof();
    let tip = b.tip;
    let problem = GeneralProblem::new(
        nd,
        dense(&b.model.m),
        dense(&b.model.c),
        dense(&b.model.k),
        move |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
            g.fill(0.0);
            g[tip] = K3 * x[tip].powi(3);
        },
        move |theta: f64, f: &mut [f64]| {
            f.fill(0.0);
            f[tip] = FORCE * theta.cos();
        },
    )
    .with_velocity_dependent(false)
    .with_jacobian(move |x: &[f64], _v: &[f64], _t: f64, dg: &mut [f64]| {
        dg.fill(0.0);
        dg[tip * nd + tip] = 3.0 * K3 * x[tip] * x[tip];
    });
    (problem, tip)
}

/// A sparse matrix as a dense row-major vector.
pub fn dense(a: &faer::sparse::SparseColMat<usize, f64>) -> Vec<f64> {
    let n = a.nrows();
    let d = a.to_dense();
    (0..n * a.ncols()).map(|i| d[(i / n, i % n)]).collect()
}

/// The period-one orbit of `coeffs` (all DOFs, `harmonics` each) at ω_f.
pub fn orbit(coeffs: Vec<f64>, omega_f: f64, harmonics: usize) -> ivt_hb::HbSolution {
    ivt_hb::HbSolution {
        coeffs,
        omega_f,
        harmonics,
        subharmonic: 1,
        stats: Default::default(),
    }
}
