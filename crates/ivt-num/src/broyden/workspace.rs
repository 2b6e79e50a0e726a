//! The Broyden solver's caller-owned state and its O(m²) kernels: the quasi-Newton
//! direction, the rank-one "good Broyden" update (Eq. 67) with `H = B⁻¹` following by
//! Sherman–Morrison, row/column replacement, and the Jacobian refresh.
//!
//! Matrices are row-major `m×m` and walked by whole rows ([`rows`]), so no index
//! is computed in the loops; the only indexed accesses (one row or column chosen
//! by the caller) are checked, a wrong index or length a [`SolveError::Dimension`].

use crate::iteration::{Progress, SolveError};
use crate::vector::{axpy, dot, matvec, norm2};
use crate::LuWorkspace;

use super::inverse::{rows, rows_mut, InverseJacobian};
use super::{BlockDiagonal, BroydenStats, System};

/// Caller-owned state of the solver: `B`, `H = B⁻¹` and all scratch vectors.
///
/// Reuse one workspace across solves of the same size: after a solve, `B`/`H`
/// hold the last Broyden approximation, which [`super::broyden_solve`] uses as the
/// next initial Jacobian (warm start, as in the ε-stepping and continuation of §3.2).
#[derive(Debug, Clone)]
pub struct BroydenWorkspace {
    m: usize,
    b: Vec<f64>,
    h: InverseJacobian,
    has_jacobian: bool,
    /// `b` holds the current `B` (false after untracked updates: rebuilt from `H`).
    b_current: bool,
    /// Update `B` alongside `H` in every iteration (default `true`). Turn off when
    /// `B` is not read between solves: each iteration then saves two of its five
    /// O(m²) passes, and [`Self::jacobian`] rebuilds `B` from `H` on demand.
    pub track_jacobian: bool,
    /// While `B` is not tracked, keep this one column of `B` current anyway
    /// (O(m) per update), so [`Self::replace_col`] of it and
    /// [`Self::replace_row`] of an exact row need no inversion: the
    /// continuation corrector's `B_λ` column and arc-length row (Eq. 72).
    pub tracked_column: Option<usize>,
    /// `b`'s exact rows and its tracked column are current (while `b` is stale
    /// as a whole); false once `H` was set directly.
    b_lines_current: bool,
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
    /// Factor of `B` or `H` when one is inverted from the other; built on the
    /// first inversion (a solve seeded with `H₀` by
    /// [`Self::set_inverse_jacobian`] usually never inverts, and the `m×m`
    /// zero-filled factor was a fifth of the set-up's allocations).
    lu: Option<LuWorkspace>,
    history: Vec<f64>,
}

