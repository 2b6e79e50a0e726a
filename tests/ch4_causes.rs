//! What does and does not explain the Chapter 4 numbers that stay
//! unreproduced: Fig. 42's max |multiplier| at (7 V, 2 N·m) — printed 0.7776
//! for (k, k2) = (0.01, 0.02) mm·rad⁻¹ and 0.4871 for (0.06, 0.12), ours on
//! thesis-ch4 0.7866 and 0.6044. Each test takes one hypothesis for how the
//! thesis computed its number and shows it does not give the printed digits
//! of both multipliers (A0's b3 of §3.2.5 is in `tests/a0_causes.rs`).
// A test may expect (the package's panic lints guard library code).
#![allow(clippy::expect_used)]

// The feedback law and its gains: `tests/ch4_causes_law.rs`.

#[path = "common/fig42.rs"]
mod fig42;

use core::f64::consts::PI;
use fig42::{fig42_orbit, fig42_point, max_without_structural, miss, printed_pair, OURS, PRINTED};
use ivt_design::delay::{steady_orbit, system_matrix, DelayOptions, FeedbackGains};
use ivt_design::shooting::{omega_at_angles, periodic_at_r, shoot_steady_state, ShootingOptions};
use ivt_design::steady::{solve_steady_state, IhbOptions, Quadrature};
use ivt_design::OperatingPoint;
use ivt_hb::stability::floquet::{monodromy_hsu, HsuRule};
use ivt_kin::plant::{GravityModel, PlantParams, PlantPreset};

/// §4.3 computes the transformation matrix by Hsu's method [57], Eq. 80: a
/// product of exp(Δθ 𝒜(θ_i)) over N_Q sub-intervals with 𝒜 frozen at each
/// sub-interval's end (first order). Over N_Q = 8…1000 it never comes below
/// ours: 0.7866…0.858 and 0.6044…0.645, never the printed 0.7776 / 0.4871.
/// The dense 𝒜(θ) itself (`system_matrix`) is checked first: with the
/// second-order midpoint rule and N_Q = 1000 it gives our RK6 values to 1e-4.
#[test]
fn hsu_transformation_matrix_is_not_the_cause() {
    let (plant, op, orbit) = fig42_orbit();
    let opts = DelayOptions::default();
    let dim = opts.chebyshev_order + 3;
    let hsu = |k: f64, k2: f64, n_q: usize, rule: HsuRule| {
        let gains = FeedbackGains::from_thesis_mm_per_rad(k, k2);
        // Hsu samples 𝒜 at θ_j = 2πj/(2 N_Q); ω̄ there by RK6 on the orbit.
        let omega = omega_at_angles(
            &plant,
            op.v_m,
            op.t_u,
            orbit.r,
            orbit.omega_start,
            2 * n_q,
            8,
        )
        .expect("orbit samples");
        let m = monodromy_hsu(dim, 2.0 * PI, n_q, rule, |theta, out| {
            let j = (theta / PI * n_q as f64).round() as usize % (2 * n_q);
            let a = system_matrix(&plant, &op, gains, orbit.r, theta, omega[j], &opts)
                .expect("system matrix");
            // DMatrix is column-major; Hsu wants row-major.
            out.copy_from_slice(a.transpose().as_slice());
        });
        max_without_structural(&m, dim)
    };
    for ((k, k2, printed), ours) in PRINTED.into_iter().zip(OURS) {
        let mid = hsu(k, k2, 1000, HsuRule::Midpoint);
        assert!((mid - ours).abs() < 1e-4, "midpoint {mid} vs RK6 {ours}");
        for n_q in [8, 16, 20, 32, 40, 50, 64, 100, 128, 200, 256, 500, 1000] {
            let left = hsu(k, k2, n_q, HsuRule::Left);
            assert!(
                left > ours - 1e-4 && left < ours + 0.075,
                "k = {k}, N_Q = {n_q}: {left}"
            );
            assert!(left - printed > 0.0085, "k = {k}, N_Q = {n_q}");
        }
    }
}

