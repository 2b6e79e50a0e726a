//! One damped Newton method for `F(x) = 0` with a dense Jacobian, optionally
//! closed by linear border rows `C x = d` ([`newton_bordered`]: the
//! pseudo-arclength constraint of thesis Eq. 70, a fixed parameter, a phase
//! condition): each step solves `[[∂F/∂x], [C]] Δx = −[F; C x − d]` through
//! [`BorderedLu`] (factor once per Jacobian, no allocation per step) and
//! halves the step until `‖[F; C x − d]‖₂` falls (backtracking line search).
//!
//! Stopping: `‖F(x)‖₂ ≤ ftol` (residual test), or a full step with
//! `|Δx_i| ≤ rtol·|x_i| + atol` for every `i` (step test; the step is taken
//! and `F` evaluated once more at the result). Failing: a singular
//! Jacobian, a non-finite residual, no decrease along the step, or
//! `max_iter` steps; every error carries the `‖F‖₂` history.

use crate::bordered::BorderedLu;
use thiserror::Error;

/// A system `F: Rⁿ → Rᵐ` with its Jacobian: square (`m = n`) for
/// [`newton`], `m = n − k` for [`newton_bordered`] with `k` border rows.
pub trait NewtonSystem {
    /// Error of an evaluation (e.g. an integration that stalls).
    type Error;
    /// `F(x)` into `r` (`m` entries). A non-finite `r` at a trial point rejects the trial
    /// (the step is halved): a way to say "outside the domain".
    ///
    /// # Errors
    /// Any evaluation failure; it ends the iteration ([`NewtonError::Eval`]).
    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Self::Error>;
    /// `∂F/∂x` at `x`, row-major `m × n`, into `jac`. Called only at the `x`
    /// of the last [`Self::residual`] call, so state computed there may be
    /// reused.
    ///
    /// # Errors
    /// As [`Self::residual`].
    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), Self::Error>;
}

/// Options of [`newton`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Converged when `‖F(x)‖₂ ≤ ftol`. Default 1e-10.
    pub ftol: f64,
    /// Converged after a full step with `|Δx_i| ≤ rtol·|x_i| + atol`.
    /// Default 0 (step test off unless `atol` > 0).
    pub rtol: f64,
    /// See `rtol`. Default 0.
    pub atol: f64,
    /// Maximum Newton steps. Default 50.
    pub max_iter: usize,
    /// Step halvings tried when the full step does not reduce `‖F‖₂`.
    /// Default 8.
    pub max_halvings: usize,
    /// When no trial reduces `‖F‖₂`, take the last (shortest) finite one
    /// anyway instead of failing, to leave a shallow local minimum of `‖F‖`
    /// from a cold start. Default `false`.
    pub accept_no_descent: bool,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            ftol: 1e-10,
            rtol: 0.0,
            atol: 0.0,
            max_iter: 50,
            max_halvings: 8,
            accept_no_descent: false,
        }
    }
}

/// Statistics of a converged solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonStats {
    /// Newton steps taken.
    pub iterations: usize,
    /// Residual evaluations (line-search trials included).
    pub residual_evals: usize,
    /// Jacobian evaluations (one per step).
    pub jacobian_evals: usize,
    /// `‖F‖₂` at the solution.
    pub residual_norm: f64,
}

/// Why [`newton`] failed; the iteration variants carry the `‖F‖₂` history
/// (first entry: the initial guess; one per accepted step).
#[derive(Debug, Clone, Error, PartialEq)]
pub enum NewtonError<E> {
    /// `max_iter` steps without meeting a stopping test.
    #[error("no convergence in {iterations} Newton steps")]
    NonConvergence {
        /// Steps taken.
        iterations: usize,
        /// `‖F‖₂` history.
        history: Vec<f64>,
    },
    /// No step length in the line search reduced `‖F‖₂`.
    #[error("no descent along the Newton step at step {iteration}")]
    NoDescent {
        /// Step at which it happened.
        iteration: usize,
        /// `‖F‖₂` history.
        history: Vec<f64>,
    },
    /// The Jacobian is numerically singular (or the step not finite).
    #[error("singular Jacobian at Newton step {iteration}")]
    SingularJacobian {
        /// Step at which it happened.
        iteration: usize,
        /// `‖F‖₂` history.
        history: Vec<f64>,
    },
    /// A non-finite start or residual.
    #[error("non-finite start or residual at Newton step {iteration}")]
    NonFinite {
        /// Step at which it happened.
        iteration: usize,
        /// `‖F‖₂` history.
        history: Vec<f64>,
    },
    /// The system's evaluation failed.
    #[error("evaluation failed")]
    Eval(E),
    /// The border rows, their right-hand side and the unknowns disagree in
    /// size (`rows` must be `k × n`, `values` `k`, `k ≤ n`).
    #[error("border of {rows} entries and {values} values does not fit {unknowns} unknowns")]
    BorderSize {
        /// Entries of the border rows.
        rows: usize,
        /// Entries of the right-hand side.
        values: usize,
        /// Unknowns `n`.
        unknowns: usize,
    },
}

