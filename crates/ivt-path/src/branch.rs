//! The one abstraction of a solution branch `R(q, λ) = 0`, `R: R^m × R → R^m`
//! (thesis §3.2.3, Eq. 68–77: the HB residual Eq. 61 in a parameter λ).
//!
//! Everything that follows or locates something on a branch reads it
//! through [`Branch`]: the continuation stepper (the residual, the Jacobian
//! `∂R/∂q` into the caller's row-major matrix and `∂R/∂λ`, for the tangent
//! and the Newton and chord correctors of Eq. 72), the fold and bifurcation
//! locators (the bilinear form `wᵀJv` and its derivatives), branch switching
//! and the Broyden corrector (through its adapter,
//! [`crate::continuation`]'s `corrector/broyden.rs`). `∂R/∂λ` and the
//! λ-derivative of `wᵀJv` have one default difference policy, the central
//! difference with the caller's step ([`residual_lambda_difference`],
//! [`bilinear_lambda_difference`]); a branch that knows them exactly (the
//! frequency family, the STHB string) overrides them.

use ivt_num::NewtonOptions;

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
    /// `∂R/∂q` at `(q, λ)`, row-major `m×m`, into `jac` (overwritten).
    fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]);
    /// `R(q, λ)` into `r` and `∂R/∂q` into `jac` (row-major `m×m`): the
    /// Newton corrector's evaluation. Default: [`Self::residual`] then
    /// [`Self::jacobian`]; a branch whose assembly yields `R` on the way
    /// (the STHB string's linearization) overrides it.
    fn residual_jacobian(&mut self, q: &[f64], lambda: f64, r: &mut [f64], jac: &mut [f64]) {
        self.residual(q, lambda, r);
        self.jacobian(q, lambda, jac);
    }
    /// `wᵀ J(q, λ) v`. Default: from an assembled [`Self::jacobian`].
    fn bilinear(&mut self, q: &[f64], lambda: f64, w: &[f64], v: &[f64]) -> f64 {
        let m = q.len();
        let mut jac = vec![0.0; m * m];
        self.jacobian(q, lambda, &mut jac);
        bilinear_form(&jac, w, v)
    }
    /// `∂/∂q (wᵀ J(q, λ) v)` into `out` (`m`): the gradient of the fold test
    /// function is `−` this at the bordered solutions `v`, `w`. Default:
    /// [`directional_jacobian_gradient`] (2 Jacobians); override with an
    /// exact form.
    fn jacobian_gradient(&mut self, q: &[f64], lambda: f64, w: &[f64], v: &[f64], out: &mut [f64])
    where
        Self: Sized,
    {
        directional_jacobian_gradient(self, q, lambda, w, v, 1e-6, out);
    }
    /// `∂R/∂λ` at `(q, λ)` into `out` (`m`): the λ column of the tangent, of
    /// the correctors' bordered matrix (Eq. 72) and of the fold system.
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

/// The options of [`ivt_num::newton()`] for a correction on a branch from a
/// close start (a converged orbit of another method, a point next to an
/// event, a step off a bifurcation): every step in full (no halving, no
/// descent test), at most `max_iter`, converged at `‖R‖ ≤ ftol`.
pub fn full_newton_steps(ftol: f64, max_iter: usize) -> NewtonOptions {
    NewtonOptions {
        ftol,
        max_iter,
        max_halvings: 0,
        accept_no_descent: true,
        ..NewtonOptions::default()
    }
}

/// The step in λ of the path's `∂R/∂λ` ([`Branch::residual_lambda`] in the
/// tangent and the correctors): `1e-7·max(|λ|, 1)`.
pub fn path_lambda_step(lambda: f64) -> f64 {
    1e-7 * lambda.abs().max(1.0)
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
pub fn bilinear_form(a: &[f64], w: &[f64], v: &[f64]) -> f64 {
    a.chunks_exact(v.len().max(1))
        .zip(w)
        .map(|(row, wi)| wi * row.iter().zip(v).map(|(x, y)| x * y).sum::<f64>())
        .sum()
}

/// `∂/∂q (wᵀ J v)` as the derivative of `J(q + εv)ᵀ w` in ε (the second
/// derivatives of `R` are symmetric: `∂_k Σᵢⱼ wᵢ ∂ⱼRᵢ vⱼ = Σᵢ wᵢ ∂_ε ∂_kRᵢ(q + εv)`),
/// by the central difference of two [`Branch::jacobian`]s with
/// `ε = fd_step·max(‖q‖∞, ‖v‖∞)/‖v‖∞`: the cost of two Jacobians where
/// [`fd_jacobian_gradient`] takes `2m`. Zero for `v = 0`.
pub fn directional_jacobian_gradient<B: Branch>(
    branch: &mut B,
    q: &[f64],
    lambda: f64,
    w: &[f64],
    v: &[f64],
    fd_step: f64,
    out: &mut [f64],
) {
    let m = q.len();
    let inf = |x: &[f64]| x.iter().fold(0.0f64, |a, e| a.max(e.abs()));
    let v_scale = inf(v);
    out.fill(0.0);
    if v_scale == 0.0 || !v_scale.is_finite() {
        return;
    }
    let eps = fd_step * inf(q).max(v_scale) / v_scale;
    let mut jac = vec![0.0; m * m];
    let mut qt: Vec<f64> = q.to_vec();
    for (sign, weight) in [(1.0, 0.5 / eps), (-1.0, -0.5 / eps)] {
        for ((t, &qk), &vk) in qt.iter_mut().zip(q).zip(v) {
            *t = qk + sign * eps * vk;
        }
        branch.jacobian(&qt, lambda, &mut jac);
        // out += weight · Jᵀ w.
        for (row, &wi) in jac.chunks_exact(m.max(1)).zip(w) {
            for (o, &a) in out.iter_mut().zip(row) {
                *o += weight * wi * a;
            }
        }
    }
}

/// `∂/∂q (wᵀ J v)` by central differences of [`Branch::jacobian`], steps
/// `fd_step·max(|q_k|, ‖q‖∞)`: `2m` Jacobians, the reference the exact and
/// the directional forms are checked against.
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
        set_entry(&mut qt, k, qk + h);
        let plus = wjv(branch, &qt);
        set_entry(&mut qt, k, qk - h);
        let minus = wjv(branch, &qt);
        set_entry(&mut qt, k, qk);
        *o = (plus - minus) / (2.0 * h);
    }
}

