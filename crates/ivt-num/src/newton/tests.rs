//! Tests of the damped Newton method against closed forms.

use super::*;

/// `F = (x₀² + x₁² − 4, x₀ − x₁)`: root `(√2, √2)`.
struct Circle {
    jacobians_at_last_residual: bool,
    last: Vec<f64>,
}

impl NewtonSystem for Circle {
    type Error = ();
    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), ()> {
        r[0] = x[0] * x[0] + x[1] * x[1] - 4.0;
        r[1] = x[0] - x[1];
        self.last = x.to_vec();
        Ok(())
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), ()> {
        self.jacobians_at_last_residual &= self.last == x;
        jac.copy_from_slice(&[2.0 * x[0], 2.0 * x[1], 1.0, -1.0]);
        Ok(())
    }
}

/// From (3, 1): quadratic convergence to √2 (the error squares each step:
/// 6 steps reach 1e-15), the Jacobian is always asked at the last
/// residual point, and the history falls monotonically.
#[test]
fn converges_quadratically_on_a_circle() {
    let mut sys = Circle {
        jacobians_at_last_residual: true,
        last: Vec::new(),
    };
    let mut x = [3.0, 1.0];
    let mut ws = NewtonWorkspace::new(2);
    let opts = NewtonOptions {
        ftol: 1e-14,
        ..Default::default()
    };
    let stats = newton(&mut sys, &mut x, &mut ws, &opts).unwrap();
    let s2 = 2f64.sqrt();
    assert!(
        (x[0] - s2).abs() < 1e-15 && (x[1] - s2).abs() < 1e-15,
        "{x:?}"
    );
    assert!(
        stats.iterations <= 6 && stats.residual_norm <= 1e-14,
        "{stats:?}"
    );
    assert!(sys.jacobians_at_last_residual);
    assert_eq!(stats.jacobian_evals, stats.iterations);
}