impl BroydenWorkspace {
    /// Workspace for `m` unknowns with no Jacobian yet (the first solve then starts
    /// from a refreshed Jacobian unless [`Self::set_jacobian`] is called).
    pub fn new(m: usize) -> Self {
        Self {
            m,
            b: vec![0.0; m * m],
            h: InverseJacobian::new(m),
            has_jacobian: false,
            b_current: true,
            track_jacobian: true,
            tracked_column: None,
            b_lines_current: true,
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
            lu: None,
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
    /// [`SolveError::Dimension`] on size mismatch, [`SolveError::SingularJacobian`]
    /// if `B₀` is singular.
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
        copy_square(h0, self.h.overwrite())?;
        self.seeded_with_inverse();
        Ok(())
    }

    /// Sets `H₀` as a [`BlockDiagonal`] matrix, e.g. the inverse of the linear
    /// Jacobian Eq. 60: like [`Self::set_inverse_jacobian`], and while `B` is not
    /// tracked the iteration keeps `H` as `H₀` plus its rank-one updates, so no
    /// step costs O(m²).
    ///
    /// # Errors
    /// [`SolveError::Dimension`] unless `h0` is `m×m`.
    pub fn set_inverse_jacobian_blocks(&mut self, h0: &BlockDiagonal) -> Result<(), SolveError> {
        if h0.len() != self.m {
            return Err(SolveError::Dimension {
                expected: self.m,
                got: h0.len(),
            });
        }
        self.h.set_blocks(h0);
        self.seeded_with_inverse();
        Ok(())
    }

    /// State after `H` was set directly: `B` stale, a Jacobian present.
    fn seeded_with_inverse(&mut self) {
        self.b_current = false;
        self.b_lines_current = false;
        self.has_jacobian = true;
        self.dx_next_ready = false;
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
    /// [`SolveError::Dimension`] if `row.len() ≠ m` or `i ≥ m` (then `got` is the
    /// `i + 1` unknowns row `i` would need); [`SolveError::SingularJacobian`] if the
    /// new `B` is singular.
    pub fn replace_row(&mut self, i: usize, row: &[f64]) -> Result<(), SolveError> {
        self.check_line(i, row)?;
        let m = self.m;
        // B' = B + e_i dᵀ, d = row − B_i;  H' = H − (H e_i)(dᵀ H)/(1 + dᵀ H e_i).
        if !(self.b_lines_current && self.exact_rows.contains(&i)) {
            self.materialize_b();
        }
        let b_i = rows_mut(&mut self.b, m).nth(i).into_iter().flatten();
        overwrite(b_i, row, &mut self.u);
        let h = self.h.dense();
        for (hu, hrow) in self.hu.iter_mut().zip(rows(h, m)) {
            *hu = hrow.get(i).copied().unwrap_or(f64::NAN);
        }
        self.h.mul_transpose(&self.u, &mut self.sth);
        self.sherman_morrison(1.0 + self.sth.get(i).copied().unwrap_or(f64::NAN))
    }

    /// Replaces column `j` of `B` by `col` and updates `H` by Sherman–Morrison.
    ///
    /// # Errors
    /// [`SolveError::Dimension`] if `col.len() ≠ m` or `j ≥ m` (as in
    /// [`Self::replace_row`]); [`SolveError::SingularJacobian`] if the new `B` is
    /// singular.
    pub fn replace_col(&mut self, j: usize, col: &[f64]) -> Result<(), SolveError> {
        self.check_line(j, col)?;
        let m = self.m;
        // B' = B + c e_jᵀ, c = col − B_:j;  H' = H − (H c)(e_jᵀ H)/(1 + e_jᵀ H c).
        if !(self.b_lines_current && self.tracked_column == Some(j)) {
            self.materialize_b();
        }
        let b_j = rows_mut(&mut self.b, m).filter_map(|brow| brow.get_mut(j));
        overwrite(b_j, col, &mut self.u);
        let h = self.h.dense();
        matvec(h, m, m, &self.u, &mut self.hu);
        for (s, h) in self
            .sth
            .iter_mut()
            .zip(rows(h, m).nth(j).into_iter().flatten())
        {
            *s = *h;
        }
        self.sherman_morrison(1.0 + self.hu.get(j).copied().unwrap_or(f64::NAN))
    }

    /// [`SolveError::Dimension`] unless `line` has `m` entries and `k < m` (the row
    /// or column `k` of an `m×m` matrix).
    fn check_line(&self, k: usize, line: &[f64]) -> Result<(), SolveError> {
        let got = if line.len() != self.m {
            line.len()
        } else if k >= self.m {
            k.saturating_add(1)
        } else {
            return Ok(());
        };
        Err(SolveError::Dimension {
            expected: self.m,
            got,
        })
    }

    /// `H ← H − hu sthᵀ / denom`, or a full inversion when `denom` is tiny.
    fn sherman_morrison(&mut self, denom: f64) -> Result<(), SolveError> {
        if !self.has_jacobian || denom.abs() < 1e-8 || !denom.is_finite() {
            return self.invert_b();
        }
        for (hui, hrow) in self.hu.iter().zip(rows_mut(self.h.dense(), self.m)) {
            axpy(-(hui / denom), &self.sth, hrow);
        }
        Ok(())
    }

    /// Entry `(i, j)` of the current `B`, without rebuilding `B` when the entry
    /// is on an exact row or the tracked column; `None` out of range.
    pub fn jacobian_entry(&mut self, i: usize, j: usize) -> Option<f64> {
        let known = self.b_lines_current
            && (self.exact_rows.contains(&i) || self.tracked_column == Some(j));
        if !known {
            self.materialize_b();
        }
        if i >= self.m || j >= self.m {
            return None;
        }
        self.b.get(i * self.m + j).copied()
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
        if !invert(&mut self.lu, self.m, self.h.dense(), &mut self.b) {
            self.b.fill(f64::NAN);
        }
        self.b_current = true;
        self.b_lines_current = true;
    }

    /// Current approximate inverse Jacobian `H = B⁻¹` (row-major; formed from
    /// its factors if the solve kept it factored).
    pub fn inverse_jacobian(&mut self) -> &[f64] {
        self.h.dense()
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
        self.b_lines_current = true;
        self.dx_next_ready = false;
        self.has_jacobian = invert(&mut self.lu, self.m, &self.b, self.h.overwrite());
        if self.has_jacobian {
            Ok(())
        } else {
            Err(SolveError::SingularJacobian {
                iteration: 0,
                history: self.history.clone(),
            })
        }
    }

    /// Starts a solve: forgets the last history and any prepared direction, and
    /// makes `B` current when it is tracked.
    pub(super) fn begin(&mut self) {
        self.history.clear();
        self.dx_next_ready = false;
        if self.track_jacobian {
            self.materialize_b();
        }
    }

    /// Evaluates `F(x)` into the current residual; returns ‖F(x)‖₂.
    pub(super) fn evaluate<S: System + ?Sized>(&mut self, sys: &mut S, x: &[f64]) -> f64 {
        sys.residual(x, &mut self.r);
        norm2(&self.r)
    }

    /// The history buffer, for the executor to record the solve in
    /// ([`Self::restore_history`] gives it back).
    pub(super) fn take_history(&mut self) -> Vec<f64> {
        std::mem::take(&mut self.history)
    }

    /// Keeps the solve's history (read by [`Self::history`]).
    pub(super) fn restore_history(&mut self, history: Vec<f64>) {
        self.history = history;
    }

    /// The quasi-Newton direction `dx = −H r` (Eq. 66), or the one [`Self::update`]
    /// already prepared.
    pub(super) fn direction(&mut self) {
        if self.dx_next_ready {
            std::mem::swap(&mut self.dx, &mut self.dx_next);
            self.dx_next_ready = false;
        } else {
            self.h.mul(&self.r, &mut self.dx);
            self.dx.iter_mut().for_each(|d| *d = -*d);
        }
    }

    /// Evaluates the trial point `x + t·dx` of the line search; returns its ‖F‖₂.
    pub(super) fn trial<S: System + ?Sized>(&mut self, sys: &mut S, x: &[f64], t: f64) -> f64 {
        for ((xt, xi), d) in self.x_trial.iter_mut().zip(x).zip(&self.dx) {
            *xt = xi + t * d;
        }
        sys.residual(&self.x_trial, &mut self.r_trial);
        norm2(&self.r_trial)
    }

    /// Accepts the trial point of step length `t` into `x` (and its residual),
    /// after the rank-one update with `s = t·dx`; returns whether `B`/`H` were
    /// updated (`false`: the update would have made `B` singular).
    pub(super) fn accept(&mut self, t: f64, x: &mut [f64]) -> bool {
        if t != 1.0 {
            self.dx.iter_mut().for_each(|v| *v *= t);
        }
        let updated = self.update(t);
        for (xi, xt) in x.iter_mut().zip(&self.x_trial) {
            *xi = *xt;
        }
        std::mem::swap(&mut self.r, &mut self.r_trial);
        updated
    }

    /// [`Self::refresh`] at `x`, then `H = B⁻¹`, counting the work in `stats`.
    ///
    /// # Errors
    /// [`SolveError::SingularJacobian`] with the history so far (`at`) if `B`
    /// is singular.
    pub(super) fn refresh_inverse<S: System + ?Sized>(
        &mut self,
        sys: &mut S,
        x: &[f64],
        fd_step: f64,
        stats: &mut BroydenStats,
        at: Progress<'_>,
    ) -> Result<(), SolveError> {
        stats.residual_evals += self.refresh(sys, x, fd_step);
        stats.jacobian_refreshes += 1;
        self.invert_b().map_err(|_| at.singular())
    }

    /// Refreshes `B` at `x` (whose residual is in `self.r`) from the system's
    /// Jacobian or by forward differences; returns residual evaluations used.
    fn refresh<S: System + ?Sized>(&mut self, sys: &mut S, x: &[f64], fd_step: f64) -> usize {
        let m = self.m;
        if sys.jacobian(x, &mut self.b) {
            return 0;
        }
        for (xt, xi) in self.x_trial.iter_mut().zip(x) {
            *xt = *xi;
        }
        let mut evals = 0;
        for (j, &xj) in x.iter().enumerate().take(m) {
            let h = fd_step * xj.abs().max(1.0);
            let hh = self.x_trial.get_mut(j).map_or(h, |xt| {
                *xt = xj + h;
                *xt - xj
            });
            sys.residual(&self.x_trial, &mut self.r_trial);
            evals += 1;
            let column = rows_mut(&mut self.b, m).filter_map(|brow| brow.get_mut(j));
            for (bij, (rt, r)) in column.zip(self.r_trial.iter().zip(&self.r)) {
                *bij = (rt - r) / hh;
            }
            if let Some(xt) = self.x_trial.get_mut(j) {
                *xt = xj;
            }
        }
        evals
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
        let y = self.r_trial.iter().zip(&self.r);
        for (i, ((u, (rt, r)), brow)) in self.u.iter_mut().zip(y).zip(rows(&self.b, m)).enumerate()
        {
            *u = if self.exact_rows.contains(&i) {
                0.0
            } else if self.track_jacobian {
                (rt - r) - dot(brow, &self.dx)
            } else {
                rt - (1.0 - t) * r
            };
        }
        // B ← B + u sᵀ/ss;  H ← H − (H u)(sᵀ H)/(ss + sᵀ H u) (kept as the pair
        // (−H u/denom, Hᵀ s) on a block-diagonal H₀).
        self.h.mul(&self.u, &mut self.hu);
        self.h.mul_transpose(&self.dx, &mut self.sth);
        let denom = ss + dot(&self.dx, &self.hu);
        if denom.abs() <= 1e-14 * ss || !denom.is_finite() {
            return false;
        }
        self.h
            .add_rank_one(self.hu.iter().map(|hu| -hu / denom), &self.sth);
        if self.track_jacobian {
            for (ui, brow) in self.u.iter().zip(rows_mut(&mut self.b, m)) {
                axpy(ui / ss, &self.dx, brow);
            }
        } else {
            self.b_current = false;
            if let Some(j) = self.tracked_column {
                let f = self.dx.get(j).copied().unwrap_or(f64::NAN) / ss;
                for (ui, brow) in self.u.iter().zip(rows_mut(&mut self.b, m)) {
                    if let Some(bij) = brow.get_mut(j) {
                        *bij += ui * f;
                    }
                }
            }
        }
        // A full untracked step has u = r_trial off the exact rows, so the next
        // direction −H' r_trial = −(ss/denom)·H u − Σ_exact r_trial,i·H'e_i needs
        // no further O(m²) product (the columns H'e_i are read when H is dense).
        self.dx_next_ready =
            !self.track_jacobian && t == 1.0 && (self.exact_rows.is_empty() || self.h.is_dense());
        if self.dx_next_ready {
            let f = -ss / denom;
            for (d, hu) in self.dx_next.iter_mut().zip(&self.hu) {
                *d = f * hu;
            }
            for i in self.exact_rows.clone() {
                let rt = self.r_trial.get(i).copied().unwrap_or(f64::NAN);
                self.h.axpy_column(i, -rt, &mut self.dx_next);
            }
        }
        true
    }
}

/// Writes `new` over `entries` (one row or column of `B`) and leaves the change
/// `new − old` in `change`.
fn overwrite<'a>(entries: impl Iterator<Item = &'a mut f64>, new: &[f64], change: &mut [f64]) {
    for ((b, &v), c) in entries.zip(new).zip(change) {
        *c = v - *b;
        *b = v;
    }
}

/// `out = a⁻¹` (row-major, `m×m`) through `lu` (built for `m` on first use);
/// `false` only if the inverse is not
/// finite (an exactly zero pivot or a poisoned matrix). A badly conditioned
/// `B` is inverted all the same: Broyden's approximations are often poorly
/// conditioned in strongly nonlinear solves, and their quasi-Newton steps stay
/// useful there (the line search and the refresh policy judge them).
fn invert(lu: &mut Option<LuWorkspace>, m: usize, a: &[f64], out: &mut [f64]) -> bool {
    let lu = lu.get_or_insert_with(|| LuWorkspace::new(m));
    // The factor's own verdict (pivots above n·ε of the largest) is stricter
    // than this solver needs; only a non-finite inverse is refused.
    let _well_conditioned = lu.factor_row_major(a);
    lu.inverse_into(out)
}

/// Copies the `m×m` matrix `from` into `to` (`m²` entries).
///
/// # Errors
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
