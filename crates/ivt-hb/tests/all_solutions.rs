//! Every solution at one point (issue 27, item 3): the thesis Duffing
//! (Eq. 49, ξ = 0.02, α = ε = 1, F = 0.1) at ω = 1.4 has three period-one orbits.
//! The reference is shooting on an RK4 integration from a grid of initial
//! states (no HB): its distinct fixed points and their stability.

use ivt_hb::orbit::aft::eval_series;
use ivt_hb::{all_solutions, Duffing, HbError, HbOptions, SearchOptions, StabilityKind};

mod common;
use common::shooting::{newton_step, period_map, period_map_jacobian};

/// A fixed point of the period map by Newton from `y`, if it converges.
fn shoot(duffing: &Duffing, omega: f64, mut y: [f64; 2]) -> Option<[f64; 2]> {
    for _ in 0..30 {
        let p = period_map(duffing, omega, y);
        let r = [p[0] - y[0], p[1] - y[1]];
        let [dx, dv] = newton_step(period_map_jacobian(duffing, omega, y), r);
        y = [y[0] + dx, y[1] + dv];
        if !(y[0].abs() < 10.0 && y[1].abs() < 10.0) {
            return None;
        }
        if dx.abs().max(dv.abs()) < 1e-12 {
            return Some(y);
        }
    }
    None
}

/// The largest |multiplier| of the fixed point (eigenvalues of ∂P/∂y).
fn max_multiplier(duffing: &Duffing, omega: f64, y: [f64; 2]) -> f64 {
    let j = period_map_jacobian(duffing, omega, y);
    let (a, b, c, d) = (j[0][0] + 1.0, j[0][1], j[1][0], j[1][1] + 1.0);
    let (tr, det) = (a + d, a * d - b * c);
    let disc = tr * tr / 4.0 - det;
    if disc >= 0.0 {
        (tr / 2.0).abs() + disc.sqrt()
    } else {
        det.sqrt()
    }
}

#[test]
fn thesis_duffing_at_1_4_has_three_orbits_as_shooting_from_a_grid_finds() {
    let omega = 1.4;
    let duffing = Duffing::fig28();
    // Reference: Newton on the period map from a 13×13 grid of states in
    // [−3, 3]², the distinct fixed points (1e-8 apart at most).
    let mut reference: Vec<[f64; 2]> = Vec::new();
    for i in 0..13 {
        for j in 0..13 {
            let y0 = [-3.0 + 0.5 * i as f64, -3.0 + 0.5 * j as f64];
            if let Some(y) = shoot(&duffing, omega, y0) {
                if !reference
                    .iter()
                    .any(|r| (r[0] - y[0]).abs() + (r[1] - y[1]).abs() < 1e-8)
                {
                    reference.push(y);
                }
            }
        }
    }
    assert_eq!(reference.len(), 3, "shooting found {reference:?}");

    let n = 15;
    let hb = HbOptions::new(n, 64);
    let found = all_solutions(&duffing, &hb, omega, &SearchOptions::default()).unwrap();
    assert_eq!(found.solutions.len(), 3, "{:?}", found.report);
    assert!(found.report.exhausted);
    let mut stable = 0;
    for s in &found.solutions {
        let c = s.solution.dof(0);
        let y = [eval_series(c, 0.0, 0), omega * eval_series(c, 0.0, 1)];
        let r = reference
            .iter()
            .min_by(|a, b| {
                let da = (a[0] - y[0]).abs() + (a[1] - y[1]).abs();
                let db = (b[0] - y[0]).abs() + (b[1] - y[1]).abs();
                da.total_cmp(&db)
            })
            .unwrap();
        let err = (r[0] - y[0]).abs().max((r[1] - y[1]).abs());
        let mu = max_multiplier(&duffing, omega, *r);
        eprintln!(
            "orbit at x(0) = {:.10}, ẋ(0) = {:.10}: |shooting − HB| = {err:.1e}, |μ|max shooting {mu:.6}, HB {:.6} ({:?})",
            y[0],
            y[1],
            s.multipliers[0].norm(),
            s.kind
        );
        // RK4 at 4000 steps per period and n = 15 harmonics: both exact to
        // ~1e-10 for this orbit's size.
        assert!(err < 1e-8, "HB {y:?} vs shooting {r:?}");
        assert!((mu - s.multipliers[0].norm()).abs() < 1e-6, "{mu}");
        assert_eq!(s.kind == StabilityKind::Stable, mu < 1.0);
        stable += usize::from(mu < 1.0);
    }
    // The middle orbit is the saddle, the outer two stable.
    assert_eq!(stable, 2);
    assert_eq!(found.solutions[1].kind, StabilityKind::Fold);
}

#[test]
fn away_from_the_resonance_there_is_one_orbit() {
    let duffing = Duffing::fig28();
    let found = all_solutions(
        &duffing,
        &HbOptions::new(9, 32),
        0.5,
        &SearchOptions::default(),
    )
    .unwrap();
    assert_eq!(found.solutions.len(), 1);
    assert!(found.report.exhausted);
    // The start count: the linear solution and 6 amplitudes × 4 phases.
    assert_eq!(found.report.starts, 25);
}

#[test]
fn bad_bounds_are_invalid_input() {
    let duffing = Duffing::fig28();
    let bad = SearchOptions {
        max_amplitude: -1.0,
        ..SearchOptions::default()
    };
    assert!(matches!(
        all_solutions(&duffing, &HbOptions::new(5, 16), 1.4, &bad),
        Err(HbError::InvalidInput(_))
    ));
    assert!(matches!(
        all_solutions(
            &duffing,
            &HbOptions::new(5, 16),
            f64::NAN,
            &SearchOptions::default()
        ),
        Err(HbError::InvalidInput(_))
    ));
}

/// The bounds docs/guide/src/model/all-solutions.md states: 6 amplitudes (× 4 phases), 60 steps per run, the box
/// 10, deflation power 2 and shift 1.
#[test]
fn defaults_are_the_readme_values() {
    let o = SearchOptions::default();
    assert_eq!(
        (o.amplitudes, o.max_iter, o.max_amplitude, o.power, o.shift),
        (6, 60, 10.0, 2.0, 1.0)
    );
}