/// The circle `x₀² + x₁² = 4` closed by the border row `x₀ − x₁ = 0`
/// takes the same steps as the square system `Circle` that has that row
/// in its Jacobian (same history to rounding), and lands on the closed
/// form `(√2, √2)`. Two border rows on three unknowns (`x₂ = 0.5`,
/// `x₀ + x₁ = 1` with `F = x₀² − x₁ + x₂`): the root of `x₀² + x₀ − 0.5`,
/// `x₀ = (−1 + √3)/2`.
#[test]
fn border_rows_close_the_system() {
    struct Arc;
    impl NewtonSystem for Arc {
        type Error = ();
        fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), ()> {
            r[0] = x[0] * x[0] + x[1] * x[1] - 4.0;
            Ok(())
        }
        fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), ()> {
            jac.copy_from_slice(&[2.0 * x[0], 2.0 * x[1]]);
            Ok(())
        }
    }
    let opts = NewtonOptions {
        ftol: 1e-14,
        ..Default::default()
    };
    let mut square = Circle {
        jacobians_at_last_residual: true,
        last: Vec::new(),
    };
    let mut x_sq = [3.0, 1.0];
    let mut ws_sq = NewtonWorkspace::new(2);
    newton(&mut square, &mut x_sq, &mut ws_sq, &opts).unwrap();
    let mut x = [3.0, 1.0];
    let mut ws = NewtonWorkspace::new(2);
    let border = Border {
        rows: &[1.0, -1.0],
        values: &[0.0],
        origin: &[],
    };
    let stats = newton_bordered(&mut Arc, border, &mut x, &mut ws, &opts).unwrap();
    assert_eq!(ws.history.len(), ws_sq.history.len());
    for (a, b) in ws.history.iter().zip(&ws_sq.history) {
        assert!((a - b).abs() <= 1e-13 * b.max(1.0), "{:?}", ws.history);
    }
    let s2 = 2f64.sqrt();
    assert!(
        (x[0] - s2).abs() < 1e-15 && (x[1] - s2).abs() < 1e-15,
        "{x:?} {stats:?}"
    );

    struct Parabola;
    impl NewtonSystem for Parabola {
        type Error = ();
        fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), ()> {
            r[0] = x[0] * x[0] - x[1] + x[2];
            Ok(())
        }
        fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), ()> {
            jac.copy_from_slice(&[2.0 * x[0], -1.0, 1.0]);
            Ok(())
        }
    }
    let mut x = [1.0, 0.0, 0.0];
    let border = Border {
        rows: &[0.0, 0.0, 1.0, 1.0, 1.0, 0.0],
        values: &[0.5, 1.0],
        origin: &[],
    };
    newton_bordered(&mut Parabola, border, &mut x, &mut ws, &opts).unwrap();
    let root = (3f64.sqrt() - 1.0) / 2.0;
    assert!(
        (x[0] - root).abs() < 1e-15 && (x[1] - (1.0 - root)).abs() < 1e-15,
        "{x:?}"
    );
    assert_eq!(x[2], 0.5);
    // The same rows about an origin: x₂ − 0.1 = 0.4, (x₀ − 0.2) + (x₁ − 0.3)
    // = 0.5 are the same constraints, so the same root.
    let mut x = [1.0, 0.0, 0.0];
    let about = Border {
        rows: &[0.0, 0.0, 1.0, 1.0, 1.0, 0.0],
        values: &[0.4, 0.5],
        origin: &[0.2, 0.3, 0.1],
    };
    newton_bordered(&mut Parabola, about, &mut x, &mut ws, &opts).unwrap();
    assert!(
        (x[0] - root).abs() < 1e-15 && (x[1] - (1.0 - root)).abs() < 1e-15,
        "{x:?}"
    );
    assert!((x[2] - 0.5).abs() < 1e-15, "{x:?}");
    let bad = Border {
        rows: &[1.0],
        values: &[0.0],
        origin: &[],
    };
    assert!(matches!(
        newton_bordered(&mut Parabola, bad, &mut x, &mut ws, &opts),
        Err(SolveError::BorderSize {
            rows: 1,
            values: 1,
            unknowns: 3
        })
    ));
}

/// `F = atan(x)` from x = 1.5: the full Newton step overshoots to
/// |x| > 1.5 (undamped Newton diverges from |x| > 1.39); halving restores
/// descent and the root 0 is reached. With the step test on (rtol = 0,
/// atol = 1e-12) and the residual test off, the iteration stops on a
/// step below 1e-12 and evaluates F there.
#[test]
fn damping_rescues_atan_and_the_step_test_stops() {
    let mut f = Scalar(|x: f64| (x.atan(), 1.0 / (1.0 + x * x)));
    let mut x = [1.5];
    let mut ws = NewtonWorkspace::new(1);
    let opts = NewtonOptions {
        ftol: 0.0,
        atol: 1e-12,
        ..Default::default()
    };
    let stats = newton(&mut f, &mut x, &mut ws, &opts).unwrap();
    assert!(x[0].abs() < 1e-12, "{x:?} {stats:?}");
    assert!(stats.residual_evals > stats.iterations + 1, "{stats:?}");
    assert_eq!(ws.residual()[0], x[0].atan());
}

/// `F = x² + 1` has no root: the residual has a minimum at 0 where the
/// Jacobian is singular; from 0.5 the line search runs out of descent or
/// the Jacobian turns singular, an error either way, with the history.
#[test]
fn no_root_is_an_error_with_history() {
    let mut f = Scalar(|x: f64| (x * x + 1.0, 2.0 * x));
    let mut x = [0.5];
    let err = newton(
        &mut f,
        &mut x,
        &mut NewtonWorkspace::new(1),
        &Default::default(),
    )
    .unwrap_err();
    assert!(!err.history().is_empty(), "{err:?}");
    assert!(!matches!(err, SolveError::Eval(())), "{err:?}");
    let mut nan = [f64::NAN];
    let err = newton(
        &mut f,
        &mut nan,
        &mut NewtonWorkspace::new(1),
        &Default::default(),
    );
    assert!(matches!(
        err,
        Err(SolveError::NonFinite { iteration: 0, .. })
    ));
}

