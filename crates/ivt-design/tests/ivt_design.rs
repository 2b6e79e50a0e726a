//! Acceptance tests of the IVT design tools (issue 7): IHB vs shooting,
//! convergence in n and in N, bad inputs.
// Test code: the crate's panic lints guard shipped code only.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

mod common;

use ivt_design::delay::{delay_stability, DelayOptions, FeedbackGains};
use ivt_design::gains::grid_stability_map;
use ivt_design::shooting::{shoot_steady_state, ShootingOptions};
use ivt_design::steady::{solve_steady_state, IhbOptions};
use ivt_design::sweep::{sweep_serial, Grid};
use ivt_design::{IvtError, OperatingPoint, Verdict};
use ivt_kin::plant::PlantParams;
use rayon::prelude::*;

fn shoot(v: f64, t: f64) -> f64 {
    let op = OperatingPoint::at_100_rpm(v, t);
    shoot_steady_state(
        &PlantParams::printed(),
        &op,
        None,
        &ShootingOptions::default(),
    )
    .unwrap()
    .r
}

fn ihb(v: f64, t: f64, n: usize) -> f64 {
    let op = OperatingPoint::at_100_rpm(v, t);
    let o = IhbOptions {
        harmonics: n,
        ..Default::default()
    };
    solve_steady_state(&PlantParams::printed(), &op, o)
        .unwrap()
        .r
}

/// Issue 7 acceptance: IHB r̄ = shooting r̄ to 1e-8 relative at 10 grid points
/// (under-drive, feasible and over-drive ones; all with |r̄| ≥ 2 mm so that
/// "relative" is meaningful). f_θ jumps at the gear corners, so the IHB
/// truncation error falls like n⁻³ (see `converges_in_n`); n = 383 is where
/// it is below 1e-8 at all ten. The shooting reference is converged to
/// ~1e-11 (RK6 step study in `shooting::tests`) and checked against a plain
/// time integration in docs/guide/src/reproducing.md.
#[test]
fn ihb_matches_shooting_at_ten_points() {
    let pts = [
        (6.0, 6.0),
        (8.4, 1.5),
        (12.0, 2.0),
        (9.2, 9.0),
        (2.0, 1.5),
        (12.0, 9.0),
        (7.0, 2.0),
        (8.8, 5.0),
        (10.0, 4.0),
        (8.4, 3.0),
    ];
    let errs: Vec<(f64, f64, f64)> = pts
        .par_iter()
        .map(|&(v, t)| {
            let rs = shoot(v, t);
            assert!(rs.abs() >= 2e-3, "({v},{t}): r̄ = {rs}");
            (v, t, (ihb(v, t, 383) - rs).abs() / rs.abs())
        })
        .collect();
    for (v, t, e) in errs {
        assert!(e <= 1e-8, "({v}, {t}): relative error {e:e}");
    }
}

/// r̄(n) → shooting r̄ as n grows, at least 6× per doubling of n (n⁻³ would be
/// 8×; the kinks of ω̄ at the gear corners make θ₁'s coefficients decay like k⁻³).
#[test]
fn converges_in_n() {
    for (v, t) in [(8.4, 1.5), (10.0, 6.0)] {
        let rs = shoot(v, t);
        let e: Vec<f64> = [15, 31, 63]
            .iter()
            .map(|&n| (ihb(v, t, n) - rs).abs())
            .collect();
        assert!(e[0] / e[1] > 6.0 && e[1] / e[2] > 6.0, "({v},{t}): {e:?}");
    }
}

/// The averaged power balance of SPEC §5 puts the 100 rpm band at about
/// [7.93, 7.93 + 0.154 T_U] V; the exact band must be close (within 0.1 V at
/// both edges at T_U = 6 N·m), and the verdicts must order as
/// under-drive → feasible → over-drive along V_m.
#[test]
fn verdicts_follow_the_band() {
    let plant = PlantParams::printed();
    let v = |v, t| {
        solve_steady_state(
            &plant,
            &OperatingPoint::at_100_rpm(v, t),
            IhbOptions::default(),
        )
        .unwrap()
        .verdict
    };
    assert_eq!(v(7.8, 6.0), Verdict::UnderDrive);
    assert_eq!(v(8.3, 6.0), Verdict::Feasible);
    assert_eq!(v(8.9, 6.0), Verdict::OverDrive);
}

