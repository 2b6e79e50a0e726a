//! Generic Broyden ("good" update, Eq. 66–67) solver for `F(x) = 0`, `x ∈ R^m`.
//!
//! The solver iterates with the inverse `H = B⁻¹` of the approximate Jacobian `B`;
//! each update is rank one, so `H` follows by Sherman–Morrison and an iteration costs
//! O(m²) with no allocation: everything lives in the caller-owned
//! [`BroydenWorkspace`]. Rows listed in [`BroydenWorkspace::exact_rows`] are never
//! changed by the update (the exact augmenting row of the arc-length method, Eq. 77).
//!
//! `B` itself is updated alongside `H` only when the caller reads it between solves
//! ([`BroydenWorkspace::track_jacobian`], on by default, as continuation does). A
//! one-shot solve turns tracking off: the update then uses `B s = −t r` (the step is
//! `s = −t H r`), which is exact for `B = H⁻¹`, and a full step lets the next
//! direction follow from the update's `H u` without another product. `B` is then
//! recovered by inverting `H` only if someone asks for it.
//!
//! Safeguards: a backtracking line search on ‖F‖ and, when the iteration stalls or
//! the line search fails, a refresh of `B` by the system's Jacobian (or by forward
//! finite differences when the system has none).

use ivt_num::vector::{axpy, dot, norm2};
use ivt_num::LuWorkspace;

mod error;
pub use error::SolveError;

/// A nonlinear system `F(x) = 0` with as many equations as unknowns.
///
/// Any closure `FnMut(&[f64], &mut [f64])` is a system (Jacobian by finite
/// differences); implement the trait to supply an analytic Jacobian.
pub trait System {
    /// Writes `F(x)` into `r` (`r.len() == x.len()`).
    fn residual(&mut self, x: &[f64], r: &mut [f64]);
    /// Writes the Jacobian `∂F/∂x` (row-major `m×m`) into `jac`; returns `false`
    /// when not available (the solver then uses finite differences).
    fn jacobian(&mut self, _x: &[f64], _jac: &mut [f64]) -> bool {
        false
    }
}

impl<F: FnMut(&[f64], &mut [f64])> System for F {
    fn residual(&mut self, x: &[f64], r: &mut [f64]) {
        self(x, r)
    }
}

/// Options of the Broyden solver.
#[derive(Debug, Clone, PartialEq)]
pub struct BroydenOptions {
    /// Convergence when ‖F(x)‖₂ ≤ `tol`.
    pub tol: f64,
    /// Maximum number of (quasi-)Newton steps.
    pub max_iter: usize,
    /// Maximum step halvings in the backtracking line search.
    pub max_backtracks: usize,
    /// Allow refreshing `B` by the exact/finite-difference Jacobian on stalls.
    pub jacobian_refresh: bool,
    /// Maximum number of Jacobian refreshes in one solve.
    pub max_refreshes: usize,
    /// A step that reduces ‖F‖ by less than this factor counts as a stall
    /// (e.g. 0.9: less than 10 % reduction).
    pub stall_ratio: f64,
    /// Consecutive stalled steps before the Jacobian is refreshed.
    pub stall_iters: usize,
    /// Relative forward-difference step for the finite-difference Jacobian.
    pub fd_step: f64,
}

impl Default for BroydenOptions {
    fn default() -> Self {
        Self {
            tol: 1e-10,
            max_iter: 100,
            max_backtracks: 8,
            jacobian_refresh: true,
            max_refreshes: 5,
            stall_ratio: 0.9,
            stall_iters: 4,
            fd_step: 1e-7,
        }
    }
}

impl BroydenOptions {
    /// Same options with another tolerance.
    pub fn with_tol(mut self, tol: f64) -> Self {
        self.tol = tol;
        self
    }
    /// Same options with another iteration limit.
    pub fn with_max_iter(mut self, max_iter: usize) -> Self {
        self.max_iter = max_iter;
        self
    }
}

/// Statistics of a converged solve (`Default`: no work done, for orbits built
/// from given coefficients).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BroydenStats {
    /// Quasi-Newton steps taken.
    pub iterations: usize,
    /// Residual evaluations (including line search and finite differences).
    pub residual_evals: usize,
    /// Times the Jacobian was refreshed (exact or finite differences).
    pub jacobian_refreshes: usize,
    /// Final ‖F(x)‖₂.
    pub residual_norm: f64,
}

