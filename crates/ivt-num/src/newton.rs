//! One damped Newton method for `F(x) = 0` with a dense Jacobian, optionally
//! closed by linear border rows `C x = d` ([`newton_bordered`]: the
//! pseudo-arclength constraint of thesis Eq. 70, a fixed parameter, a phase
//! condition): each step solves `[[∂F/∂x], [C]] Δx = −[F; C x − d]` through
//! [`BorderedLu`] (factor once per Jacobian, no allocation per step) and
//! halves the step until `‖[F; C x − d]‖₂` falls (backtracking line search).
//!
//! Stopping: `‖F(x)‖₂ ≤ ftol` (residual test), or a full step with
//! `|Δx_i| ≤ rtol·|x_i| + atol` for every `i` (step test; the step is taken
//! and `F` evaluated once more at the result), or the system's own test
//! ([`NewtonSystem::check_step`], asked after every accepted step: a step
//! relative to a scale of its choosing, a noise floor, a divergence rule).
//! Failing: a singular Jacobian, a non-finite residual (at the start or at
//! the shortest trial step), no decrease along the step, or `max_iter`
//! steps; every error carries the `‖F‖₂` history.
//!
//! Every Newton iteration of the workspace is this one: the HB orbit
//! (classic IHB), the exact-Jacobian corrector and start of a path, the
//! fold and bifurcation locators on their extended systems, limit cycles,
//! branch switching, the STHB string and the θ-shooting of ivt-design.

use crate::bordered::{BorderedError, BorderedLu};
use crate::iteration::{execute, Progress, SolveError, Solver, Step, StepCheck, Stopping};

/// A system `F: Rⁿ → Rᵐ` with its Jacobian: square (`m = n`) for
/// [`newton`], `m = n − k` for [`newton_bordered`] with `k` border rows.
pub trait NewtonSystem {
    /// Error of an evaluation (e.g. an integration that stalls).
    type Error;
    /// `F(x)` into `r` (`m` entries). A non-finite `r` at a trial point rejects the trial
    /// (the step is halved): a way to say "outside the domain".
    ///
    /// # Errors
    /// Any evaluation failure; it ends the iteration ([`SolveError::Eval`]).
    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Self::Error>;
    /// `∂F/∂x` at `x`, row-major `m × n`, into `jac`. Called only at the `x`
    /// of the last [`Self::residual`] call, so state computed there may be
    /// reused.
    ///
    /// # Errors
    /// As [`Self::residual`].
    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), Self::Error>;
    /// The caller's stopping rule beside `ftol` and the step test, asked
    /// after each accepted step that left `‖F‖₂ > ftol`: `x` is the new
    /// point, `step` the step taken to reach it (damping included),
    /// `history` the `‖F‖₂` history (its last entry at `x`). Default:
    /// [`StepCheck::Continue`].
    ///
    /// # Errors
    /// Any failure of the caller's own (e.g. the iteration collapsed onto a
    /// trivial solution); it ends the iteration ([`SolveError::Eval`]).
    fn check_step(
        &mut self,
        _x: &[f64],
        _step: &[f64],
        _history: &[f64],
    ) -> Result<StepCheck, Self::Error> {
        Ok(StepCheck::Continue)
    }
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
    /// With `accept_no_descent`: take the full step instead of the
    /// shortest (the classic "keep the Newton step if no halving helps").
    /// Default `false`.
    pub full_step_without_descent: bool,
    /// A trial with `‖F‖₂ ≤ accept_below` is accepted even without descent
    /// (below the noise floor of `F` a rise is not divergence). Default 0.
    pub accept_below: f64,
    /// Accept a factorization whose pivots are below `n·ε` of the largest
    /// (singular to rounding) and check the step for finiteness instead:
    /// extended systems at a bifurcation are regular in exact arithmetic but
    /// may be badly scaled. Default `false`.
    pub accept_near_singular: bool,
    /// Factor the Jacobian with each row (and the residual entry on it)
    /// scaled to unit ∞-norm: the step is the same in exact arithmetic, but
    /// the singularity test then sees how separated the rows are, not how
    /// their sizes differ (harmonic h of a harmonic-balance Jacobian grows
    /// as h²ω²). Border rows are not scaled. Default `false`.
    pub scale_rows: bool,
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
            full_step_without_descent: false,
            accept_below: 0.0,
            accept_near_singular: false,
            scale_rows: false,
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