impl<E> NewtonError<E> {
    /// The `‖F‖₂` history (empty for [`NewtonError::Eval`]).
    pub fn history(&self) -> &[f64] {
        match self {
            Self::NonConvergence { history, .. }
            | Self::NoDescent { history, .. }
            | Self::SingularJacobian { history, .. }
            | Self::NonFinite { history, .. } => history,
            Self::Eval(_) | Self::BorderSize { .. } => &[],
        }
    }
}

/// `k` linear rows `C x = d` closing an `n − k`-row system (`rows`
/// row-major `k × n`, `values` `k`).
#[derive(Debug, Clone, Copy)]
pub struct Border<'a> {
    /// `C`, row-major `k × n`.
    pub rows: &'a [f64],
    /// `d`.
    pub values: &'a [f64],
}

impl Border<'_> {
    /// No border rows: [`newton`]'s square system.
    pub const NONE: Border<'static> = Border {
        rows: &[],
        values: &[],
    };
}

/// Caller-owned buffers of [`newton`] and [`newton_bordered`]: Jacobian,
/// its (bordered) LU, step, trial point and residuals. Reused across solves
/// of the same sizes; resized (the only allocation) when they change.
#[derive(Debug, Clone)]
pub struct NewtonWorkspace {
    jac: Vec<f64>,
    lu: BorderedLu,
    dx: Vec<f64>,
    x_trial: Vec<f64>,
    r: Vec<f64>,
    r_trial: Vec<f64>,
    history: Vec<f64>,
}

impl NewtonWorkspace {
    /// Buffers for a square system of `m` unknowns.
    pub fn new(m: usize) -> Self {
        Self::bordered(m, 0)
    }

    /// Buffers for `n` unknowns of which `k` are fixed by border rows.
    pub fn bordered(n: usize, k: usize) -> Self {
        let m = n.saturating_sub(k);
        Self {
            jac: vec![0.0; m * n],
            lu: BorderedLu::new(m, n - m),
            dx: vec![0.0; n],
            x_trial: vec![0.0; n],
            r: vec![0.0; n],
            r_trial: vec![0.0; n],
            history: Vec::with_capacity(64),
        }
    }

    /// Number of unknowns.
    pub fn dim(&self) -> usize {
        self.dx.len()
    }

    /// `[F; C x − d]` at the last accepted point of the last solve.
    pub fn residual(&self) -> &[f64] {
        &self.r
    }

    /// Sign of the determinant of the last factored (bordered) Jacobian.
    pub fn det_sign(&self) -> f64 {
        self.lu.det_sign()
    }
}

/// `[F(x); C x − d]` into `r`.
fn bordered_residual<S: NewtonSystem + ?Sized>(
    sys: &mut S,
    border: &Border,
    x: &[f64],
    r: &mut [f64],
) -> Result<(), S::Error> {
    let m = x.len() - border.values.len();
    let (rf, rc) = r.split_at_mut(m);
    sys.residual(x, rf)?;
    for ((out, row), d) in rc
        .iter_mut()
        .zip(border.rows.chunks_exact(x.len()))
        .zip(border.values)
    {
        *out = crate::vector::dot(row, x) - d;
    }
    Ok(())
}

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Solves the square system `F(x) = 0` by damped Newton from the guess `x`
/// (overwritten by the solution).
///
/// # Errors
/// [`NewtonError`] as described there.
pub fn newton<S: NewtonSystem + ?Sized>(
    sys: &mut S,
    x: &mut [f64],
    ws: &mut NewtonWorkspace,
    opts: &NewtonOptions,
) -> Result<NewtonStats, NewtonError<S::Error>> {
    newton_bordered(sys, Border::NONE, x, ws, opts)
}