/// Caller-owned state of the solver: `B`, `H = B⁻¹` and all scratch vectors.
///
/// Reuse one workspace across solves of the same size: after a solve, `B`/`H`
/// hold the last Broyden approximation, which [`broyden_solve`] uses as the next
/// initial Jacobian (warm start, as in the ε-stepping and continuation of §3.2).
#[derive(Debug, Clone)]
pub struct BroydenWorkspace {
    m: usize,
    b: Vec<f64>,
    h: Vec<f64>,
    has_jacobian: bool,
    /// `b` holds the current `B` (false after untracked updates: rebuilt from `H`).
    b_current: bool,
    /// Update `B` alongside `H` in every iteration (default `true`). Turn off when
    /// `B` is not read between solves: each iteration then saves two of its five
    /// O(m²) passes, and [`Self::jacobian`] rebuilds `B` from `H` on demand.
    pub track_jacobian: bool,
    /// The next quasi-Newton direction is already in `dx_next` (see [`Self::update`]).
    dx_next_ready: bool,
    /// Rows of `B` that the Broyden update leaves untouched (their equations are
    /// linear with an exact Jacobian row, e.g. the arc-length row Eq. 77).
    pub exact_rows: std::ops::Range<usize>,
    r: Vec<f64>,
    r_trial: Vec<f64>,
    x_trial: Vec<f64>,
    dx: Vec<f64>,
    dx_next: Vec<f64>,
    u: Vec<f64>,
    hu: Vec<f64>,
    sth: Vec<f64>,
    /// Factor of `B` or `H` when one is inverted from the other.
    lu: LuWorkspace,
    history: Vec<f64>,
}

impl BroydenWorkspace {
    /// Workspace for `m` unknowns with no Jacobian yet (the first solve then starts
    /// from a refreshed Jacobian unless [`Self::set_jacobian`] is called).
    pub fn new(m: usize) -> Self {
        Self {
            m,
            b: vec![0.0; m * m],
            h: vec![0.0; m * m],
            has_jacobian: false,
            b_current: true,
            track_jacobian: true,
            dx_next_ready: false,
            exact_rows: 0..0,
            r: vec![0.0; m],
            r_trial: vec![0.0; m],
            x_trial: vec![0.0; m],
            dx: vec![0.0; m],
            dx_next: vec![0.0; m],
            u: vec![0.0; m],
            hu: vec![0.0; m],
            sth: vec![0.0; m],
            lu: LuWorkspace::new(m),
            history: Vec::with_capacity(256),
        }
    }

    /// Number of unknowns.
    pub fn len(&self) -> usize {
        self.m
    }

    /// True for a zero-size workspace.
    pub fn is_empty(&self) -> bool {
        self.m == 0
    }

    /// Sets the initial Jacobian `B₀` (row-major `m×m`) and inverts it.
    ///
    /// # Errors
    /// [`SolveError::SingularJacobian`] if `B₀` is singular.
    pub fn set_jacobian(&mut self, b0: &[f64]) -> Result<(), SolveError> {
        copy_square(b0, &mut self.b)?;
        self.invert_b()
    }

    /// Sets only the inverse `H₀ = B₀⁻¹` (row-major `m×m`), e.g. of the
    /// block-diagonal linear Jacobian Eq. 60, skipping the O(m³) inversion; for a
    /// solve that does not read `B` ([`Self::track_jacobian`] off). `B` is rebuilt
    /// from `H` if asked.
    ///
    /// # Errors
    /// [`SolveError::Dimension`] on size mismatch.
    pub fn set_inverse_jacobian(&mut self, h0: &[f64]) -> Result<(), SolveError> {
        copy_square(h0, &mut self.h)?;
        self.b_current = false;
        self.has_jacobian = true;
        self.dx_next_ready = false;
        Ok(())
    }

    /// Gives mutable access to `B` for the caller to edit (e.g. to replace one
    /// column); call [`Self::refactor`] afterwards.
    pub fn jacobian_mut(&mut self) -> &mut [f64] {
        self.materialize_b();
        self.has_jacobian = false;
        &mut self.b
    }

    /// Re-inverts `B` after [`Self::jacobian_mut`] edits.
    ///
    /// # Errors
    /// [`SolveError::SingularJacobian`] if `B` is singular.
    pub fn refactor(&mut self) -> Result<(), SolveError> {
        self.invert_b()
    }