/// `k` linear rows `C (x − x₀) = d` closing an `n − k`-row system (`rows`
/// row-major `k × n`, `values` `k`, `origin` `x₀` of `n` entries or empty
/// for `C x = d`).
#[derive(Debug, Clone, Copy)]
pub struct Border<'a> {
    /// `C`, row-major `k × n`.
    pub rows: &'a [f64],
    /// `d`.
    pub values: &'a [f64],
    /// `x₀`, or empty. Each row is then evaluated as `Σᵢ cᵢ (xᵢ − x₀ᵢ)`, a
    /// difference of points, which keeps the last digits that `Cx − Cx₀`
    /// loses to cancellation when both are large (an arclength constraint
    /// at large λ).
    pub origin: &'a [f64],
}

impl Border<'_> {
    /// No border rows: [`newton`]'s square system.
    pub const NONE: Border<'static> = Border {
        rows: &[],
        values: &[],
        origin: &[],
    };
}

/// Caller-owned buffers of [`newton`] and [`newton_bordered`]: Jacobian,
/// its (bordered) LU, step, trial point and residuals. Reused across solves
/// of the same sizes; resized (the only allocation) when they change.
#[derive(Debug, Clone)]
pub struct NewtonWorkspace {
    pub(crate) jac: Vec<f64>,
    pub(crate) lu: BorderedLu,
    pub(crate) dx: Vec<f64>,
    x_trial: Vec<f64>,
    pub(crate) r: Vec<f64>,
    r_trial: Vec<f64>,
    pub(crate) history: Vec<f64>,
    /// The ∞-norms the Jacobian's rows were divided by (`scale_rows`).
    row_sizes: Vec<f64>,
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
            row_sizes: Vec::new(),
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

    /// The `‖F‖₂` history of the last solve (first entry: the initial
    /// guess; one per accepted step).
    pub fn history(&self) -> &[f64] {
        &self.history
    }

    /// Sign of the determinant of the last factored (bordered) Jacobian.
    pub fn det_sign(&self) -> f64 {
        self.lu.det_sign()
    }

