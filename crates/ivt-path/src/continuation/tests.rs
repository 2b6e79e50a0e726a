//! The stepper on the unit circle `u² + λ² = 1` (folds at λ = ±1) with
//! both correctors: the folds, the landing on a bound, and the traced
//! result's JSON.

use super::*;
use crate::branch::{Branch, ResidualBranch};

/// `u² + λ² = 1` with its exact derivatives.
struct Circle;

impl Branch for Circle {
    fn len(&self) -> usize {
        1
    }
    fn residual(&mut self, u: &[f64], lambda: f64, r: &mut [f64]) {
        r[0] = u[0] * u[0] + lambda * lambda - 1.0;
    }
    fn jacobian(&mut self, u: &[f64], _lambda: f64, jac: &mut [f64]) {
        jac[0] = 2.0 * u[0];
    }
    fn residual_lambda(&mut self, _u: &[f64], lambda: f64, _h: f64, r_lambda: &mut [f64]) {
        r_lambda[0] = 2.0 * lambda;
    }
}

/// The circle's residual alone, for the Broyden corrector.
fn circle_residual() -> ResidualBranch<impl FnMut(&[f64], &mut [f64])> {
    ResidualBranch::new(1, |x: &[f64], r: &mut [f64]| {
        r[0] = x[0] * x[0] + x[1] * x[1] - 1.0
    })
}

#[test]
fn broyden_traces_a_circle_through_both_folds() {
    // x² + λ² = 1 from (x, λ) = (−0.6, 0.8): folds at λ = ±1 (x = 0).
    let opts = ContinuationOptions {
        ds: 0.05,
        max_points: 200,
        lambda_min: -2.0,
        lambda_max: 2.0,
        ..Default::default()
    };
    let mut branch = circle_residual();
    let corrector = Box::new(BroydenCorrector::new(1, &opts.broyden, None));
    let mut n = 0;
    let path = Stepper::new(&mut branch, corrector, &[-0.6, 0.8], 0, 1.0, &opts)
        .unwrap()
        .run(|_, p| {
            n += 1;
            assert!((p.x[0] * p.x[0] + p.x[1] * p.x[1] - 1.0).abs() < 1e-9);
            n < 150
        });
    assert!(path.events.len() >= 2, "{:?}", path.events);
    assert!(
        (path.events[0].lambda - 1.0).abs() < 1e-3,
        "{:?}",
        path.events
    );
    assert!(
        (path.events[1].lambda + 1.0).abs() < 1e-3,
        "{:?}",
        path.events
    );
}

/// A first step (0.3) far longer than the interval λ ∈ [0.8, 0.85] on
/// the circle x² + λ² = 1: the path ends on λ = 0.85 exactly, on the
/// circle (x = −√(1 − 0.85²)), and no point lies outside the interval,
/// with either corrector.
#[test]
fn a_long_step_lands_on_the_bound_and_never_leaves_the_interval() {
    let opts = ContinuationOptions {
        ds: 0.3,
        lambda_min: 0.8,
        lambda_max: 0.85,
        ..Default::default()
    };
    let mut broyden = circle_residual();
    let corrector = Box::new(BroydenCorrector::new(1, &opts.broyden, None));
    let by_broyden = Stepper::new(&mut broyden, corrector, &[-0.6, 0.8], 0, 1.0, &opts)
        .unwrap()
        .run(|_, _| true);
    let by_newton = Stepper::new(
        &mut Circle,
        Box::new(NewtonCorrector::new(1, &opts)),
        &[-0.6, 0.8],
        0,
        1.0,
        &opts,
    )
    .unwrap()
    .run(|_, _| true);
    for path in [by_broyden, by_newton] {
        assert_eq!(path.termination, Termination::LeftInterval);
        for p in &path.points {
            assert!((0.8..=0.85).contains(&p.lambda()), "{:?}", path.points);
        }
        let last = path.points.last().unwrap();
        assert_eq!(last.lambda(), 0.85);
        let x_exact = -(1.0f64 - 0.85 * 0.85).sqrt();
        assert!((last.x[0] - x_exact).abs() < 1e-9, "{last:?}");
    }
}

