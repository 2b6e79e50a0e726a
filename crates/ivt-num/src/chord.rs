//! The chord iteration: iterations on a factorization `A₀` of the Jacobian
//! that the caller already has (no new factorization), accelerated by
//! Broyden's updates of it (Kelley's `brsol`: the update of `A₀⁻¹` applied
//! through the stored steps by Sherman–Morrison), superlinear where the
//! plain chord contracts linearly. It gives up fast, for a Newton iteration
//! to take over: when the residual does not fall by ½ per iteration (over
//! two) or grows. A [`Solver`] of the iteration core; the first attempt of
//! the exact-Jacobian path corrector (ivt-path's `NewtonCorrector`), on the
//! LU its tangent left.

use crate::bordered::BorderedLu;
use crate::broyden::System;
use crate::iteration::{execute, Progress, SolveError, Solver, Step, StepCheck, Stopping};
use crate::vector::{dot, norm2};

/// Chord iterations on `sys` from `x` with the factored `lu` (of size
/// `x.len()`): at most `max_iter` steps, converged at `‖F‖₂ ≤ tol`. `r` is
/// the residual scratch (`x.len()` entries); with `residual_known` it holds
/// `F(x)` on entry. Returns the steps taken; on failure `x` is the best
/// iterate (the smallest ‖F‖₂), for Newton to start from.
///
/// # Errors
/// [`SolveError::NonConvergence`] (with the history) when the iteration
/// stops contracting or after `max_iter` steps, [`SolveError::NonFinite`]
/// for a non-finite residual.
pub fn chord<S: System + ?Sized>(
    sys: &mut S,
    lu: &mut BorderedLu,
    x: &mut [f64],
    r: &mut [f64],
    residual_known: bool,
    stopping: Stopping,
) -> Result<usize, SolveError> {
    let mut solver = Chord {
        sys,
        lu,
        r,
        residual_known,
        steps: Vec::new(),
        best: (f64::INFINITY, x.to_vec()),
    };
    let result = execute(&mut solver, x, stopping, &mut Vec::new());
    if result.is_err() {
        x.copy_from_slice(&solver.best.1);
    }
    result
}

/// The chord's state: the factor, the residual, the steps taken (for the
/// updates) and the best iterate.
struct Chord<'a, S: ?Sized> {
    sys: &'a mut S,
    lu: &'a mut BorderedLu,
    r: &'a mut [f64],
    residual_known: bool,
    steps: Vec<Vec<f64>>,
    best: (f64, Vec<f64>),
}

impl<S: ?Sized> Chord<'_, S> {
    /// Keeps `x` as the best iterate if its ‖F‖₂ (`at.norm()`) is the
    /// smallest so far.
    fn keep_best(&mut self, x: &[f64], at: Progress<'_>) {
        let now = at.norm();
        if now < self.best.0 {
            self.best.0 = now;
            self.best.1.copy_from_slice(x);
        }
    }
}

impl<S: System + ?Sized> Solver for Chord<'_, S> {
    type Error = std::convert::Infallible;

    fn start(&mut self, x: &mut [f64]) -> Result<f64, SolveError> {
        if !self.residual_known {
            self.sys.residual(x, self.r);
        }
        Ok(norm2(self.r))
    }

    fn init(&mut self, x: &[f64], at: Progress<'_>) -> Result<(), SolveError> {
        self.keep_best(x, at);
        Ok(())
    }

    fn next_iter(&mut self, x: &mut [f64], at: Progress<'_>) -> Result<Step, SolveError> {
        // z = −A₀⁻¹F, then the updates s_{j+1} s_jᵀ z / ‖s_j‖² in order.
        let mut z = self.r.to_vec();
        if self.lu.solve(&mut z).is_err() {
            return Err(SolveError::NonConvergence {
                iterations: at.iteration - 1,
                history: at.history.to_vec(),
            });
        }
        z.iter_mut().for_each(|v| *v = -*v);
        for pair in self.steps.windows(2) {
            if let [s0, s1] = pair {
                let c = dot(s0, &z) / dot(s0, s0);
                z.iter_mut().zip(s1).for_each(|(v, s)| *v += c * s);
            }
        }
        if let Some(last) = self.steps.last() {
            let denom = 1.0 - dot(last, &z) / dot(last, last);
            z.iter_mut().for_each(|v| *v /= denom);
        }
        for (xi, d) in x.iter_mut().zip(&z) {
            *xi += d;
        }
        self.steps.push(z);
        self.sys.residual(x, self.r);
        Ok(Step::Moved {
            norm: norm2(self.r),
            converged: false,
        })
    }

    /// Diverging once ‖F‖ does not fall below the last value, or above a
    /// quarter of the one two steps back.
    fn check(&mut self, x: &[f64], at: Progress<'_>) -> Result<StepCheck, SolveError> {
        self.keep_best(x, at);
        let now = at.norm();
        let before = |k: usize| {
            at.history
                .len()
                .checked_sub(k + 1)
                .and_then(|i| at.history.get(i))
        };
        let grew = before(1).is_some_and(|b| now >= *b);
        Ok(if grew || before(2).is_some_and(|b| now > 0.25 * b) {
            StepCheck::Diverged
        } else {
            StepCheck::Continue
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `F(x) = (x₀² + x₁² − 4, x₀ − x₁)`, root `(√2, √2)`, from `(1.5, 1.4)`
    /// on the LU of the exact Jacobian at the start: the chord reaches the
    /// root to 1e-13 in fewer than 15 steps; on the LU of a Jacobian with the
    /// wrong sign in a row it stops at once (the residual grows) and leaves
    /// `x` at the start, its best iterate.
    #[test]
    fn converges_on_a_good_factor_and_gives_up_on_a_bad_one() {
        let mut f = |x: &[f64], r: &mut [f64]| {
            r[0] = x[0] * x[0] + x[1] * x[1] - 4.0;
            r[1] = x[0] - x[1];
        };
        let start = [1.5, 1.4];
        let stopping = Stopping {
            ftol: 1e-13,
            max_iter: 30,
        };
        let mut lu = BorderedLu::new(2, 0);
        lu.factor(&[3.0, 2.8, 1.0, -1.0], &[], &[], &[]).unwrap();
        let (mut x, mut r) = (start, [0.0; 2]);
        let steps = chord(&mut f, &mut lu, &mut x, &mut r, false, stopping).unwrap();
        let s2 = 2f64.sqrt();
        assert!(
            (x[0] - s2).abs() < 1e-13 && (x[1] - s2).abs() < 1e-13,
            "{x:?}"
        );
        assert!(steps < 15, "{steps}");
        lu.factor(&[-3.0, -2.8, 1.0, -1.0], &[], &[], &[]).unwrap();
        let mut x = start;
        let err = chord(&mut f, &mut lu, &mut x, &mut r, false, stopping).unwrap_err();
        assert!(matches!(err, SolveError::NonConvergence { .. }), "{err:?}");
        assert_eq!(x, start);
    }
}