    /// Replaces row `i` of `B` by `row` and updates `H` by Sherman–Morrison
    /// (O(m²)); re-inverts if the update is ill-conditioned.
    ///
    /// # Errors
    /// [`SolveError::SingularJacobian`] if the new `B` is singular.
    pub fn replace_row(&mut self, i: usize, row: &[f64]) -> Result<(), SolveError> {
        let m = self.m;
        // B' = B + e_i dᵀ, d = row − B_i;  H' = H − (H e_i)(dᵀ H)/(1 + dᵀ H e_i).
        self.overwrite_b(row, |j| i * m + j);
        for j in 0..m {
            self.hu[j] = self.h[j * m + i];
        }
        self.sth.fill(0.0);
        for (uk, hrow) in self.u.iter().zip(self.h.chunks_exact(m)) {
            axpy(*uk, hrow, &mut self.sth);
        }
        self.sherman_morrison(1.0 + self.sth[i])
    }

    /// Replaces column `j` of `B` by `col` and updates `H` by Sherman–Morrison.
    ///
    /// # Errors
    /// [`SolveError::SingularJacobian`] if the new `B` is singular.
    pub fn replace_col(&mut self, j: usize, col: &[f64]) -> Result<(), SolveError> {
        let m = self.m;
        // B' = B + c e_jᵀ, c = col − B_:j;  H' = H − (H c)(e_jᵀ H)/(1 + e_jᵀ H c).
        self.overwrite_b(col, |i| i * m + j);
        for i in 0..m {
            self.hu[i] = dot(&self.h[i * m..(i + 1) * m], &self.u);
        }
        self.sth.copy_from_slice(&self.h[j * m..(j + 1) * m]);
        self.sherman_morrison(1.0 + self.hu[j])
    }

    /// Writes `new` over the entries `at(k)` of `B` (one row or column, made
    /// current first) and leaves the change `new − old` in `u`.
    fn overwrite_b(&mut self, new: &[f64], at: impl Fn(usize) -> usize) {
        self.materialize_b();
        for (k, (u, &v)) in self.u.iter_mut().zip(new).enumerate() {
            let e = at(k);
            *u = v - self.b[e];
            self.b[e] = v;
        }
    }

    /// `H ← H − hu sthᵀ / denom`, or a full inversion when `denom` is tiny.
    fn sherman_morrison(&mut self, denom: f64) -> Result<(), SolveError> {
        let m = self.m;
        if !self.has_jacobian || denom.abs() < 1e-8 || !denom.is_finite() {
            return self.invert_b();
        }
        for i in 0..m {
            let f = self.hu[i] / denom;
            for (hij, s) in self.h[i * m..(i + 1) * m].iter_mut().zip(&self.sth) {
                *hij -= f * s;
            }
        }
        Ok(())
    }

    /// Current approximate Jacobian `B` (row-major); rebuilt from `H` when
    /// [`Self::track_jacobian`] was off (NaN-filled if `H` is singular, which an `H`
    /// built by the solver is not unless it overflowed).
    pub fn jacobian(&mut self) -> &[f64] {
        self.materialize_b();
        &self.b
    }

    /// Makes `b` the current `B` by inverting `H` if untracked updates left it stale.
    fn materialize_b(&mut self) {
        if self.b_current {
            return;
        }
        if !invert(&mut self.lu, &self.h, &mut self.b) {
            self.b.fill(f64::NAN);
        }
        self.b_current = true;
    }

    /// Current approximate inverse Jacobian `H = B⁻¹` (row-major).
    pub fn inverse_jacobian(&self) -> &[f64] {
        &self.h
    }

    /// Whether a Jacobian is set (otherwise the next solve refreshes first).
    pub fn has_jacobian(&self) -> bool {
        self.has_jacobian
    }

    /// Forgets the Jacobian so the next solve starts with a refresh.
    pub fn clear_jacobian(&mut self) {
        self.has_jacobian = false;
    }

    /// ‖F‖₂ after each accepted step of the last solve (first: initial guess).
    pub fn history(&self) -> &[f64] {
        &self.history
    }

    /// Last residual vector `F(x)` of the last solve.
    pub fn residual(&self) -> &[f64] {
        &self.r
    }

    fn invert_b(&mut self) -> Result<(), SolveError> {
        self.b_current = true;
        self.dx_next_ready = false;
        self.has_jacobian = invert(&mut self.lu, &self.b, &mut self.h);
        if self.has_jacobian {
            Ok(())
        } else {
            Err(SolveError::SingularJacobian {
                iteration: 0,
                history: self.history.clone(),
            })
        }
    }

