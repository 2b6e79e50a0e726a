//! Issue 41, items 3–4: searches that say what they found and refuse what
//! they cannot answer. References are closed forms, never HB:
//! - the damped linear response `a₁ = F(α − ω²)/((α − ω²)² + (2ξω)²)`,
//!   `b₁ = 2ξωF/(…)` (the cubic term of Duffing is below rounding at ω = 1e6);
//! - the undamped linear response `F/(α − ω²)` and its resonances `h·ω = √α`;
//! - the free Duffing oscillator `ẍ + x + x³ = 0`: amplitude A has the
//!   frequency `ω(A) = π√(1 + A²) / (2K(m))`, `m = A²/(2(1 + A²))` (K the
//!   complete elliptic integral, by the arithmetic–geometric mean);
//! - the eigenvalues `μ/2 ± √(μ²/4 − 1)` of `ẍ − μẋ + x = 0` (a complex pair
//!   crosses at μ = 0 with ω = 1 and turns real at μ = ±2).
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_hb::problem::boxed_family;
use ivt_hb::{
    all_solutions, cycle_branch, hopf_points, CycleBranchOptions, GeneralProblem, HbError,
    HbOptions, PeriodicProblem, SearchOptions,
};

/// `ẍ + 2ξẋ + αx + εx³ = F cos θ`.
fn duffing(xi: f64, alpha: f64, eps: f64, force: f64) -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![2.0 * xi],
        vec![alpha],
        move |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| g[0] = eps * x[0].powi(3),
        move |t: f64, f: &mut [f64]| f[0] = force * t.cos(),
    )
    .with_velocity_dependent(false)
}

#[test]
fn large_omega_finds_the_one_orbit_of_the_damped_duffing() {
    let (xi, force) = (0.02, 0.1);
    for omega in [1e3, 1e6] {
        let all = all_solutions(
            &duffing(xi, 1.0, 1.0, force),
            &HbOptions::new(20, 64),
            omega,
            &SearchOptions::default(),
        )
        .unwrap();
        assert_eq!(all.solutions.len(), 1, "ω = {omega}");
        let q = &all.solutions[0].solution.coeffs;
        let d = (1.0 - omega * omega).powi(2) + (2.0 * xi * omega).powi(2);
        let (a1, b1) = (
            force * (1.0 - omega * omega) / d,
            force * 2.0 * xi * omega / d,
        );
        assert!(
            (q[1] - a1).abs() <= 1e-9 * a1.abs(),
            "ω = {omega}: a1 {} vs {a1}",
            q[1]
        );
        assert!(
            (q[21] - b1).abs() <= 1e-6 * a1.abs(),
            "ω = {omega}: b1 {} vs {b1}",
            q[21]
        );
        assert!(all.report.exhausted && all.report.bound.contains("1 failed run per start"));
    }
}

#[test]
fn undamped_linear_system_found_off_resonance_and_refused_at_one() {
    let force = 0.1;
    let hb = HbOptions::new(20, 64);
    let omega = 0.7; // h·0.7 ≠ 1 for every h ≤ 20
    let all = all_solutions(
        &duffing(0.0, 1.0, 0.0, force),
        &hb,
        omega,
        &SearchOptions::default(),
    )
    .unwrap();
    assert_eq!(all.solutions.len(), 1);
    let a1 = force / (1.0 - omega * omega);
    let q = &all.solutions[0].solution.coeffs;
    assert!((q[1] - a1).abs() <= 1e-10 * a1, "{} vs {a1}", q[1]);
    // ω = 1: harmonic 1 resonates and the load excites it (no periodic
    // orbit); ω = 0.5: harmonic 2 resonates unloaded (a continuum).
    for (omega, h) in [(1.0, 1), (0.5, 2)] {
        let err = all_solutions(
            &duffing(0.0, 1.0, 0.0, force),
            &hb,
            omega,
            &SearchOptions::default(),
        )
        .unwrap_err();
        let HbError::InvalidInput(why) = &err else {
            panic!("{err:?}")
        };
        assert!(why.contains(&format!("singular at harmonic {h} ")), "{why}");
    }
}

