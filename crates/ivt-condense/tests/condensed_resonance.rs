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

/// A sharp resonance the default step is wider than (issue 42): two unit
/// masses, DOF 0 (k = 1, c = 0.04, the cubic spring 0.05 x³ and the force
/// cos θ) coupled by k_c = 0.05 to DOF 1 (k = 1.69, c = 0.0052: ζ = 0.2 % at
/// ω = 1.3), swept over 0.5–2.0. DOF 1's resonance is a narrow peak on DOF
/// 0's skirt, bent by the spring into folds near ω = 1.3, where the path's
/// steps reach 0.15 of the sweep. Before the stepper rejected a step whose
/// corrected point lay far from its prediction or whose tangent turned by
/// more than `max_turn`, the condensed curve stepped across the peak (its
/// highest point above ω = 1.2: 5.17 instead of 9.14, measured) and its
/// folds were not those of the curve. Reference: the dense harmonic balance
/// of the whole 2-DOF system (the modified IHB of `frequency_response`, all
/// DOFs, the same n = 7) and its located folds.
#[test]
fn default_condensed_frc_does_not_step_across_a_sharp_resonance() {
    use ivt_hb::{frequency_response, FrcOptions};
    let (kc, k3) = (0.05, 0.05);
    let (m, c, k) = (
        [1.0, 0.0, 0.0, 1.0],
        [0.04, 0.0, 0.0, 2.0 * 0.002 * 1.3],
        [1.0 + kc, -kc, -kc, 1.69 + kc],
    );
    let triplets = |a: &[f64; 4]| -> Vec<(usize, usize, f64)> {
        (0..4)
            .filter(|&i| a[i] != 0.0)
            .map(|i| (i / 2, i % 2, a[i]))
            .collect()
    };
    let structure =
        Structure::from_triplets(2, &triplets(&m), &triplets(&c), &triplets(&k)).unwrap();
    let spring = move |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| g[0] = k3 * x[0].powi(3);
    let unforced = |_t: f64, f: &mut [f64]| f[0] = 0.0;
    let local = GeneralProblem::new(1, vec![0.0], vec![0.0], vec![0.0], spring, unforced)
        .with_velocity_dependent(false);
    let hb = HbOptions::new(7, 32);
    let mut branch =
        CondensedBranch::new(structure, vec![0], &[1.0, 0.0], &[], local, &hb).unwrap();
    let mut opts = CondensedFrcOptions::default();
    (opts.from, opts.to) = (0.5, 2.0);
    opts.stability_blocks = None;
    let condensed = condensed_response(&mut branch, &opts).unwrap();
    assert_eq!(condensed.termination, Termination::LeftInterval);

    let whole = GeneralProblem::new(
        2,
        m.to_vec(),
        c.to_vec(),
        k.to_vec(),
        move |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
            g[0] = k3 * x[0].powi(3);
            g[1] = 0.0;
        },
        |t: f64, f: &mut [f64]| {
            f[0] = t.cos();
            f[1] = 0.0;
        },
    )
    .with_velocity_dependent(false);
    let dense = frequency_response(
        &whole,
        &hb,
        &FrcOptions::sweep(0.5, 2.0, Default::default()),
    )
    .unwrap();
    let folds = |f: &[f64]| format!("{f:?}");
    let dense_folds: Vec<f64> = dense.events.iter().map(|f| f.omega_f).collect();
    let condensed_folds: Vec<f64> = condensed.events.iter().map(|f| f.omega_f).collect();
    assert!(dense_folds.len() >= 2, "{}", folds(&dense_folds));
    assert!(dense.events.iter().all(|f| f.located));
    assert_eq!(
        condensed_folds.len(),
        dense_folds.len(),
        "condensed {} vs dense {}",
        folds(&condensed_folds),
        folds(&dense_folds)
    );
    assert!(condensed.events.iter().all(|f| f.located));
    for (a, b) in condensed_folds.iter().zip(&dense_folds) {
        assert!((a - b).abs() <= 1e-8 * b, "fold {a} vs dense {b}");
    }
    // The fold orbits: DOF 0's harmonics, condensed against dense (DOF 0's
    // block of the dense coefficients).
    for (a, b) in condensed.events.iter().zip(&dense.events) {
        let scale = b.coeffs.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let worst = a
            .coeffs
            .iter()
            .zip(&b.coeffs[..a.coeffs.len()])
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(worst <= 1e-6 * scale, "fold orbit differs by {worst:e}");
    }
}