    /// [`Self::refresh`] at `x`, then `H = B⁻¹`, counting the work in `stats`.
    ///
    /// # Errors
    /// [`SolveError::SingularJacobian`] with the history so far if `B` is singular.
    fn refresh_inverse<S: System + ?Sized>(
        &mut self,
        sys: &mut S,
        x: &[f64],
        fd_step: f64,
        stats: &mut BroydenStats,
    ) -> Result<(), SolveError> {
        stats.residual_evals += self.refresh(sys, x, fd_step);
        stats.jacobian_refreshes += 1;
        self.invert_b().map_err(|_| SolveError::SingularJacobian {
            iteration: stats.iterations,
            history: self.history.clone(),
        })
    }

    /// Refreshes `B` at `x` (whose residual is in `self.r`) from the system's
    /// Jacobian or by forward differences; returns residual evaluations used.
    fn refresh<S: System + ?Sized>(&mut self, sys: &mut S, x: &[f64], fd_step: f64) -> usize {
        let m = self.m;
        if sys.jacobian(x, &mut self.b) {
            return 0;
        }
        self.x_trial.copy_from_slice(x);
        for j in 0..m {
            let h = fd_step * x[j].abs().max(1.0);
            self.x_trial[j] = x[j] + h;
            let hh = self.x_trial[j] - x[j];
            sys.residual(&self.x_trial, &mut self.r_trial);
            for i in 0..m {
                self.b[i * m + j] = (self.r_trial[i] - self.r[i]) / hh;
            }
            self.x_trial[j] = x[j];
        }
        m
    }

    /// Rank-one "good Broyden" update (Eq. 67) with `s = dx` (the accepted step,
    /// `t` times the direction `−H r`) and `y = r_trial − r`; rows in `exact_rows`
    /// are kept. `H` follows by Sherman–Morrison, `B` only when tracked.
    /// Returns `false` if the update would make `B` singular.
    fn update(&mut self, t: f64) -> bool {
        let m = self.m;
        let ss = dot(&self.dx, &self.dx);
        if ss == 0.0 || !ss.is_finite() {
            return false;
        }
        // u = y − B s, masked on the exact rows; untracked, B s = −t r (B = H⁻¹).
        for i in 0..m {
            self.u[i] = if self.exact_rows.contains(&i) {
                0.0
            } else if self.track_jacobian {
                (self.r_trial[i] - self.r[i]) - dot(&self.b[i * m..(i + 1) * m], &self.dx)
            } else {
                self.r_trial[i] - (1.0 - t) * self.r[i]
            };
        }
        // B ← B + u sᵀ/ss;  H ← H − (H u)(sᵀ H)/(ss + sᵀ H u).
        for i in 0..m {
            self.hu[i] = dot(&self.h[i * m..(i + 1) * m], &self.u);
        }
        self.sth.fill(0.0);
        for (si, hrow) in self.dx.iter().zip(self.h.chunks_exact(m)) {
            axpy(*si, hrow, &mut self.sth);
        }
        let denom = ss + dot(&self.dx, &self.hu);
        if denom.abs() <= 1e-14 * ss || !denom.is_finite() {
            return false;
        }
        for (i, hrow) in self.h.chunks_exact_mut(m).enumerate() {
            axpy(-self.hu[i] / denom, &self.sth, hrow);
        }
        if self.track_jacobian {
            for (i, brow) in self.b.chunks_exact_mut(m).enumerate() {
                axpy(self.u[i] / ss, &self.dx, brow);
            }
        } else {
            self.b_current = false;
        }
        // A full untracked step with no masked row has u = r_trial, so the next
        // direction −H' r_trial = −(ss/denom)·H u needs no further product.
        self.dx_next_ready = !self.track_jacobian && t == 1.0 && self.exact_rows.is_empty();
        if self.dx_next_ready {
            let f = -ss / denom;
            for (d, hu) in self.dx_next.iter_mut().zip(&self.hu) {
                *d = f * hu;
            }
        }
        true
    }
}

/// Copies the `m×m` matrix `from` into `to` (`m²` entries).
///
/// # Errors
/// `out = a⁻¹` (row-major) through `lu`; `false` only if the inverse is not
/// finite (an exactly zero pivot or a poisoned matrix). A badly conditioned
/// `B` is inverted all the same: Broyden's approximations are often poorly
/// conditioned in strongly nonlinear solves, and their quasi-Newton steps stay
/// useful there (the line search and the refresh policy judge them).
fn invert(lu: &mut LuWorkspace, a: &[f64], out: &mut [f64]) -> bool {
    // The factor's own verdict (pivots above n·ε of the largest) is stricter
    // than this solver needs; only a non-finite inverse is refused.
    let _well_conditioned = lu.factor_row_major(a);
    lu.inverse_into(out)
}