/// A scalar function with its derivative.
struct Scalar<F>(F);

impl<F: FnMut(f64) -> (f64, f64)> NewtonSystem for Scalar<F> {
    type Error = ();
    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), ()> {
        r[0] = (self.0)(x[0]).0;
        Ok(())
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), ()> {
        jac[0] = (self.0)(x[0]).1;
        Ok(())
    }
}

/// The caller's stopping rule: `F = x² − 2` from 1 with the residual test
/// off stops when the step falls below 1e-12 relative (on √2 to 1e-15);
/// undamped Newton on `atan` from x = 3 (|x| grows each step, undamped Newton
/// diverges from |x| > 1.39) is stopped as diverged at the first rise of ‖F‖.
#[test]
fn check_step_converges_or_diverges_for_the_caller() {
    struct Relative<F>(Scalar<F>);
    impl<F: FnMut(f64) -> (f64, f64)> NewtonSystem for Relative<F> {
        type Error = ();
        fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), ()> {
            self.0.residual(x, r)
        }
        fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), ()> {
            self.0.jacobian(x, jac)
        }
        fn check_step(&mut self, x: &[f64], step: &[f64], h: &[f64]) -> Result<StepCheck, ()> {
            Ok(if step[0].abs() <= 1e-12 * x[0].abs() {
                StepCheck::Converged
            } else if h.len() >= 2 && h[h.len() - 1] > h[h.len() - 2] {
                StepCheck::Diverged
            } else {
                StepCheck::Continue
            })
        }
    }
    let undamped = NewtonOptions {
        ftol: 0.0,
        max_halvings: 0,
        accept_no_descent: true,
        ..Default::default()
    };
    let mut ws = NewtonWorkspace::new(1);
    let mut x = [1.0];
    let mut sqrt2 = Relative(Scalar(|x: f64| (x * x - 2.0, 2.0 * x)));
    let stats = newton(&mut sqrt2, &mut x, &mut ws, &undamped).unwrap();
    assert!((x[0] - 2f64.sqrt()).abs() < 1e-15, "{x:?} {stats:?}");
    assert!(stats.iterations <= 7, "{stats:?}");

    let mut atan = Relative(Scalar(|x: f64| (x.atan(), 1.0 / (1.0 + x * x))));
    let mut x = [3.0];
    let err = newton(&mut atan, &mut x, &mut ws, &undamped).unwrap_err();
    assert!(
        matches!(err, SolveError::NonConvergence { iterations: 1, ref history } if history.len() == 2),
        "{err:?}"
    );
    assert!(x[0].abs() > 3.0, "{x:?}");
}

/// `F = x² + 1` from 0.1: the Newton step −5.05 and its half both raise
/// ‖F‖ (25.5 and 6.88 against 1.01). With one halving and
/// `accept_no_descent` the half step is taken (x = −2.425);
/// `full_step_without_descent` takes the full one (x = −4.95), and so does
/// `accept_below = 30` without `accept_no_descent`.
#[test]
fn no_descent_policies_take_the_step_they_name() {
    let mut f = Scalar(|x: f64| (x * x + 1.0, 2.0 * x));
    let mut ws = NewtonWorkspace::new(1);
    let base = NewtonOptions {
        max_iter: 1,
        max_halvings: 1,
        accept_no_descent: true,
        ..Default::default()
    };
    let cases = [
        (base, 0.1 - 2.525),
        (
            NewtonOptions {
                full_step_without_descent: true,
                ..base
            },
            0.1 - 5.05,
        ),
        (
            NewtonOptions {
                accept_no_descent: false,
                accept_below: 30.0,
                ..base
            },
            0.1 - 5.05,
        ),
    ];
    for (opts, expected) in cases {
        let mut x = [0.1];
        let err = newton(&mut f, &mut x, &mut ws, &opts).unwrap_err();
        assert!(
            matches!(err, SolveError::NonConvergence { iterations: 1, .. }),
            "{err:?}"
        );
        assert!((x[0] - expected).abs() < 1e-14, "{x:?} vs {expected}");
        assert_eq!(ws.residual()[0], x[0] * x[0] + 1.0);
    }
}