/// Max |Floquet multiplier| of the delayed loop with gains `g` at `op`, by a
/// Chebyshev collocation of order `n`.
fn max_multiplier(plant: &PlantParams, op: &OperatingPoint, g: FeedbackGains, n: usize) -> f64 {
    let o = DelayOptions {
        chebyshev_order: n,
        ..Default::default()
    };
    delay_stability(plant, op, g, &o)
        .unwrap()
        .max_abs_multiplier
}

/// Max |multiplier| converges in the Chebyshev order: N = 16 and 32 agree to
/// 1e-3 (and N = 8 is already within 1e-2) at two points.
#[test]
fn stability_converges_in_chebyshev_order() {
    let plant = PlantParams::printed();
    let g = FeedbackGains::from_thesis_mm_per_rad(0.01, 0.02);
    for (v, t) in [(8.4, 4.0), (10.0, 6.0)] {
        let op = OperatingPoint::at_100_rpm(v, t);
        let m: Vec<f64> = [8, 16, 32]
            .iter()
            .map(|&n| max_multiplier(&plant, &op, g, n))
            .collect();
        assert!((m[1] - m[2]).abs() < 1e-3, "({v},{t}): {m:?}");
        assert!((m[0] - m[2]).abs() < 1e-2, "({v},{t}): {m:?}");
    }
}

/// A steady-state route reduced to the error it reports, if any.
type Solve<'a> = dyn Fn(&OperatingPoint) -> Option<IvtError> + 'a;

/// Both steady-state routes (IHB and shooting) name the bad input: a NaN
/// V_m or T_U, a negative speed; so do the grid sweep and the stability.
#[test]
fn bad_inputs_give_clear_errors() {
    let plant = PlantParams::printed();
    let ihb = |op: &OperatingPoint| solve_steady_state(&plant, op, IhbOptions::default()).err();
    let shooting = |op: &OperatingPoint| {
        shoot_steady_state(&plant, op, None, &ShootingOptions::default()).err()
    };
    let routes: [&Solve; 2] = [&ihb, &shooting];
    let bad = [
        ("v_m", OperatingPoint::at_100_rpm(f64::NAN, 4.0)),
        ("t_u", OperatingPoint::at_100_rpm(8.0, f64::NAN)),
        (
            "omega0",
            OperatingPoint {
                omega0: -1.0,
                ..OperatingPoint::at_100_rpm(8.0, 4.0)
            },
        ),
    ];
    for (k, solve) in routes.iter().enumerate() {
        for (name, op) in &bad {
            let e = solve(op);
            assert!(
                matches!(e, Some(IvtError::Input { name: n, .. }) if n == *name),
                "route {k}, {name}: {e:?}"
            );
        }
    }
    let empty = Grid {
        v_m: vec![],
        ..Grid::thesis()
    };
    assert!(matches!(
        sweep_serial(&plant, &empty, IhbOptions::default()),
        Err(IvtError::EmptyGrid(_))
    ));
    let g = FeedbackGains {
        k: f64::NAN,
        k2: 0.0,
    };
    assert!(delay_stability(
        &plant,
        &OperatingPoint::at_100_rpm(8.4, 4.0),
        g,
        &DelayOptions::default()
    )
    .is_err());
}

/// The whole thesis grid solves (416 points, none failing).
#[test]
fn thesis_grid_solves_everywhere() {
    let pts = common::thesis_grid_serial();
    assert_eq!(pts.len(), 416);
    assert!(pts.iter().all(|p| p.result.is_ok()));
}

