//! The hot path of the condensed harmonic balance (issue 28): the receptances
//! of the cantilever at one frequency (one sparse LU and refined solves per
//! harmonic, n = 7), against the number of elements. `cargo bench -p ivt-hb
//! --bench condense`; the whole-curve scaling study is bench/large_scaling.py.

use faer::c64;
use ivt_hb::condense::{Coupling, Receptances, Structure};
use ivt_hb::models::cantilever;

fn main() {
    divan::main();
}

#[divan::bench(args = [50, 250, 500, 1000])]
fn receptances_n7(bencher: divan::Bencher, n_elements: usize) {
    let beam = cantilever(n_elements, 1.0, 1.0, 1.0, 0.07, 2e-4).expect("valid beam");
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