/// Two orbits the thesis might have linearized about instead of the exact
/// unconstrained one (r̄ = 0.02422 m):
/// - the saturated one: (7 V, 2 N·m) is over-drive (Eq. 159 > 0), so the law
///   Eq. 160 applies u_ol = r_max = 0.012 m; that orbit runs at ~496 rpm and
///   gives 0.99/0.98 with K = −k ω0²/2π, 0.93/0.84 with ω0 replaced by the
///   orbit's own mean speed in K;
/// - the n = 7 modified IHB orbit of Fig. 39 (equally spaced AFT samples,
///   the thesis's route): r̄ = 0.024202 m (7e-4 below the exact one), and
///   the multipliers rise to 0.7903 / 0.6089, away from the print.
#[test]
fn saturated_or_n7_orbit_is_not_the_cause() {
    let plant = PlantPreset::ThesisCh4.params();
    let op = fig42_point();
    let shoot = ShootingOptions::default();
    let sat = periodic_at_r(&plant, op.v_m, op.t_u, plant.r_max, op.omega0, &shoot)
        .expect("saturated orbit");
    assert!(sat.omega_a() > 4.0 * op.omega0, "{}", sat.omega_a());
    // K = −k ω0²/2π with ω0, then with the orbit's own mean speed.
    for (omega0, floor) in [(op.omega0, [0.99, 0.98]), (sat.omega_a(), [0.92, 0.83])] {
        let pair = printed_pair(&plant, &OperatingPoint { omega0, ..op }, &sat, (1.0, 1.0));
        assert!(
            pair[0] > floor[0] && pair[1] > floor[1] && pair[0] < 1.0,
            "saturated, K with {omega0}: {pair:?}"
        );
    }
    let ihb = IhbOptions {
        harmonics: 7,
        quadrature: Quadrature::Uniform,
        ..IhbOptions::default()
    };
    let n7 = solve_steady_state(&plant, &op, ihb).expect("IHB n = 7");
    let exact = steady_orbit(&plant, &op, None, &DelayOptions::default()).expect("orbit");
    assert!(
        (n7.r - exact.r).abs() / exact.r < 2e-3,
        "{} {}",
        n7.r,
        exact.r
    );
    let n7_orbit =
        periodic_at_r(&plant, op.v_m, op.t_u, n7.r, exact.omega_start, &shoot).expect("n7");
    let pair = printed_pair(&plant, &op, &n7_orbit, (1.0, 1.0));
    for (got, want) in pair.into_iter().zip([0.7903, 0.6089]) {
        assert!((got - want).abs() < 1e-4, "n = 7 orbit: {got}");
    }
    assert!(miss(pair) > 0.1);
}

/// Thesis-ch4 with k_t and k_e scaled by (s_t, s_e) from the printed Table 1.
fn motor_scaled(s_t: f64, s_e: f64) -> PlantParams {
    let mut p = PlantParams::printed();
    p.k_t *= s_t;
    p.k_e *= s_e;
    p
}

/// r̄ at (V_m, T_U) by shooting.
fn r_bar(plant: &PlantParams, v_m: f64, t_u: f64) -> f64 {
    let op = OperatingPoint::at_100_rpm(v_m, t_u);
    shoot_steady_state(plant, &op, None, &ShootingOptions::default())
        .expect("steady state")
        .r
}

/// Thesis-ch4 with every inertia of Table 1 (`all`) or only those of J_a
/// scaled by `s`; r̄ hardly depends on them (no inertia in the mean power
/// balance), the multipliers do.
fn inertia_scaled(s: f64, all: bool) -> PlantParams {
    let mut p = PlantPreset::ThesisCh4.params();
    for j in [
        &mut p.j_n2,
        &mut p.j_carrier,
        &mut p.j_inshaft,
        &mut p.j_crk,
        &mut p.j_ring,
    ] {
        *j *= s;
    }
    if all {
        for j in [&mut p.j_n1, &mut p.m_r, &mut p.m_dr, &mut p.j_u] {
            *j *= s;
        }
    }
    p
}

