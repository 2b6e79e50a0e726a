//! Hopf point and cycle branch (issue 27, item 2) of
//! `ẍ − (μ + x² − x⁴)ẋ + x = 0`: the subcritical Hopf point at μ = 0, the
//! cycle branch from it, its fold and the two cycles at μ = −0.1, against
//! time integration (RK4, no HB): a cycle through `(x₀, 0)` of period T
//! solves `y(T; x₀, μ) = (x₀, 0)`; a fold of cycles adds
//! `det ∂(y(T) − y₀)/∂(x₀, T) = 0`; the non-trivial multiplier is
//! `det ∂y(T)/∂y₀` (the other is 1).
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_hb::problem::{bautin, boxed_family};
use ivt_hb::{
    cycle_branch, limit_cycle_branch, ContinuationOptions, CycleBranch, CycleBranchOptions,
    HbError, HbOptions, PeriodicProblem, Termination,
};

mod common;
use common::shooting::{central_jacobian, flow, newton3, newton_step, turning_state};

/// The family `ẍ − (μ + x² − x⁴)ẋ + x = 0` (`bautin` at ν = 1).
fn family(mu: f64) -> Result<impl PeriodicProblem, HbError> {
    Ok(bautin(mu, 1.0))
}

/// `y(T)` from `y₀` at μ (RK4, 4000 steps).
fn flow_at(mu: f64, y0: [f64; 2], period: f64) -> [f64; 2] {
    let rhs = |_t: f64, y: [f64; 2]| [y[1], (mu + y[0] * y[0] - y[0].powi(4)) * y[1] - y[0]];
    flow(rhs, y0, period, 4000)
}

/// `y(T; (x₀, 0)) − (x₀, 0)`.
fn gap(mu: f64, x0: f64, period: f64) -> [f64; 2] {
    let y = flow_at(mu, [x0, 0.0], period);
    [y[0] - x0, y[1]]
}

/// The cycle through `(x₀, 0)` at μ by Newton in `(x₀, T)`.
fn cycle_by_shooting(mu: f64, mut u: [f64; 2]) -> [f64; 2] {
    for _ in 0..30 {
        let r = gap(mu, u[0], u[1]);
        let j = central_jacobian(|u| gap(mu, u[0], u[1]), u, [1e-6; 2]);
        let d = newton_step(j, r);
        u = [u[0] + d[0], u[1] + d[1]];
        if d[0].abs().max(d[1].abs()) < 1e-13 {
            break;
        }
    }
    u
}

/// The non-trivial multiplier `det ∂y(T)/∂y₀` of the cycle `(x₀, T)`.
fn multiplier(mu: f64, x0: f64, period: f64) -> f64 {
    let j = central_jacobian(|y| flow_at(mu, y, period), [x0, 0.0], [1e-6; 2]);
    j[0][0] * j[1][1] - j[0][1] * j[1][0]
}

/// The cycle branch of `family` over −0.2 ≤ μ ≤ 0.1 (n = 25), with the
/// cycles at μ = −0.1, and its HB options.
fn branch_over_the_hopf_point() -> (HbOptions, CycleBranch) {
    let hb = HbOptions::new(25, 128);
    let opts = CycleBranchOptions {
        at: vec![-0.1],
        ..CycleBranchOptions::default()
    };
    let branch = cycle_branch(&boxed_family(family), &hb, -0.2, 0.1, &opts).unwrap();
    (hb, branch)
}

#[test]
fn subcritical_hopf_cycle_branch_and_fold_match_time_integration() {
    let (_, branch) = branch_over_the_hopf_point();
    assert_eq!(branch.hopf.len(), 1);
    let hopf = &branch.hopf[0];
    assert!(
        hopf.p.abs() < 1e-12 && (hopf.omega - 1.0).abs() < 1e-12,
        "{hopf:?}"
    );
    assert!(hopf.subcritical(), "l₁ = {}", hopf.lyapunov);
    // The fold of cycles: one, against shooting on (x₀, T, μ).
    assert_eq!(
        branch.folds.len(),
        1,
        "{:?}",
        branch.folds.iter().map(|f| f.0).collect::<Vec<_>>()
    );
    let (mu_fold, orbit) = &branch.folds[0];
    let guess = [
        turning_state(&orbit.coeffs),
        std::f64::consts::TAU / orbit.omega_f,
        *mu_fold,
    ];
    let u = newton3(
        |u| {
            let r = gap(u[2], u[0], u[1]);
            let j = central_jacobian(|w| gap(u[2], w[0], w[1]), [u[0], u[1]], [1e-6; 2]);
            [r[0], r[1], j[0][0] * j[1][1] - j[0][1] * j[1][0]]
        },
        guess,
    );
    eprintln!(
        "fold: HB μ = {mu_fold:.12}, shooting {:.12}, |Δ| {:.1e}",
        u[2],
        (mu_fold - u[2]).abs()
    );
    assert!((mu_fold - u[2]).abs() < 1e-8, "{mu_fold} vs {}", u[2]);
    // μ = −0.1: the small unstable cycle and the large stable one.
    assert_eq!(branch.at.len(), 2);
    let mut cycles: Vec<_> = branch.at.iter().map(|(_, c)| c).collect();
    cycles.sort_by(|a, b| a.solution.amplitude(0).total_cmp(&b.solution.amplitude(0)));
    for (cycle, stable) in cycles.iter().zip([false, true]) {
        let x0 = turning_state(&cycle.solution.coeffs);
        let [x_ref, t_ref] = cycle_by_shooting(-0.1, [x0, cycle.period()]);
        let mult = multiplier(-0.1, x_ref, t_ref);
        eprintln!(
            "μ = −0.1: x₀ {x0:.10} (shooting {x_ref:.10}), T {:.12} (shooting {t_ref:.12}), multiplier {mult:.6}",
            cycle.period()
        );
        assert!((cycle.period() - t_ref).abs() < 1e-8 * t_ref);
        assert_eq!(cycle.stable(), stable);
        assert_eq!(mult < 1.0, stable, "multiplier {mult}");
    }
    // Along the branch, the stability changes only at the fold.
    let changes = branch
        .points
        .windows(2)
        .filter(|w| w[0].1.stable() != w[1].1.stable())
        .count();
    assert_eq!(changes, 1);
    assert!(branch.unlocated.is_empty(), "{:?}", branch.unlocated);
}

