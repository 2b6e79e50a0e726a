//! The condensed branch in scaled unknowns, the variables the path follower
//! and the fold locator see: `q̃ = q/q_s` (q_s the linear response of the
//! nonlinear DOFs at the start) and `λ̃ = ω_f/ω_s` (ω_s the sweep's width),
//! the residual (a displacement) divided by q_s.
//!
//! Why: the correctors' tolerances are absolute on `[R; tᵀ(x − x_pred)]`.
//! In physical units the constraint row carries λ's rounding, ε·ω_f, which
//! for the bladed disk (ω_f ≈ 1200 rad/s, ε·ω_f ≈ 3e-13) is far above the
//! residual's tolerance (1e-12 of a 1e-6 m response): the corrector could
//! not converge and kept halving the step (> 5000 steps for the band). The
//! arclength itself mixed metres and rad/s, so the step size meant
//! something else on every model. Scaled, both rows are of order one and a
//! step `ds` is a fraction of the sweep and of the start's response.
//!
//! The residual is further divided by the point's own size,
//! `w(q̃) = max(1, ‖q̃‖₂)`, so a tolerance on it is relative to
//! max(‖u_S‖ at the start, ‖q‖ of the point). Why: near a lightly damped
//! resonance the response grows hundreds of times above the start's, and
//! with it the rounding of the residual (`∂R̃/∂λ̃` times λ̃'s rounding):
//! on `x″ + 0.002 x′ + x = cos θ` a tolerance of 1e-12 of the start's
//! response was unattainable 110× above it, and the sweep stopped 70 % below
//! the peak (`tests/condensed_resonance.rs`). Where ‖q̃‖₂ ≤ 1 (the start's
//! linear response has ‖q̃‖₂ = 1) nothing changes. The Jacobian and the
//! λ-derivatives are divided by the same `w` without its gradient: a Newton
//! step `−(J/w)⁻¹(R/w) = −J⁻¹R` (bordered likewise) is the unweighted one
//! (a chord step on another point's factorization, by the ratio of the two
//! weights, near 1),
//! and the omitted term `−R ∇wᵀ/w²` vanishes on the curve (R = 0), so the
//! iterates and every root (points, folds) are those of `R`; only where the
//! correctors stop moves.

use super::branch::CondensedBranch;
use ivt_hb::problem::PeriodicProblem;
use ivt_path::branch::Branch;

/// [`CondensedBranch`] seen in scaled unknowns (module docs).
pub(crate) struct Scaled<'a, P: PeriodicProblem> {
    pub(crate) branch: &'a mut CondensedBranch<P>,
    q_scale: f64,
    w_origin: f64,
    w_scale: f64,
    /// The physical unknowns of the last call.
    q: Vec<f64>,
}

impl<'a, P: PeriodicProblem> Scaled<'a, P> {
    /// `branch` with `q = q_scale·q̃`, `ω_f = w_origin + w_scale·λ̃` (scales
    /// positive).
    pub(crate) fn new(
        branch: &'a mut CondensedBranch<P>,
        q_scale: f64,
        w_origin: f64,
        w_scale: f64,
    ) -> Self {
        let m = Branch::len(branch);
        Self {
            branch,
            q_scale,
            w_origin,
            w_scale,
            q: vec![0.0; m],
        }
    }

    /// `(q, ω_f)` of the scaled `(q̃, λ̃)`.
    pub(crate) fn physical(&self, q: &[f64], lambda: f64) -> (Vec<f64>, f64) {
        (
            q.iter().map(|v| v * self.q_scale).collect(),
            self.omega(lambda),
        )
    }

    /// The scaled point `[q̃, λ̃]` of `(q, ω_f)`.
    pub(crate) fn scaled(&self, q: &[f64], omega_f: f64) -> Vec<f64> {
        q.iter()
            .map(|v| v / self.q_scale)
            .chain([self.lambda(omega_f)])
            .collect()
    }

    /// λ̃ of ω_f.
    pub(crate) fn lambda(&self, omega_f: f64) -> f64 {
        (omega_f - self.w_origin) / self.w_scale
    }

    /// ω_f of λ̃.
    pub(crate) fn omega(&self, lambda: f64) -> f64 {
        self.w_origin + lambda * self.w_scale
    }

    /// Stores the physical unknowns of `u` in `self.q`; returns the
    /// weight `w(u) = max(1, ‖u‖₂)` of the residual at `u` (module docs).
    fn load(&mut self, u: &[f64]) -> f64 {
        self.q
            .iter_mut()
            .zip(u)
            .for_each(|(q, v)| *q = v * self.q_scale);
        ivt_num::vector::norm2(u).max(1.0)
    }
}

impl<P: PeriodicProblem> Branch for Scaled<'_, P> {
    fn len(&self) -> usize {
        self.q.len()
    }
    fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]) {
        let weight = self.load(q);
        let omega_f = self.omega(lambda);
        Branch::residual(self.branch, &self.q, omega_f, r);
        let divisor = self.q_scale * weight;
        r.iter_mut().for_each(|v| *v /= divisor);
    }
    /// `∂R̃/∂q̃ = ∂R/∂q / w(q̃)`: the scales `q_s` cancel; `w`'s gradient is
    /// omitted (module docs).
    fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]) {
        let weight = self.load(q);
        let omega_f = self.omega(lambda);
        Branch::jacobian(self.branch, &self.q, omega_f, jac);
        if weight != 1.0 {
            jac.iter_mut().for_each(|v| *v /= weight);
        }
    }
    fn residual_lambda(&mut self, q: &[f64], lambda: f64, h: f64, out: &mut [f64]) {
        let weight = self.load(q);
        let (w, omega_f) = (self.w_scale, self.omega(lambda));
        Branch::residual_lambda(self.branch, &self.q, omega_f, h * w, out);
        let factor = w / self.q_scale / weight;
        out.iter_mut().for_each(|v| *v *= factor);
    }
    /// `∂J̃/∂λ̃ = ω_s ∂J/∂ω_f / w(q̃)` (the branch's own, exact in the
    /// receptances).
    fn bilinear_lambda(&mut self, q: &[f64], lambda: f64, h: f64, w: &[f64], v: &[f64]) -> f64 {
        let weight = self.load(q);
        let (ws, omega_f) = (self.w_scale, self.omega(lambda));
        ws * Branch::bilinear_lambda(self.branch, &self.q, omega_f, h * ws, w, v) / weight
    }
}