/// K(m) by the arithmetic–geometric mean.
fn elliptic_k(m: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - m).sqrt());
    // Quadratic convergence: 30 steps are far past double precision.
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
}

/// The free frequency of `ẍ + x + x³ = 0` at amplitude `a`.
fn free_frequency(a: f64) -> f64 {
    let m = a * a / (2.0 * (1.0 + a * a));
    std::f64::consts::PI * (1.0 + a * a).sqrt() / (2.0 * elliptic_k(m))
}

#[test]
fn unforced_undamped_orbits_are_reported_once_each_not_per_phase() {
    let omega = 1.4;
    let all = all_solutions(
        &duffing(0.0, 1.0, 1.0, 0.0),
        &HbOptions::new(20, 64),
        omega,
        &SearchOptions::default(),
    )
    .unwrap();
    // The rest point, the orbit of free frequency 1.4 and the one of 3·1.4
    // (period 2π/4.2 is also 2π/1.4-periodic); today's search found 7 with
    // the phase-shifted copies.
    let amplitudes: Vec<f64> = all
        .solutions
        .iter()
        .map(|s| s.solution.amplitude(0))
        .collect();
    assert_eq!(amplitudes.len(), 3, "{amplitudes:?}");
    assert!(amplitudes[0] < 1e-12);
    // The second keeps only its harmonics 3, 9, 15 of 1.4 at n = 20 (three
    // of its own): its truncation error is larger (measured 7e-5).
    for ((a, h), tol) in amplitudes[1..].iter().zip([1.0, 3.0]).zip([1e-8, 2e-4]) {
        let w = free_frequency(*a);
        assert!(
            (w - h * omega).abs() < tol * w,
            "A = {a}: ω(A) = {w}, not {}",
            h * omega
        );
    }
    assert!(all.report.copies_merged >= 2, "{:?}", all.report);
    // A forced problem keeps its distinct orbits (the three at 1.4).
    let forced = all_solutions(
        &duffing(0.02, 1.0, 1.0, 0.1),
        &HbOptions::new(20, 64),
        omega,
        &SearchOptions::default(),
    )
    .unwrap();
    assert_eq!(forced.solutions.len(), 3);
    assert_eq!(forced.report.copies_merged, 0);
}

/// `ẍ − μẋ + x + x²ẋ = 0` (the pair crosses at μ = 0, turns real at μ = ±2).
fn van_der_pol(mu: f64) -> Result<impl PeriodicProblem, HbError> {
    Ok(GeneralProblem::new(
        1,
        vec![1.0],
        vec![-mu],
        vec![1.0],
        |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| g[0] = x[0] * x[0] * v[0],
        |_: f64, f: &mut [f64]| f.fill(0.0),
    ))
}

#[test]
fn hopf_only_where_a_complex_pair_crosses_on_any_range() {
    for (from, to, grid) in [
        (-5.0, 5.0, 100),
        (-1000.0, 1000.0, 100),
        (-0.2, 2.5, 100),
        (-1000.0, 1000.0, 7),
    ] {
        let search = hopf_points(&van_der_pol, &[0.0], from, to, grid).unwrap();
        assert_eq!(
            search.points.len(),
            1,
            "[{from}, {to}]: {:?}",
            search.points
        );
        let h = &search.points[0];
        assert!(h.p.abs() < 1e-12 && (h.omega - 1.0).abs() < 1e-12, "{h:?}");
        assert!(search.undecided.is_empty(), "{:?}", search.undecided);
    }
}

/// Two uncoupled oscillators whose pairs cross at μ = 0 and μ = 3
/// (`C = diag(−μ, μ − 3)`, cubic damping `x²ẋ` on each).
fn two_crossings(mu: f64) -> Result<impl PeriodicProblem, HbError> {
    Ok(GeneralProblem::new(
        2,
        vec![1.0, 0.0, 0.0, 1.0],
        vec![-mu, 0.0, 0.0, mu - 3.0],
        vec![1.0, 0.0, 0.0, 4.0],
        |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| {
            g[0] = x[0] * x[0] * v[0];
            g[1] = x[1] * x[1] * v[1];
        },
        |_: f64, f: &mut [f64]| f.fill(0.0),
    ))
}

