//! Issue #28 item 3 on the condensed path: the default condensed sweep
//! (`condensed_response` with `CondensedFrcOptions::default()`, the path of
//! `ivt.hb.frc` for sparse matrices) resolves a lightly damped resonance.
//! The linear oscillator `x″ + 0.002 x′ + x = cos θ` (m = 1, c = 0.002,
//! k = 1: ζ = c/(2√(km)) = 0.001) built as the Python binding builds it
//! (`hb_large.rs`: a sparse structure, the nonlinear DOF 0 with zero local
//! matrices and `g` = 0), swept over 0.5 ≤ ω ≤ 1.5. Its amplitude
//! `1/√((1 − ω²)² + (2ζω)²)` peaks at `1/(2ζ√(1 − ζ²))` = 500.00025 (closed
//! form, at `ω = √(1 − 2ζ²)`), about 375 times the response at the start.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_condense::{
    condensed_response, CondensedBranch, CondensedFrc, CondensedFrcOptions, Structure,
};
use ivt_hb::{GeneralProblem, HbOptions, Termination};

/// The default condensed curve of the oscillator over 0.5–1.5.
fn default_sweep() -> CondensedFrc {
    let structure =
        Structure::from_triplets(1, &[(0, 0, 1.0)], &[(0, 0, 0.002)], &[(0, 0, 1.0)]).unwrap();
    let free = |_x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| g[0] = 0.0;
    let unforced = |_t: f64, f: &mut [f64]| f[0] = 0.0;
    let local = GeneralProblem::new(1, vec![0.0], vec![0.0], vec![0.0], free, unforced)
        .with_velocity_dependent(false);
    let hb = HbOptions::new(3, 16);
    let mut branch = CondensedBranch::new(structure, vec![0], &[1.0], &[], local, &hb).unwrap();
    let mut opts = CondensedFrcOptions::default();
    (opts.from, opts.to) = (0.5, 1.5);
    condensed_response(&mut branch, &opts).unwrap()
}

#[test]
fn default_condensed_frc_resolves_a_lightly_damped_resonance() {
    let zeta: f64 = 0.001;
    let exact = 1.0 / (2.0 * zeta * (1.0 - zeta * zeta).sqrt());
    let frc = default_sweep();
    let n = frc.points.len();
    assert_eq!(
        frc.termination,
        Termination::LeftInterval,
        "must reach ω = 1.5 ({n} points)"
    );
    let top = frc
        .points
        .iter()
        .max_by(|a, b| a.amplitude.total_cmp(&b.amplitude))
        .unwrap();
    assert!(
        (top.amplitude - exact).abs() <= 1e-4 * exact,
        "peak {} vs {exact} ({n} points)",
        top.amplitude
    );
    // The peak is a point of the curve at the closed form's ω = √(1 − 2ζ²)
    // (an amplitude within 1e-4 puts it within ~1.4e-5 of it), in path order.
    let omega_peak = (1.0 - 2.0 * zeta * zeta).sqrt();
    assert!((top.omega_f - omega_peak).abs() <= 2e-5, "{}", top.omega_f);
    assert!(
        frc.points.windows(2).all(|w| w[0].omega_f < w[1].omega_f),
        "a linear curve is monotone in ω"
    );
}