/// Nearby thesis-ch4 variants that keep the printed steady states:
/// - k_t and k_e scaled separately from Table 1: for k_e ÷ (5…17) and k_t
///   set so that r̄(7 V, 2 N·m) = 0.0242 m (Eq. 158), the second multiplier
///   stays above 0.54 (printed 0.4871); where r̄(6 V, 6 N·m) also prints
///   Fig. 39's 0.0067 (k_e ÷ 6.1…8.8, k_t ÷ 9.2…9.8) the pair is 0.83–0.89 /
///   0.62–0.68, further off than ÷10 (0.7866 / 0.6044);
/// - the inertias (all of Table 1, or J_a's alone) scaled by s: r̄ moves by
///   < 1e-3 relative for s ≤ 1.6, and at both s in [1, 1.6] where the first
///   multiplier is the printed 0.7776 (bisection: ×1.048 and ×1.472 for all,
///   ×1.056 and ×1.549 for J_a's), the second is 0.599 or 0.515 (printed
///   0.4871); at ×1.6 (all) the second is below the print (0.449) and the
///   first above ours (0.795);
/// - G = m_r g (sin θ + cos θ) (the Eq. 148 form): 0.784 / 0.602.
#[test]
fn nearby_plants_keeping_r_bar_are_not_the_cause() {
    let op = fig42_point();
    let mut admissible = 0;
    for i in 0..=28 {
        let s_e = 0.06 + 0.005 * i as f64;
        // s_t on r̄(7 V, 2 N·m) = 0.0242 m (secant), then Fig. 39's r̄(6, 6).
        let (mut a, mut b) = (0.09, 0.11);
        let g = |s_t: f64| r_bar(&motor_scaled(s_t, s_e), 7.0, 2.0) - 0.0242;
        let (mut fa, mut fb) = (g(a), g(b));
        for _ in 0..20 {
            if (fb - fa).abs() < 1e-15 {
                break;
            }
            let c = b - fb * (b - a) / (fb - fa);
            (a, fa) = (b, fb);
            (b, fb) = (c, g(c));
        }
        let plant = motor_scaled(b, s_e);
        let r66 = r_bar(&plant, 6.0, 6.0);
        let orbit = steady_orbit(&plant, &op, None, &DelayOptions::default()).expect("orbit");
        let pair = printed_pair(&plant, &op, &orbit, (1.0, 1.0));
        assert!(pair[1] > 0.54, "s_e = {s_e}: {pair:?}");
        if (r66 - 0.0067).abs() <= 5e-5 {
            admissible += 1;
            assert!(miss(pair) > 0.04, "s_e = {s_e}: {pair:?}");
        }
    }
    assert!(admissible >= 8, "{admissible}");
    for all in [true, false] {
        let at = |s: f64| {
            let p = inertia_scaled(s, all);
            let orbit = steady_orbit(&p, &op, None, &DelayOptions::default()).expect("orbit");
            assert!((orbit.r - 0.02422).abs() < 2.5e-5, "s = {s}: r̄ {}", orbit.r);
            printed_pair(&p, &op, &orbit, (1.0, 1.0))
        };
        let mut crossings = 0;
        let grid: Vec<f64> = (0..=24).map(|i| 1.0 + 0.025 * i as f64).collect();
        for w in grid.windows(2) {
            let (mut lo, mut hi) = (w[0], w[1]);
            let sign = |s: f64| at(s)[0] > PRINTED[0].2;
            if sign(lo) == sign(hi) {
                continue;
            }
            let s_lo = sign(lo);
            for _ in 0..30 {
                let mid = 0.5 * (lo + hi);
                if sign(mid) == s_lo {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let pair = at(0.5 * (lo + hi));
            assert!((pair[0] - PRINTED[0].2).abs() < 1e-3, "{pair:?}");
            let second = if lo < 1.2 { 0.599 } else { 0.5154 };
            assert!(
                (pair[1] - second).abs() < 1e-3,
                "×{lo} (all: {all}): {pair:?}"
            );
            crossings += 1;
        }
        assert!(crossings >= 2, "all: {all}: {crossings}");
        if all {
            // Heavier still, the second gets below the print, the first not.
            let heavy = at(1.6);
            let d = [heavy[0] - 0.7947, heavy[1] - 0.4493];
            assert!(d[0].abs() < 1e-3 && d[1].abs() < 1e-3, "×1.6: {heavy:?}");
        }
    }

    let mut roller = PlantPreset::ThesisCh4.params();
    roller.gravity = GravityModel::RollerMass;
    let orbit = steady_orbit(&roller, &op, None, &DelayOptions::default()).expect("orbit");
    assert!((orbit.r - 0.02422).abs() < 2.5e-5, "{}", orbit.r);
    let pair = printed_pair(&roller, &op, &orbit, (1.0, 1.0));
    for (got, ours) in pair.into_iter().zip(OURS) {
        assert!((got - ours).abs() < 5e-3, "roller mass: {got} vs {ours}");
    }
}