/// A family with no member at μ = −0.1 exactly (the path steps over it):
/// the branch passes μ = −0.1 on the small and on the large cycles but
/// cannot solve either there. Both are `unlocated` with the value, the
/// locator's start near μ = −0.1 and the reason (the solver's, then the
/// family's error); the cycles at μ = −0.05 and the fold are located as
/// usual.
#[test]
fn an_at_value_where_the_family_fails_is_reported_unlocated() {
    let hb = HbOptions::new(25, 128);
    let opts = CycleBranchOptions {
        at: vec![-0.1, -0.05],
        ..CycleBranchOptions::default()
    };
    let gappy = |mu: f64| {
        if mu == -0.1 {
            Err(HbError::InvalidInput("no model at μ = -0.1".into()))
        } else {
            family(mu)
        }
    };
    let branch = cycle_branch(&boxed_family(gappy), &hb, -0.2, 0.1, &opts).unwrap();
    let located: Vec<f64> = branch.at.iter().map(|(p, _)| *p).collect();
    assert_eq!(located, [-0.05, -0.05], "{located:?}");
    assert_eq!(branch.folds.len(), 1);
    assert_eq!(branch.unlocated.len(), 2, "{:?}", branch.unlocated);
    for u in &branch.unlocated {
        assert_eq!((u.what, u.value), ("at", Some(-0.1)));
        assert!((u.near.0 + 0.1).abs() < 0.05, "near μ = {}", u.near.0);
        assert!(
            u.reason
                .ends_with("; the family fails there: invalid input: no model at μ = -0.1"),
            "{}",
            u.reason
        );
        eprintln!(
            "unlocated at μ = −0.1 from μ = {:.4}: {}",
            u.near.0, u.reason
        );
    }
}

/// `limit_cycle_branch` from the small cycle at μ = −0.1 towards −0.2 turns
/// at the fold of cycles and comes back on the large cycles: its one event is
/// that turn, estimated by the stepper from a parabola through the three
/// points around it. The fold that `cycle_branch` locates (checked against
/// shooting above) lies beyond those points in μ, and the estimate is nearer
/// to it than the nearest of them.
#[test]
fn limit_cycle_branch_reports_its_turn_at_the_fold_of_cycles() {
    let (hb, located) = branch_over_the_hopf_point();
    let mu_fold = located.folds[0].0;
    let small = located
        .at
        .iter()
        .map(|(_, c)| c)
        .min_by(|a, b| a.solution.amplitude(0).total_cmp(&b.solution.amplitude(0)))
        .unwrap();
    let path = ContinuationOptions {
        ds: 0.01,
        ..ContinuationOptions::default()
    };
    let family = |mu: f64| family(mu).unwrap();
    let branch = limit_cycle_branch(family, &hb, small, -0.1, -0.2, &path, 512).unwrap();
    assert_eq!(branch.termination, Termination::LeftInterval);
    assert_eq!(branch.events.len(), 1, "{:?}", branch.events);
    let turn = &branch.events[0];
    let mus: Vec<f64> = branch.points[turn.bracket..turn.bracket + 3]
        .iter()
        .map(|(mu, _)| *mu)
        .collect();
    let lo = mus.iter().copied().fold(f64::INFINITY, f64::min);
    eprintln!(
        "turn μ = {:.10} (nearest point {lo:.10}), located {mu_fold:.10}, |Δ| {:.1e}",
        turn.lambda,
        (turn.lambda - mu_fold).abs()
    );
    assert!(mu_fold < lo, "{mus:?} vs {mu_fold}");
    assert!(
        (turn.lambda - mu_fold).abs() < lo - mu_fold,
        "{} vs {mu_fold} ({mus:?})",
        turn.lambda
    );
    // The turn's point is a stability change: small cycles unstable, large stable.
    assert!(!branch.points[0].1.stable() && branch.points.last().unwrap().1.stable());
}