/// The circle by the Newton corrector from (u, λ) = (−0.6, 0.8) upwards:
/// over the fold at λ = 1 and back down to the bound λ = −0.99, where the
/// path must end exactly; every point on the circle to 1e-10.
fn newton_circle_over_its_fold() -> Path {
    let opts = ContinuationOptions {
        ds: 0.05,
        ds_max: 0.1,
        max_points: 400,
        lambda_min: -0.99,
        lambda_max: 2.0,
        ..Default::default()
    };
    let corrector = Box::new(NewtonCorrector::new(1, &opts));
    Stepper::new(&mut Circle, corrector, &[-0.6, 0.8], 0, 1.0, &opts)
        .unwrap()
        .run(|_, p| {
            assert!((p.x[0] * p.x[0] + p.x[1] * p.x[1] - 1.0).abs() <= 1e-10);
            true
        })
}

#[test]
fn newton_traces_a_circle_over_its_fold_onto_the_bound() {
    let path = newton_circle_over_its_fold();
    assert_eq!(path.termination, Termination::LeftInterval);
    assert_eq!(path.points.last().unwrap().lambda(), -0.99);
    assert_eq!(path.events.len(), 1, "{:?}", path.events);
    // The parabola through three points 0.1 apart on the unit circle.
    assert!(
        (path.events[0].lambda - 1.0).abs() < 1e-3,
        "{:?}",
        path.events
    );
}

/// The stepper hands out points one by one and then repeats its stop; the
/// residual branch's forward-difference Jacobian is the circle's `2u` to
/// the difference's O(h).
#[test]
fn next_repeats_its_stop_and_the_residual_branch_differences_its_jacobian() {
    let mut opts = ContinuationOptions::default();
    (opts.ds, opts.max_points) = (0.05, 3);
    let mut circle = Circle;
    let mut stepper = Stepper::new(
        &mut circle,
        Box::new(NewtonCorrector::new(1, &opts)),
        &[-0.6, 0.8],
        0,
        1.0,
        &opts,
    )
    .unwrap();
    let mut points = 0;
    while let Step::Point(_) = stepper.next() {
        points += 1;
    }
    assert_eq!(points, 3);
    assert_eq!(stepper.next(), Step::Stop(Termination::MaxPoints));
    let mut jac = [0.0];
    circle_residual().jacobian(&[-0.6], 0.8, &mut jac);
    assert!((jac[0] + 1.2).abs() < 1e-6, "{jac:?}");
}

/// A traced result serializes as `points`, `events` and `termination` (the
/// snake_case word, SPEC §6): the circle's path over its fold at λ = 1 onto
/// the bound λ = −0.99, read as its λ values and its fold's λ.
#[test]
fn a_traced_curve_serializes_its_points_events_and_termination_word() {
    let path = newton_circle_over_its_fold();
    let read = Traced {
        points: path
            .points
            .iter()
            .map(PathPoint::lambda)
            .collect::<Vec<_>>(),
        events: path.events.iter().map(|f| f.lambda).collect::<Vec<_>>(),
        termination: path.termination,
    };
    let v = serde_json::to_value(&read).unwrap();
    let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort_unstable();
    assert_eq!(keys, ["events", "points", "termination"]);
    assert_eq!(v["termination"], "left_interval");
    assert_eq!(v["points"].as_array().unwrap().len(), read.points.len());
    assert_eq!(v["points"][0], 0.8);
    assert_eq!(v["points"][read.points.len() - 1], -0.99);
    let events = v["events"].as_array().unwrap();
    assert_eq!(events.len(), 1, "{events:?}");
    assert!(
        (events[0].as_f64().unwrap() - 1.0).abs() < 1e-3,
        "{events:?}"
    );
}