/// Issue 7 acceptance: the predicted max |multiplier| (Chebyshev Tau, N = 16)
/// matches the contraction per revolution of a direct simulation of the
/// nonlinear delay loop Eq. 172 started 1 µm off r̄, at three feasible points.
/// The two routes share only the plant model; they agree to 1e-4 relative
/// (largest measured 9.8e-5 at (9.2, 8)), asserted at 2e-4: the simulated
/// contraction is read from 200 revolutions of RK4 (64 steps per segment)
/// and carries an error of that order. Gains k = 1, k2 = 2 mm·rad⁻¹ (ctrl
/// reading, k_SI = 1e-3, 2e-3) make the dominant multiplier 0.7–0.85, well
/// separated from the others (|λ| < 0.4), so 200 revolutions resolve it; the
/// fourth case uses the thesis's 0.01/0.02 (λ ≈ 0.996).
#[test]
fn predicted_multiplier_matches_simulated_contraction() {
    use ivt_design::delay_sim::{check_prediction, DelaySimOptions};
    let plant = PlantParams::printed();
    let cases = [
        (8.4, 4.0, 1.0, 2.0),
        (8.0, 2.0, 1.0, 2.0),
        (9.2, 8.0, 1.0, 2.0),
        (8.4, 4.0, 0.01, 0.02),
    ];
    for (v, t, k, k2) in cases {
        let op = OperatingPoint::at_100_rpm(v, t);
        let g = FeedbackGains::from_thesis_mm_per_rad(k, k2);
        let s = delay_stability(&plant, &op, g, &DelayOptions::default()).unwrap();
        let (c, rel) = check_prediction(&plant, &op, g, &s, &DelaySimOptions::default()).unwrap();
        assert!(
            rel < 2e-4,
            "({v},{t}) k={k}: predicted {} simulated {} (relative {rel:.1e})",
            s.max_abs_multiplier,
            c.measured
        );
    }
}

/// Broyden (thesis Eq. 156–157, default) and Newton reach the same r̄: both
/// stop at ‖R_p‖ < 1e-10 N·m, which bounds their difference far below the
/// truncation error; 1e-9 relative is asserted.
#[test]
fn broyden_and_newton_agree() {
    use ivt_design::steady::IhbMethod;
    let plant = PlantParams::printed();
    for (v, t) in [(8.4, 1.5), (6.0, 6.0), (12.0, 9.0)] {
        let op = OperatingPoint::at_100_rpm(v, t);
        let solve = |method| {
            let o = IhbOptions {
                method,
                ..Default::default()
            };
            solve_steady_state(&plant, &op, o).unwrap().r
        };
        let (b, n) = (solve(IhbMethod::Broyden), solve(IhbMethod::Newton));
        assert!((b - n).abs() <= 1e-9 * n.abs(), "({v},{t}): {b} vs {n}");
    }
}

/// The root README's "Where the thesis and the printed model disagree",
/// open-loop law: by θ-shooting (direct integration, independent of the IHB
/// route) r̄(6 V, 6 N·m) = −0.02435 m to the printed digits, and the band at
/// 100 rpm is V_m ∈ [7.869, 7.869 + 0.1537·T_U]: r̄ changes sign across
/// 7.869 ± 5e-4 V, and reaches r_max = 0.012 m across 7.869 + 0.1537·8 V
/// ± 1e-3 V (the rounding of both printed coefficients at T_U = 8 N·m).
#[test]
fn readme_r_bar_and_band_by_shooting() {
    let r66 = shoot(6.0, 6.0);
    assert!((r66 + 0.02435).abs() <= 5e-6, "r̄(6, 6) = {r66}");
    // Near the lower edge r̄ ≈ ±1e-5 m: the default relative tolerance
    // (1e-13 of max(|r̄|, 1 µm)) is below the rounding floor there, so these
    // sign checks stop at 1e-6 (Newton's last step; the error is its square).
    let sign_check = |v: f64, t: f64| {
        let o = ShootingOptions {
            tol: 1e-6,
            ..ShootingOptions::default()
        };
        shoot_steady_state(
            &PlantParams::printed(),
            &OperatingPoint::at_100_rpm(v, t),
            None,
            &o,
        )
        .unwrap()
        .r
    };
    let (lo_below, lo_above) = (sign_check(7.8685, 4.0), sign_check(7.8695, 4.0));
    assert!(lo_below < 0.0 && lo_above > 0.0, "{lo_below} {lo_above}");
    let v_hi = 7.869 + 0.1537 * 8.0;
    let (hi_below, hi_above) = (sign_check(v_hi - 1e-3, 8.0), sign_check(v_hi + 1e-3, 8.0));
    let r_max = 0.012;
    assert!(
        hi_below < r_max && hi_above > r_max,
        "{hi_below} {hi_above}"
    );
}