#[test]
fn two_crossings_in_one_grid_interval_are_both_located() {
    // Eigenvalues with Re > 0 at μ = −1, 1.5, 4: 2 (the second pair, real),
    // 4 (both pairs, complex), 2 (the first pair, turned real at μ = 2):
    // each change is bisected and classified; the pairs turning real
    // (μ = −1, 2) change no count and are not reported.
    let search = hopf_points(&two_crossings, &[0.0, 0.0], -1.0, 4.0, 2).unwrap();
    let ps: Vec<(f64, f64)> = search.points.iter().map(|h| (h.p, h.omega)).collect();
    assert_eq!(ps.len(), 2, "{ps:?}");
    assert!(
        ps[0].0.abs() < 1e-12 && (ps[0].1 - 1.0).abs() < 1e-12,
        "{ps:?}"
    );
    assert!(
        (ps[1].0 - 3.0).abs() < 1e-12 && (ps[1].1 - 2.0).abs() < 1e-12,
        "{ps:?}"
    );
    // A grid of one interval from −1 to 2.5 (counts 0 and 2, then the second
    // pair's crossing is outside): one point.
    let one = hopf_points(&two_crossings, &[0.0, 0.0], -1.0, 2.5, 1).unwrap();
    assert_eq!(one.points.len(), 1);
}

#[test]
fn cycle_branch_refuses_a_forced_family_and_ends_on_a_failing_member_with_its_cause() {
    let forced = |mu: f64| -> Result<_, HbError> {
        Ok(GeneralProblem::new(
            1,
            vec![1.0],
            vec![-mu],
            vec![1.0],
            |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| g[0] = x[0] * x[0] * v[0],
            |t: f64, f: &mut [f64]| f[0] = 0.1 * t.cos(),
        ))
    };
    let hb = HbOptions::new(10, 32);
    let opts = CycleBranchOptions::default();
    let err = cycle_branch(&boxed_family(forced), &hb, -0.2, 0.1, &opts).unwrap_err();
    assert!(
        err.to_string().contains("excitation f(θ) is not zero"),
        "{err}"
    );
    // g depending on θ (a parametric term) is a forcing too.
    let parametric = |mu: f64| -> Result<_, HbError> {
        Ok(GeneralProblem::new(
            1,
            vec![1.0],
            vec![-mu],
            vec![1.0],
            |x: &[f64], v: &[f64], t: f64, g: &mut [f64]| {
                g[0] = x[0] * x[0] * v[0] + 0.2 * t.cos() * x[0]
            },
            |_: f64, f: &mut [f64]| f.fill(0.0),
        ))
    };
    let err = cycle_branch(&boxed_family(parametric), &hb, -0.2, 0.1, &opts).unwrap_err();
    assert!(err.to_string().contains("depends on θ"), "{err}");
    // g NaN from μ = 0.05 on: the branch (cycles for μ > 0) stalls there and
    // the error names the cause instead of a `step_too_small` end.
    let nan_late = |mu: f64| -> Result<_, HbError> {
        Ok(GeneralProblem::new(
            1,
            vec![1.0],
            vec![-mu],
            vec![1.0],
            move |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| {
                g[0] = if mu < 0.05 {
                    x[0] * x[0] * v[0]
                } else {
                    f64::NAN
                }
            },
            |_: f64, f: &mut [f64]| f.fill(0.0),
        ))
    };
    let err = cycle_branch(&boxed_family(nan_late), &hb, -0.2, 0.1, &opts).unwrap_err();
    assert_eq!(err.kind(), "input");
    assert!(err.to_string().contains("g returned NaN"), "{err}");
    // A family that changes size.
    let resized = |mu: f64| -> Result<GeneralProblem<_, _>, HbError> {
        let n = if mu < 0.05 { 1 } else { 2 };
        Ok(GeneralProblem::new(
            n,
            vec![1.0; n * n],
            vec![-mu; n * n],
            vec![1.0; n * n],
            |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| g[0] = x[0] * x[0] * v[0],
            |_: f64, f: &mut [f64]| f.fill(0.0),
        ))
    };
    let err = cycle_branch(&boxed_family(resized), &hb, -0.2, 0.1, &opts).unwrap_err();
    assert!(err.to_string().contains("changes size"), "{err}");
}