    /// Factors the Jacobian in `jac` bordered by `rows` (its rows scaled
    /// under `opts.scale_rows`) and solves for the Newton step
    /// `dx = −J⁻¹ r`; `false` when the factor is unusable (singular, unless
    /// `accept_near_singular` takes a factor singular to rounding; or the
    /// sizes disagree) or the step is not finite.
    pub(crate) fn newton_step(&mut self, rows: &[f64], opts: &NewtonOptions) -> bool {
        self.row_sizes.clear();
        if opts.scale_rows {
            let n = self.dx.len().max(1);
            for row in self.jac.chunks_exact_mut(n) {
                let size = row.iter().fold(0.0f64, |a, v| a.max(v.abs()));
                if size > 0.0 && size.is_finite() {
                    row.iter_mut().for_each(|v| *v /= size);
                    self.row_sizes.push(size);
                } else {
                    self.row_sizes.push(1.0);
                }
            }
        }
        let factored = match self.lu.factor_rows(&self.jac, rows) {
            Ok(()) => true,
            Err(BorderedError::Singular) => opts.accept_near_singular,
            Err(BorderedError::Size { .. }) => false,
        };
        if !factored {
            return false;
        }
        self.dx.iter_mut().zip(&self.r).for_each(|(d, r)| *d = -r);
        for (d, size) in self.dx.iter_mut().zip(&self.row_sizes) {
            *d /= size;
        }
        self.lu.solve(&mut self.dx).is_ok() && self.dx.iter().all(|v| v.is_finite())
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
        let cx = if border.origin.is_empty() {
            crate::vector::dot(row, x)
        } else {
            row.iter()
                .zip(x.iter().zip(border.origin))
                .map(|(c, (a, b))| c * (a - b))
                .sum()
        };
        *out = cx - d;
    }
    Ok(())
}

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Backtracking along `ws.dx` from `x`: `t = 1, ½, ¼, …` until `‖F‖₂`
/// falls below `norm` (or below `opts.accept_below`). The accepted trial
/// point and residual are left in `ws.x_trial`, `ws.r_trial`; returns its
/// `t`, or `None` when no trial is acceptable under `opts`.
fn line_search<S: NewtonSystem + ?Sized>(
    sys: &mut S,
    border: &Border,
    x: &[f64],
    ws: &mut NewtonWorkspace,
    opts: &NewtonOptions,
    norm: f64,
    residual_evals: &mut usize,
) -> Result<Option<f64>, SolveError<S::Error>> {
    let mut t = 1.0;
    let mut trial_at = |t: f64, ws: &mut NewtonWorkspace, evals: &mut usize| {
        for ((xt, xi), d) in ws.x_trial.iter_mut().zip(x).zip(&ws.dx) {
            *xt = xi + t * d;
        }
        *evals += 1;
        bordered_residual(sys, border, &ws.x_trial, &mut ws.r_trial)
            .map_err(SolveError::Eval)
            .map(|()| norm2(&ws.r_trial))
    };
    for k in 0..=opts.max_halvings {
        let trial = trial_at(t, ws, residual_evals)?;
        let descent = trial < norm || trial <= opts.accept_below;
        let last = k == opts.max_halvings;
        if trial.is_finite() && (descent || (last && opts.accept_no_descent)) {
            if !descent && opts.full_step_without_descent && t < 1.0 {
                trial_at(1.0, ws, residual_evals)?;
                return Ok(Some(1.0));
            }
            return Ok(Some(t));
        }
        t *= 0.5;
    }
    Ok(None)
}

/// Solves the square system `F(x) = 0` by damped Newton from the guess `x`
/// (overwritten by the solution).
///
/// # Errors
/// [`SolveError`] as described there.
pub fn newton<S: NewtonSystem + ?Sized>(
    sys: &mut S,
    x: &mut [f64],
    ws: &mut NewtonWorkspace,
    opts: &NewtonOptions,
) -> Result<NewtonStats, SolveError<S::Error>> {
    newton_bordered(sys, Border::NONE, x, ws, opts)
}

/// Solves `[F(x); C x − d] = 0` (`F` with `n − k` rows, `k` border rows)
/// by damped Newton from the guess `x` (overwritten by the solution). The
/// Jacobian `[[∂F/∂x], [C]]` is factored by [`BorderedLu`]; the residual
/// and its history include the border rows.
///
/// # Errors
/// [`SolveError`] as described there; [`SolveError::BorderSize`] when
/// the border does not fit `x`.
pub fn newton_bordered<S: NewtonSystem + ?Sized>(
    sys: &mut S,
    border: Border,
    x: &mut [f64],
    ws: &mut NewtonWorkspace,
    opts: &NewtonOptions,
) -> Result<NewtonStats, SolveError<S::Error>> {
    let n = x.len();
    let k = border.values.len();
    if k > n || border.rows.len() != k * n {
        return Err(SolveError::BorderSize {
            rows: border.rows.len(),
            values: k,
            unknowns: n,
        });
    }
    if ws.dim() != n || ws.lu.borders() != k {
        *ws = NewtonWorkspace::bordered(n, k);
    }
    let mut history = std::mem::take(&mut ws.history);
    let mut solver = Newton {
        sys,
        border,
        ws,
        opts,
        residual_evals: 0,
        jacobian_evals: 0,
        t: 1.0,
    };
    let stats = run_newton(&mut solver, x, opts, &mut history, |s| {
        (s.residual_evals, s.jacobian_evals)
    });
    ws.history = history;
    stats
}

