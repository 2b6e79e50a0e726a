//! The Broyden driver: quasi-Newton steps (Eq. 66) with a backtracking line search
//! on ‖F‖, and the policy that refreshes the Jacobian when the line search fails or
//! the iteration stalls, as a [`Solver`] of the iteration core
//! ([`crate::iteration::execute`]). The linear algebra lives in [`BroydenWorkspace`].

use super::{BroydenOptions, BroydenStats, BroydenWorkspace, System};
use crate::iteration::{execute, Progress, SolveError, Solver, Step, StepCheck, Stopping};

/// Solves `F(x) = 0` by Broyden's method from the initial guess `x` (overwritten
/// by the solution), starting from the Jacobian held in `ws` (set with
/// [`BroydenWorkspace::set_jacobian`] or left from a previous solve; refreshed if
/// none).
///
/// # Errors
/// [`SolveError`] with the residual history when the tolerance is not reached,
/// the residual is not finite, or the Jacobian is singular;
/// [`SolveError::Dimension`] if `x` and `ws` differ in size.
pub fn broyden_solve<S: System + ?Sized>(
    sys: &mut S,
    x: &mut [f64],
    ws: &mut BroydenWorkspace,
    opts: &BroydenOptions,
) -> Result<BroydenStats, SolveError> {
    if x.len() != ws.len() {
        return Err(SolveError::Dimension {
            expected: ws.len(),
            got: x.len(),
        });
    }
    ws.begin();
    let mut history = ws.take_history();
    let mut solver = Broyden {
        sys,
        ws,
        opts,
        stats: BroydenStats::default(),
        stalled: 0,
        updated: true,
    };
    let stopping = Stopping {
        ftol: opts.tol,
        max_iter: opts.max_iter,
    };
    let result = execute(&mut solver, x, stopping, &mut history);
    let mut stats = solver.stats;
    stats.residual_norm = history.last().copied().unwrap_or(f64::NAN);
    ws.restore_history(history);
    stats.iterations = result?;
    Ok(stats)
}

/// Broyden's method as a [`Solver`]: the state between two steps of
/// [`broyden_solve`].
struct Broyden<'a, S: ?Sized> {
    sys: &'a mut S,
    ws: &'a mut BroydenWorkspace,
    opts: &'a BroydenOptions,
    /// Residual evaluations and refreshes (the iterations are the executor's).
    stats: BroydenStats,
    /// Consecutive steps that reduced ‖F‖ by less than `stall_ratio`.
    stalled: usize,
    /// The last step's rank-one update kept `B` regular.
    updated: bool,
}

impl<S: System + ?Sized> Broyden<'_, S> {
    /// A Jacobian refresh is still allowed.
    fn can_refresh(&self) -> bool {
        self.opts.jacobian_refresh && self.stats.jacobian_refreshes < self.opts.max_refreshes
    }
}

impl<S: System + ?Sized> Solver for Broyden<'_, S> {
    type Error = std::convert::Infallible;

    fn start(&mut self, x: &mut [f64]) -> Result<f64, SolveError> {
        if !x.iter().all(|v| v.is_finite()) {
            return Err(SolveError::NonFinite {
                iteration: 0,
                history: Vec::new(),
            });
        }
        self.stats.residual_evals = 1;
        Ok(self.ws.evaluate(self.sys, x))
    }

    /// A workspace without a Jacobian refreshes it at the start.
    fn init(&mut self, x: &[f64], at: Progress<'_>) -> Result<(), SolveError> {
        if !self.ws.has_jacobian() {
            let fd_step = self.opts.fd_step;
            self.ws
                .refresh_inverse(self.sys, x, fd_step, &mut self.stats, at)?;
        }
        Ok(())
    }

    /// The quasi-Newton step with a backtracking line search on ‖F‖; a
    /// failed line search refreshes the Jacobian instead (a restart).
    fn next_iter(&mut self, x: &mut [f64], at: Progress<'_>) -> Result<Step, SolveError> {
        let norm = at.norm();
        self.ws.direction();
        let mut t = 1.0;
        let mut accepted = false;
        let mut trial_norm = f64::INFINITY;
        for _ in 0..=self.opts.max_backtracks {
            trial_norm = self.ws.trial(self.sys, x, t);
            self.stats.residual_evals += 1;
            if trial_norm.is_finite() && trial_norm < norm {
                accepted = true;
                break;
            }
            t *= 0.5;
        }
        if !accepted {
            if !self.can_refresh() {
                return Err(at.non_convergence());
            }
            self.stalled = 0;
            let fd_step = self.opts.fd_step;
            self.ws
                .refresh_inverse(self.sys, x, fd_step, &mut self.stats, at)?;
            return Ok(Step::Restarted);
        }
        self.updated = self.ws.accept(t, x);
        let ratio = trial_norm / norm;
        self.stalled = if ratio > self.opts.stall_ratio {
            self.stalled + 1
        } else {
            0
        };
        Ok(Step::Moved {
            norm: trial_norm,
            converged: false,
        })
    }

    /// A step that left `B` singular, or too many stalled steps, refresh the
    /// Jacobian (an update that left `B` singular without a refresh left is
    /// [`SolveError::SingularJacobian`]).
    fn check(&mut self, x: &[f64], at: Progress<'_>) -> Result<StepCheck, SolveError> {
        if self.updated && self.stalled < self.opts.stall_iters {
            return Ok(StepCheck::Continue);
        }
        if !self.can_refresh() {
            if !self.updated {
                return Err(at.singular());
            }
            return Ok(StepCheck::Continue);
        }
        self.stalled = 0;
        let fd_step = self.opts.fd_step;
        self.ws
            .refresh_inverse(self.sys, x, fd_step, &mut self.stats, at)?;
        Ok(StepCheck::Continue)
    }
}