/// `A x = b` with `A = [[1, 1, 0], [1, 1 + 2ε, 0], [0, 0, 1]]`: the second
/// pivot 2ε is below 3ε of the largest, so the factorization is refused as
/// singular, unless `accept_near_singular` is set; then the step is finite
/// and the residual falls to rounding (≤ 1e-12).
#[test]
fn near_singular_factors_are_accepted_on_request() {
    struct Linear;
    const A: [f64; 9] = [
        1.0,
        1.0,
        0.0,
        1.0,
        1.0 + 2.0 * f64::EPSILON,
        0.0,
        0.0,
        0.0,
        1.0,
    ];
    impl NewtonSystem for Linear {
        type Error = ();
        fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), ()> {
            for (i, ri) in r.iter_mut().enumerate() {
                *ri = (0..3).map(|j| A[3 * i + j] * x[j]).sum::<f64>() - [3.0, 3.0, 3.0][i];
            }
            Ok(())
        }
        fn jacobian(&mut self, _x: &[f64], jac: &mut [f64]) -> Result<(), ()> {
            jac.copy_from_slice(&A);
            Ok(())
        }
    }
    let mut ws = NewtonWorkspace::new(3);
    let mut x = [0.0; 3];
    let err = newton(&mut Linear, &mut x, &mut ws, &NewtonOptions::default());
    assert!(
        matches!(err, Err(SolveError::SingularJacobian { .. })),
        "{err:?}"
    );
    let opts = NewtonOptions {
        accept_near_singular: true,
        ftol: 1e-12,
        ..Default::default()
    };
    let mut x = [0.0; 3];
    let stats = newton(&mut Linear, &mut x, &mut ws, &opts).unwrap();
    assert!(
        stats.residual_norm <= 1e-12 && (x[2] - 3.0).abs() < 1e-15,
        "{x:?} {stats:?}"
    );
}

/// `F = (10²⁰(x₀ + x₁ − 3), x₀ − x₁ + 1)`, root (1, 2): the unscaled
/// Jacobian's second pivot (−2) is below `n·ε` of the first (10²⁰), a
/// singular factor; with `scale_rows` the rows are `(1, 1)` and `(1, −1)`
/// and one Newton step lands on the root (the system is linear).
#[test]
fn scaled_rows_factor_a_jacobian_whose_rows_differ_in_size() {
    struct Lopsided;
    impl NewtonSystem for Lopsided {
        type Error = ();
        fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), ()> {
            r[0] = 1e20 * (x[0] + x[1] - 3.0);
            r[1] = x[0] - x[1] + 1.0;
            Ok(())
        }
        fn jacobian(&mut self, _x: &[f64], jac: &mut [f64]) -> Result<(), ()> {
            jac.copy_from_slice(&[1e20, 1e20, 1.0, -1.0]);
            Ok(())
        }
    }
    let mut ws = NewtonWorkspace::new(2);
    let mut x = [0.0; 2];
    let err = newton(&mut Lopsided, &mut x, &mut ws, &NewtonOptions::default());
    assert!(
        matches!(err, Err(SolveError::SingularJacobian { .. })),
        "{err:?}"
    );
    let opts = NewtonOptions {
        scale_rows: true,
        ..Default::default()
    };
    let mut x = [0.0; 2];
    let stats = newton(&mut Lopsided, &mut x, &mut ws, &opts).unwrap();
    assert_eq!(stats.iterations, 1, "{stats:?}");
    assert!(
        (x[0] - 1.0).abs() < 1e-15 && (x[1] - 2.0).abs() < 1e-15,
        "{x:?}"
    );
}