/// `x[k] = value` (nothing for `k` out of range).
fn set_entry(x: &mut [f64], k: usize, value: f64) {
    if let Some(e) = x.get_mut(k) {
        *e = value;
    }
}

/// A branch given by its residual alone, `residual(x, r)` over `x = (u, λ)`
/// (`m + 1` entries): the form of a system the Broyden corrector follows
/// without a Jacobian (a subproblem assembled by the caller). Its
/// [`Branch::jacobian`] is the forward difference of the residual.
pub struct ResidualBranch<F> {
    residual: F,
    x: Vec<f64>,
    r0: Vec<f64>,
    r1: Vec<f64>,
}

impl<F: FnMut(&[f64], &mut [f64])> ResidualBranch<F> {
    /// The branch of `m` unknowns with the residual `residual`.
    pub fn new(m: usize, residual: F) -> Self {
        Self {
            residual,
            x: vec![0.0; m + 1],
            r0: vec![0.0; m],
            r1: vec![0.0; m],
        }
    }

    /// `(q, λ)` into the scratch point.
    fn load(&mut self, q: &[f64], lambda: f64) {
        if let Some((last, u)) = self.x.split_last_mut() {
            u.copy_from_slice(q);
            *last = lambda;
        }
    }
}

impl<F: FnMut(&[f64], &mut [f64])> Branch for ResidualBranch<F> {
    fn len(&self) -> usize {
        self.r0.len()
    }
    fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]) {
        self.load(q, lambda);
        (self.residual)(&self.x, r);
    }
    /// Forward differences of step `1e-7·max(|q_j|, 1)`.
    fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]) {
        let m = q.len();
        self.load(q, lambda);
        (self.residual)(&self.x, &mut self.r0);
        for (j, &qj) in q.iter().enumerate() {
            let h = 1e-7 * qj.abs().max(1.0);
            set_entry(&mut self.x, j, qj + h);
            (self.residual)(&self.x, &mut self.r1);
            set_entry(&mut self.x, j, qj);
            for (row, (a, b)) in jac
                .chunks_exact_mut(m.max(1))
                .zip(self.r1.iter().zip(&self.r0))
            {
                set_entry(row, j, (a - b) / h);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `R = (q₀²q₁ − λ, sin q₁ + q₀q₂, q₂³ + λq₀)` with its Jacobian.
    struct Cubic;

    impl Branch for Cubic {
        fn len(&self) -> usize {
            3
        }
        fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]) {
            r.copy_from_slice(&[
                q[0] * q[0] * q[1] - lambda,
                q[1].sin() + q[0] * q[2],
                q[2].powi(3) + lambda * q[0],
            ]);
        }
        fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]) {
            jac.copy_from_slice(&[
                2.0 * q[0] * q[1],
                q[0] * q[0],
                0.0,
                q[2],
                q[1].cos(),
                q[0],
                lambda,
                0.0,
                3.0 * q[2] * q[2],
            ]);
        }
    }

    #[test]
    fn the_directional_gradient_of_the_bilinear_form_is_the_exact_one() {
        let (q, lambda): ([f64; 3], f64) = ([0.7, -1.3, 0.4], 0.9);
        let (w, v) = ([0.3, -0.8, 0.5], [1.1, 0.2, -0.6]);
        // ∂/∂q (wᵀ J v) by hand from the Jacobian above.
        let exact = [
            w[0] * (2.0 * q[1] * v[0] + 2.0 * q[0] * v[1]) + w[1] * v[2],
            w[0] * 2.0 * q[0] * v[0] - w[1] * q[1].sin() * v[1],
            w[1] * v[0] + w[2] * 6.0 * q[2] * v[2],
        ];
        let (mut directional, mut reference) = ([0.0; 3], [0.0; 3]);
        directional_jacobian_gradient(&mut Cubic, &q, lambda, &w, &v, 1e-5, &mut directional);
        fd_jacobian_gradient(&mut Cubic, &q, lambda, &w, &v, 1e-5, &mut reference);
        for ((d, r), e) in directional.iter().zip(&reference).zip(&exact) {
            assert!(
                (d - e).abs() < 1e-8 && (r - e).abs() < 1e-8,
                "{directional:?} {reference:?} {exact:?}"
            );
        }
        // v = 0: zero, not NaN.
        directional_jacobian_gradient(
            &mut Cubic,
            &q,
            lambda,
            &w,
            &[0.0; 3],
            1e-5,
            &mut directional,
        );
        assert_eq!(directional, [0.0; 3]);
    }
}