/// [`SolveError::Dimension`] if the lengths differ.
fn copy_square(from: &[f64], to: &mut [f64]) -> Result<(), SolveError> {
    if from.len() != to.len() {
        return Err(SolveError::Dimension {
            expected: to.len(),
            got: from.len(),
        });
    }
    to.copy_from_slice(from);
    Ok(())
}

/// Solves `F(x) = 0` by Broyden's method from the initial guess `x` (overwritten
/// by the solution), starting from the Jacobian held in `ws` (set with
/// [`BroydenWorkspace::set_jacobian`] or left from a previous solve; refreshed if
/// none).
///
/// # Errors
/// [`SolveError`] with the residual history when the tolerance is not reached,
/// the residual is not finite, or the Jacobian is singular.
pub fn broyden_solve<S: System + ?Sized>(
    sys: &mut S,
    x: &mut [f64],
    ws: &mut BroydenWorkspace,
    opts: &BroydenOptions,
) -> Result<BroydenStats, SolveError> {
    let m = ws.m;
    if x.len() != m {
        return Err(SolveError::Dimension {
            expected: m,
            got: x.len(),
        });
    }
    ws.history.clear();
    ws.dx_next_ready = false;
    if ws.track_jacobian {
        ws.materialize_b();
    }
    if !x.iter().all(|v| v.is_finite()) {
        return Err(SolveError::NonFinite {
            iteration: 0,
            history: Vec::new(),
        });
    }
    let mut stats = BroydenStats {
        iterations: 0,
        residual_evals: 1,
        jacobian_refreshes: 0,
        residual_norm: 0.0,
    };
    sys.residual(x, &mut ws.r);
    let mut norm = norm2(&ws.r);
    ws.history.push(norm);
    if !norm.is_finite() {
        return Err(SolveError::NonFinite {
            iteration: 0,
            history: ws.history.clone(),
        });
    }
    if !ws.has_jacobian {
        ws.refresh_inverse(sys, x, opts.fd_step, &mut stats)?;
    }
    let mut stalled = 0usize;
    while norm > opts.tol {
        if stats.iterations >= opts.max_iter {
            stats.residual_norm = norm;
            return Err(SolveError::NonConvergence {
                iterations: stats.iterations,
                history: ws.history.clone(),
            });
        }
        stats.iterations += 1;
        // Quasi-Newton direction dx = −H r (Eq. 66).
        if ws.dx_next_ready {
            std::mem::swap(&mut ws.dx, &mut ws.dx_next);
            ws.dx_next_ready = false;
        } else {
            for i in 0..m {
                ws.dx[i] = -dot(&ws.h[i * m..(i + 1) * m], &ws.r);
            }
        }
        // Backtracking line search on ‖F‖.
        let mut t = 1.0;
        let mut accepted = false;
        let mut trial_norm = f64::INFINITY;
        for _ in 0..=opts.max_backtracks {
            for i in 0..m {
                ws.x_trial[i] = x[i] + t * ws.dx[i];
            }
            sys.residual(&ws.x_trial, &mut ws.r_trial);
            stats.residual_evals += 1;
            trial_norm = norm2(&ws.r_trial);
            if trial_norm.is_finite() && trial_norm < norm {
                accepted = true;
                break;
            }
            t *= 0.5;
        }
        let can_refresh = opts.jacobian_refresh && stats.jacobian_refreshes < opts.max_refreshes;
        if !accepted {
            if !can_refresh {
                return Err(SolveError::NonConvergence {
                    iterations: stats.iterations,
                    history: ws.history.clone(),
                });
            }
            stalled = 0;
            ws.refresh_inverse(sys, x, opts.fd_step, &mut stats)?;
            continue;
        }
        // Accept the step; s = t·dx.
        if t != 1.0 {
            ws.dx.iter_mut().for_each(|v| *v *= t);
        }
        let updated = ws.update(t);
        x.copy_from_slice(&ws.x_trial);
        std::mem::swap(&mut ws.r, &mut ws.r_trial);
        let ratio = trial_norm / norm;
        norm = trial_norm;
        ws.history.push(norm);
        stalled = if ratio > opts.stall_ratio {
            stalled + 1
        } else {
            0
        };
        if (!updated || stalled >= opts.stall_iters) && norm > opts.tol {
            if !can_refresh {
                if !updated {
                    return Err(SolveError::SingularJacobian {
                        iteration: stats.iterations,
                        history: ws.history.clone(),
                    });
                }
                continue;
            }
            stalled = 0;
            ws.refresh_inverse(sys, x, opts.fd_step, &mut stats)?;
        }
    }
    stats.residual_norm = norm;
    Ok(stats)
}

#[cfg(test)]
mod tests;
