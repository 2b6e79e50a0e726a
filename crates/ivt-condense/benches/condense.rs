//! The hot path of the condensed harmonic balance (issue 28): the receptances
//! of the cantilever at one frequency (one sparse LU and refined solves per
//! harmonic, n = 7), against the number of elements. `cargo bench -p ivt-hb
//! --bench condense`; the whole-curve scaling study is bench/large_scaling.py.
#![allow(clippy::expect_used, clippy::indexing_slicing)]

use faer::c64;
use ivt_condense::models::{cantilever, BeamProperties};
use ivt_condense::{Coupling, Receptances, Structure};

fn main() {
    divan::main();
}

#[divan::bench(args = [50, 250, 500, 1000])]
fn receptances_n7(bencher: divan::Bencher, n_elements: usize) {
    let beam = cantilever(n_elements, &BeamProperties::default()).expect("valid beam");
    let s = &beam.model;
    let structure = Structure::new(s.m.as_ref(), s.c.as_ref(), s.k.as_ref()).expect("structure");
    let mut load = vec![c64::new(0.0, 0.0); s.n_dof()];
    load[beam.tip] = c64::new(0.005, 0.0);
    let coupling = Coupling {
        dofs: vec![beam.tip],
        load,
        load_harmonic: 1,
    };
    bencher.bench_local(|| {
        Receptances::new(&structure, &coupling, 7, divan::black_box(3.7)).expect("receptances")
    });
}

/// The acceptance curve of issue 28: the N = 500 cantilever (1000 DOFs),
/// 0.7–1.3 ω₁, n = 7, folds, truncation estimates and multipliers at every
/// point (what `ivt.hb.frc` runs, without Python's callbacks).
#[divan::bench(sample_count = 3)]
fn beam_curve_n500(bencher: divan::Bencher) {
    let beam = cantilever(500, &BeamProperties::default()).expect("valid beam");
    let w1 = 3.516_015_268_066_119;
    let curve = Curve {
        tip: beam.tip,
        force: 0.005,
        band: (0.7 * w1, 1.3 * w1),
        harmonics: 7,
        spring,
    };
    bencher.bench_local(|| curve.run(&beam.model));
}

/// The bladed-disk acceptance curve of issue 28: pyHarm's 72-DOF disk
/// condensed onto the blade tip (cubic spring 5e10 x³), 1150–1260 rad/s,
/// n = 5, multipliers at every point.
#[divan::bench(sample_count = 3)]
fn disk_curve(bencher: divan::Bencher) {
    let disk = ivt_condense::models::bladed_disk().expect("disk");
    let curve = Curve {
        tip: disk.tip,
        force: 1.0,
        band: (1150.0, 1260.0),
        harmonics: 5,
        spring: tip_spring,
    };
    bencher.bench_local(|| curve.run(&disk.model));
}

/// A structure's curve condensed onto one DOF with a spring to ground,
/// forced there, stability at every point (the defaults).
struct Curve {
    tip: usize,
    force: f64,
    band: (f64, f64),
    harmonics: usize,
    spring: fn(&[f64], &[f64], f64, &mut [f64]),
}

impl Curve {
    fn run(&self, s: &ivt_condense::models::SparseModel) -> ivt_condense::CondensedFrc {
        use ivt_condense::{condensed_response, CondensedBranch, CondensedFrcOptions};
        use ivt_hb::{GeneralProblem, HbOptions};
        let structure =
            Structure::new(s.m.as_ref(), s.c.as_ref(), s.k.as_ref()).expect("structure");
        let mut load = vec![0.0; s.n_dof()];
        load[self.tip] = self.force;
        let opts = CondensedFrcOptions {
            from: self.band.0,
            to: self.band.1,
            ..CondensedFrcOptions::default()
        };
        let zero = || vec![0.0];
        let local = GeneralProblem::new(1, zero(), zero(), zero(), self.spring, unforced)
            .with_velocity_dependent(false);
        let hb = HbOptions::new(self.harmonics, 32);
        let mut branch = CondensedBranch::new(structure, vec![self.tip], &load, &[], local, &hb)
            .expect("branch");
        condensed_response(&mut branch, &opts).expect("curve")
    }
}

/// The disk's blade-tip cubic spring 5e10 x³.
fn tip_spring(x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]) {
    g[0] = 5e10 * x[0].powi(3);
}

/// The tip's cubic spring 200 x³.
fn spring(x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]) {
    g[0] = 200.0 * x[0].powi(3);
}

/// No force on the local DOF (the load vector carries it).
fn unforced(_t: f64, f: &mut [f64]) {
    f[0] = 0.0;
}