/// The root README's Fig. 42 row: at (7 V, 2 N·m) the thesis prints 0.4871
/// (k, k2 = 0.06, 0.12) and 0.7776 (0.01, 0.02). We state 0.988 / 0.998 with
/// k_SI = 1e-3·k and 1.020 / 0.729 reading the numbers as SI, at the default
/// Chebyshev order N = 16 (to half a printed unit, 5e-4); N = 32 moves none
/// of them by more than 1e-3, so the digits are not a discretization
/// artefact; and each differs from the thesis by more than 0.04 (40 printed
/// units), so neither reading reproduces it. The point is under-drive (r̄ < 0 by shooting).
#[test]
fn readme_fig42_multipliers() {
    assert!(shoot(7.0, 2.0) < 0.0);
    let plant = PlantParams::printed();
    let op = OperatingPoint::at_100_rpm(7.0, 2.0);
    let m = |g: FeedbackGains, n: usize| max_multiplier(&plant, &op, g, n);
    let mm = FeedbackGains::from_thesis_mm_per_rad;
    let si = |k, k2| FeedbackGains { k, k2 };
    for (g, stated, thesis) in [
        (mm(0.06, 0.12), 0.988, 0.4871),
        (mm(0.01, 0.02), 0.998, 0.7776),
        (si(0.06, 0.12), 1.020, 0.4871),
        (si(0.01, 0.02), 0.729, 0.7776),
    ] {
        let (m16, m32) = (m(g, 16), m(g, 32));
        eprintln!("{g:?}: N = 16 {m16:.6}, N = 32 {m32:.6}");
        assert!((m16 - stated).abs() <= 5e-4, "{g:?}: {m16} vs {stated}");
        assert!((m32 - m16).abs() < 1e-3, "{g:?}: {m16} vs N = 32 {m32}");
        assert!(
            (stated - thesis).abs() > 0.04,
            "{stated} vs thesis {thesis}"
        );
    }
}

/// The grid stability map (`ivt stability-map`): every point equals
/// `delay_stability` there, `values` lays them out row by row in T_U, the
/// worst case is their maximum; `feasible_only` skips exactly the points the
/// verdict calls under- or over-drive (NaN in `values`); a map where every
/// point fails is `AllFailed`, not a worst case of 0.
#[test]
fn grid_stability_map_layout_skips_and_failures() {
    let plant = PlantParams::printed();
    let g = FeedbackGains::from_thesis_mm_per_rad(2.0, 1.0);
    let opts = DelayOptions::default();
    let grid = Grid {
        v_m: vec![7.0, 8.0, 8.4],
        t_u: vec![4.0, 6.0],
        omega0: ivt_design::thesis_omega0(),
    };
    let all = grid_stability_map(&plant, &grid, false, g, &opts).unwrap();
    assert_eq!((all.entries.len(), all.failed), (6, 0));
    let values = all.values(&grid);
    for ((op, r), v) in all.entries.iter().zip(&values) {
        let direct = delay_stability(&plant, op, g, &opts).unwrap();
        assert_eq!(*r.as_ref().unwrap(), direct.max_abs_multiplier);
        assert_eq!(*v, direct.max_abs_multiplier);
    }
    assert_eq!((all.entries[4].0.v_m, all.entries[4].0.t_u), (8.0, 6.0));
    assert_eq!(all.worst, values.iter().copied().fold(f64::MIN, f64::max));

    let feasible = grid_stability_map(&plant, &grid, true, g, &opts).unwrap();
    let keep = |v: f64, t: f64| ihb(v, t, 7) >= 0.0 && ihb(v, t, 7) <= plant.r_max;
    let expect: Vec<(f64, f64)> = grid
        .operating_points()
        .iter()
        .filter(|op| keep(op.v_m, op.t_u))
        .map(|op| (op.v_m, op.t_u))
        .collect();
    let got: Vec<(f64, f64)> = feasible
        .entries
        .iter()
        .map(|(op, _)| (op.v_m, op.t_u))
        .collect();
    assert_eq!(got, expect);
    assert!(!expect.is_empty() && expect.len() < 6, "{expect:?}");
    let nan = feasible.values(&grid).iter().filter(|v| v.is_nan()).count();
    assert_eq!(nan, 6 - expect.len());

    let hopeless = FeedbackGains::from_thesis_mm_per_rad(1e6, 0.02);
    let one_row = Grid {
        v_m: vec![8.0, 9.0],
        t_u: vec![1.5],
        ..grid
    };
    match grid_stability_map(&plant, &one_row, false, hopeless, &opts) {
        Err(IvtError::AllFailed { points: 2, first }) => assert!(!first.is_empty()),
        other => panic!("expected AllFailed over 2 points, got {other:?}"),
    }
}