/// The tail of the damped and the deflated Newton drivers: `solver` run by
/// [`execute`] from `x` under `opts`' stopping rule, recording ‖F‖₂ in
/// `history`; its statistics, the evaluation counts read by `evals`.
///
/// # Errors
/// [`execute`]'s.
pub(crate) fn run_newton<S: Solver>(
    solver: &mut S,
    x: &mut [f64],
    opts: &NewtonOptions,
    history: &mut Vec<f64>,
    evals: fn(&S) -> (usize, usize),
) -> Result<NewtonStats, SolveError<S::Error>> {
    let stopping = Stopping {
        ftol: opts.ftol,
        max_iter: opts.max_iter,
    };
    let result = execute(solver, x, stopping, history);
    let (residual_evals, jacobian_evals) = evals(solver);
    Ok(NewtonStats {
        iterations: result?,
        residual_evals,
        jacobian_evals,
        residual_norm: history.last().copied().unwrap_or(f64::NAN),
    })
}

/// Damped Newton as a [`Solver`] of the iteration core: the state between
/// two steps of [`newton_bordered`].
struct Newton<'a, 'b, S: ?Sized> {
    sys: &'a mut S,
    border: Border<'b>,
    ws: &'a mut NewtonWorkspace,
    opts: &'a NewtonOptions,
    residual_evals: usize,
    jacobian_evals: usize,
    /// The length of the last accepted step along the Newton direction.
    t: f64,
}

impl<S: NewtonSystem + ?Sized> Solver for Newton<'_, '_, S> {
    type Error = S::Error;

    fn start(&mut self, x: &mut [f64]) -> Result<f64, SolveError<S::Error>> {
        if !x.iter().all(|v| v.is_finite()) {
            return Err(SolveError::NonFinite {
                iteration: 0,
                history: Vec::new(),
            });
        }
        bordered_residual(self.sys, &self.border, x, &mut self.ws.r).map_err(SolveError::Eval)?;
        self.residual_evals += 1;
        Ok(norm2(&self.ws.r))
    }

    fn next_iter(&mut self, x: &mut [f64], at: Progress<'_>) -> Result<Step, SolveError<S::Error>> {
        let ws = &mut *self.ws;
        self.sys
            .jacobian(x, &mut ws.jac)
            .map_err(SolveError::Eval)?;
        self.jacobian_evals += 1;
        if !ws.newton_step(self.border.rows, self.opts) {
            return Err(at.singular());
        }
        let opts = self.opts;
        let small = ws
            .dx
            .iter()
            .zip(x.iter())
            .all(|(d, xi)| d.abs() <= opts.rtol * xi.abs() + opts.atol);
        if small {
            x.iter_mut().zip(&ws.dx).for_each(|(xi, d)| *xi += d);
            bordered_residual(self.sys, &self.border, x, &mut ws.r).map_err(SolveError::Eval)?;
            self.residual_evals += 1;
            return Ok(Step::Moved {
                norm: norm2(&ws.r),
                converged: true,
            });
        }
        let searched = line_search(
            self.sys,
            &self.border,
            x,
            ws,
            opts,
            at.norm(),
            &mut self.residual_evals,
        )?;
        let Some(t) = searched else {
            if !norm2(&ws.r_trial).is_finite() {
                // The shortest trial left the domain of F.
                return Err(at.non_finite());
            }
            return Err(SolveError::NoDescent {
                iteration: at.iteration,
                history: at.history.to_vec(),
            });
        };
        x.copy_from_slice(&ws.x_trial);
        std::mem::swap(&mut ws.r, &mut ws.r_trial);
        self.t = t;
        Ok(Step::Moved {
            norm: norm2(&ws.r),
            converged: false,
        })
    }

    /// The system's own rule ([`NewtonSystem::check_step`]) on the step
    /// taken (damping included).
    fn check(&mut self, x: &[f64], at: Progress<'_>) -> Result<StepCheck, SolveError<S::Error>> {
        let t = self.t;
        self.ws.dx.iter_mut().for_each(|d| *d *= t);
        self.sys
            .check_step(x, &self.ws.dx, at.history)
            .map_err(SolveError::Eval)
    }
}

#[cfg(test)]
mod tests;
