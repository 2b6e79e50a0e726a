//! The one-parameter family of square systems `R(q, λ) = 0` that continuation
//! and the event locators ([`crate::events`]) work on, with `∂R/∂q` and the
//! derivatives of the fold test function `wᵀ J(q, λ) v` (Govaerts' bordering,
//! [`crate::locate_fold`]): by default from central differences.
//!
//! [`crate::FamilyBranch`] is the harmonic-balance residual (Eq. 61) in any
//! parameter λ (e.g. `|w| (&problem, w)` for λ = ω_f, the branch of a
//! frequency-response curve) with the exact Galerkin Jacobian (Eq. 56).
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]
#![cfg_attr(not(test), deny(clippy::panic, clippy::indexing_slicing))]
#![cfg_attr(not(test), deny(clippy::unreachable, clippy::todo))]
#![cfg_attr(not(test), deny(clippy::unimplemented))]

/// A one-parameter family of square systems `R(q, λ) = 0` with `∂R/∂q`.
pub trait Branch {
    /// Number of unknowns `m` (λ excluded).
    fn len(&self) -> usize;
    /// True for a branch without unknowns.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// `R(q, λ)` into `r` (`m`).
    fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]);
    /// `∂R/∂q` at `(q, λ)`, row-major `m×m`, into `jac`.
    fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]);
    /// `wᵀ J(q, λ) v`. Default: from an assembled [`Self::jacobian`].
    fn bilinear(&mut self, q: &[f64], lambda: f64, w: &[f64], v: &[f64]) -> f64 {
        let m = q.len();
        let mut jac = vec![0.0; m * m];
        self.jacobian(q, lambda, &mut jac);
        bilinear_form(&jac, w, v)
    }
    /// `∂/∂q (wᵀ J(q, λ) v)` into `out` (`m`): the gradient of the fold test
    /// function is `−` this at the bordered solutions `v`, `w`. Default:
    /// [`fd_jacobian_gradient`] (2m Jacobians); override with a cheaper form.
    fn jacobian_gradient(&mut self, q: &[f64], lambda: f64, w: &[f64], v: &[f64], out: &mut [f64])
    where
        Self: Sized,
    {
        fd_jacobian_gradient(self, q, lambda, w, v, 1e-6, out);
    }
    /// `∂R/∂λ` at `(q, λ)` into `out` (`m`): the λ column of the fold system.
    /// Default: [`residual_lambda_difference`] with step `h`.
    fn residual_lambda(&mut self, q: &[f64], lambda: f64, h: f64, out: &mut [f64]) {
        residual_lambda_difference(self, q, lambda, h, out);
    }
    /// `∂(wᵀ J v)/∂λ` at `(q, λ)`. Default: [`bilinear_lambda_difference`]
    /// with step `h`.
    fn bilinear_lambda(&mut self, q: &[f64], lambda: f64, h: f64, w: &[f64], v: &[f64]) -> f64 {
        bilinear_lambda_difference(self, q, lambda, h, w, v)
    }
}

/// `∂R/∂λ` by the central difference of [`Branch::residual`] with step `h`
/// (O(h²)).
pub fn residual_lambda_difference<B: Branch + ?Sized>(
    branch: &mut B,
    q: &[f64],
    lambda: f64,
    h: f64,
    out: &mut [f64],
) {
    let mut minus = vec![0.0; out.len()];
    branch.residual(q, lambda + h, out);
    branch.residual(q, lambda - h, &mut minus);
    for (o, b) in out.iter_mut().zip(&minus) {
        *o = (*o - b) / (2.0 * h);
    }
}

/// `∂(wᵀ J v)/∂λ` by the central difference of [`Branch::bilinear`] with
/// step `h` (O(h²)).
pub fn bilinear_lambda_difference<B: Branch + ?Sized>(
    branch: &mut B,
    q: &[f64],
    lambda: f64,
    h: f64,
    w: &[f64],
    v: &[f64],
) -> f64 {
    (branch.bilinear(q, lambda + h, w, v) - branch.bilinear(q, lambda - h, w, v)) / (2.0 * h)
}

/// `wᵀ A v` for a row-major square `A`.
fn bilinear_form(a: &[f64], w: &[f64], v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    a.chunks_exact(v.len())
        .zip(w)
        .map(|(row, wi)| wi * row.iter().zip(v).map(|(x, y)| x * y).sum::<f64>())
        .sum()
}

/// `∂/∂q (wᵀ J v)` by central differences of [`Branch::jacobian`], steps
/// `fd_step·max(|q_k|, ‖q‖∞)`.
pub fn fd_jacobian_gradient<B: Branch>(
    branch: &mut B,
    q: &[f64],
    lambda: f64,
    w: &[f64],
    v: &[f64],
    fd_step: f64,
    out: &mut [f64],
) {
    let m = q.len();
    let mut jac = vec![0.0; m * m];
    let mut qt = q.to_vec();
    let q_scale = q.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let mut wjv = |branch: &mut B, qt: &[f64]| {
        branch.jacobian(qt, lambda, &mut jac);
        bilinear_form(&jac, w, v)
    };
    for (k, (o, &qk)) in out.iter_mut().zip(q).enumerate() {
        let h = fd_step * qk.abs().max(q_scale).max(f64::MIN_POSITIVE);
        let at = |x: f64, qt: &mut Vec<f64>| {
            if let Some(slot) = qt.get_mut(k) {
                *slot = x;
            }
        };
        at(qk + h, &mut qt);
        let plus = wjv(branch, &qt);
        at(qk - h, &mut qt);
        let minus = wjv(branch, &qt);
        at(qk, &mut qt);
        *o = (plus - minus) / (2.0 * h);
    }
}