/// Solves `[F(x); C x − d] = 0` (`F` with `n − k` rows, `k` border rows)
/// by damped Newton from the guess `x` (overwritten by the solution). The
/// Jacobian `[[∂F/∂x], [C]]` is factored by [`BorderedLu`]; the residual
/// and its history include the border rows.
///
/// # Errors
/// [`NewtonError`] as described there; [`NewtonError::BorderSize`] when
/// the border does not fit `x`.
pub fn newton_bordered<S: NewtonSystem + ?Sized>(
    sys: &mut S,
    border: Border,
    x: &mut [f64],
    ws: &mut NewtonWorkspace,
    opts: &NewtonOptions,
) -> Result<NewtonStats, NewtonError<S::Error>> {
    let n = x.len();
    let k = border.values.len();
    if k > n || border.rows.len() != k * n {
        return Err(NewtonError::BorderSize {
            rows: border.rows.len(),
            values: k,
            unknowns: n,
        });
    }
    if ws.dim() != n || ws.lu.borders() != k {
        *ws = NewtonWorkspace::bordered(n, k);
    }
    ws.history.clear();
    let mut stats = NewtonStats {
        iterations: 0,
        residual_evals: 0,
        jacobian_evals: 0,
        residual_norm: f64::NAN,
    };
    let non_finite = |iteration, history: &[f64]| NewtonError::NonFinite {
        iteration,
        history: history.to_vec(),
    };
    if !x.iter().all(|v| v.is_finite()) {
        return Err(non_finite(0, &ws.history));
    }
    bordered_residual(sys, &border, x, &mut ws.r).map_err(NewtonError::Eval)?;
    stats.residual_evals += 1;
    let mut norm = norm2(&ws.r);
    ws.history.push(norm);
    if !norm.is_finite() {
        return Err(non_finite(0, &ws.history));
    }
    while norm > opts.ftol {
        if stats.iterations >= opts.max_iter {
            return Err(NewtonError::NonConvergence {
                iterations: stats.iterations,
                history: ws.history.clone(),
            });
        }
        stats.iterations += 1;
        let it = stats.iterations;
        sys.jacobian(x, &mut ws.jac).map_err(NewtonError::Eval)?;
        stats.jacobian_evals += 1;
        let singular = |history: &[f64]| NewtonError::SingularJacobian {
            iteration: it,
            history: history.to_vec(),
        };
        if ws.lu.factor_rows(&ws.jac, border.rows).is_err() {
            return Err(singular(&ws.history));
        }
        ws.dx.iter_mut().zip(&ws.r).for_each(|(d, r)| *d = -r);
        if ws.lu.solve(&mut ws.dx).is_err() {
            return Err(singular(&ws.history));
        }
        if !ws.dx.iter().all(|v| v.is_finite()) {
            return Err(singular(&ws.history));
        }
        let small = ws
            .dx
            .iter()
            .zip(x.iter())
            .all(|(d, xi)| d.abs() <= opts.rtol * xi.abs() + opts.atol);
        if small {
            x.iter_mut().zip(&ws.dx).for_each(|(xi, d)| *xi += d);
            bordered_residual(sys, &border, x, &mut ws.r).map_err(NewtonError::Eval)?;
            stats.residual_evals += 1;
            norm = norm2(&ws.r);
            ws.history.push(norm);
            if !norm.is_finite() {
                return Err(non_finite(it, &ws.history));
            }
            break;
        }
        // Backtracking: t = 1, ½, ¼, … until ‖F‖ falls.
        let mut t = 1.0;
        let mut accepted = None;
        for k in 0..=opts.max_halvings {
            for ((xt, xi), d) in ws.x_trial.iter_mut().zip(x.iter()).zip(&ws.dx) {
                *xt = xi + t * d;
            }
            bordered_residual(sys, &border, &ws.x_trial, &mut ws.r_trial)
                .map_err(NewtonError::Eval)?;
            stats.residual_evals += 1;
            let trial = norm2(&ws.r_trial);
            let last = k == opts.max_halvings;
            if trial.is_finite() && (trial < norm || (last && opts.accept_no_descent)) {
                accepted = Some(trial);
                break;
            }
            t *= 0.5;
        }
        let Some(trial) = accepted else {
            return Err(NewtonError::NoDescent {
                iteration: it,
                history: ws.history.clone(),
            });
        };
        x.copy_from_slice(&ws.x_trial);
        std::mem::swap(&mut ws.r, &mut ws.r_trial);
        norm = trial;
        ws.history.push(norm);
    }
    stats.residual_norm = norm;
    Ok(stats)
}

#[cfg(test)]
mod tests {
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
        };
        newton_bordered(&mut Parabola, border, &mut x, &mut ws, &opts).unwrap();
        let root = (3f64.sqrt() - 1.0) / 2.0;
        assert!(
            (x[0] - root).abs() < 1e-15 && (x[1] - (1.0 - root)).abs() < 1e-15,
            "{x:?}"
        );
        assert_eq!(x[2], 0.5);
        let bad = Border {
            rows: &[1.0],
            values: &[0.0],
        };
        assert!(matches!(
            newton_bordered(&mut Parabola, bad, &mut x, &mut ws, &opts),
            Err(NewtonError::BorderSize {
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
        assert!(!matches!(err, NewtonError::Eval(())), "{err:?}");
        let mut nan = [f64::NAN];
        let err = newton(
            &mut f,
            &mut nan,
            &mut NewtonWorkspace::new(1),
            &Default::default(),
        );
        assert!(matches!(
            err,
            Err(NewtonError::NonFinite { iteration: 0, .. })
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
}
