//! One-parameter families of periodic problems: the HB residual Eq. 61 as a branch
//! `R(q, λ) = 0` in any parameter λ (the excitation frequency, a stiffness, a
//! parametric amplitude, …), with the exact Galerkin Jacobian Eq. 56.
//!
//! A family maps λ to a problem and its excitation frequency ω_f. The excitation
//! `f(θ)` is projected once (it is part of the planned residual), so it must not
//! depend on λ; [`FamilyBranch::new`] checks this.

use crate::orbit::galerkin::{GalerkinForm, GalerkinJacobian};
use crate::orbit::ihb::{HbError, HbOptions, HbResidual, HbSolution};
use crate::problem::{AtFrequency, PeriodicProblem};
use crate::BroydenStats;
use ivt_path::branch::{bilinear_lambda_difference, residual_lambda_difference, Branch};
use ivt_path::continuation::{
    correct_at_fixed_lambda, BroydenCorrector, ContinuationOptions, Corrector, NewtonCorrector,
    Stepper,
};

/// A one-parameter family of periodic problems.
pub trait Family {
    /// The problem type.
    type Problem: PeriodicProblem;
    /// The problem and its excitation frequency ω_f at parameter λ.
    fn at(&self, lambda: f64) -> (Self::Problem, f64);
    /// `true` when λ is ω_f and the problem does not depend on it
    /// ([`Frequency`]): then `∂R/∂λ` of a velocity-independent `g` is that of
    /// the linear part alone, exact and without a residual evaluation.
    fn is_frequency(&self) -> bool {
        false
    }
}

/// The frequency family of one problem, `λ = ω_f` (frequency-response curves),
/// the problem bound to each ω_f ([`AtFrequency`]: a model whose `g` or `f`
/// reads ω_f is not [`Family::is_frequency`], its `∂R/∂λ` is differenced).
#[derive(Debug, Clone, Copy)]
pub struct Frequency<'a, P>(pub &'a P);

impl<'a, P: PeriodicProblem> Family for Frequency<'a, P> {
    type Problem = AtFrequency<'a, P>;
    fn at(&self, lambda: f64) -> (AtFrequency<'a, P>, f64) {
        (AtFrequency::new(self.0, lambda), lambda)
    }
    fn is_frequency(&self) -> bool {
        !self.0.frequency_dependent()
    }
}

/// Any `Fn(λ) -> (problem, ω_f)` is a family, e.g. `|w| (&duffing, w)` for a
/// frequency sweep or `|b| (MathieuDuffing::thesis(b), 2.0)` for β.
impl<P: PeriodicProblem, F: Fn(f64) -> (P, f64)> Family for F {
    type Problem = P;
    fn at(&self, lambda: f64) -> (P, f64) {
        self(lambda)
    }
}

/// The HB residual of a [`Family`] as a [`Branch`] in λ.
pub struct FamilyBranch<F: Family> {
    family: F,
    hb: HbOptions,
    res: HbResidual,
    galerkin: GalerkinJacobian,
    /// The nonlinear part of `wᵀJv` and its gradient (fold location).
    form: GalerkinForm,
    /// `L v` of [`Branch::bilinear`]; scratch of the frequency family's `∂R/∂λ`.
    lv: Vec<f64>,
    /// `(q, λ)` of the last Galerkin assembly, whose `∂g` samples
    /// [`FamilyBranch::jacobian_samples_at`] hands out.
    galerkin_at: Vec<f64>,
}

impl<F: Family> FamilyBranch<F> {
    /// Plans the residual at `lambda0`.
    ///
    /// # Errors
    /// As [`HbResidual::new`]; [`HbError::InvalidInput`] if the projected
    /// excitation differs between `lambda0` and a nearby λ.
    pub fn new(family: F, hb: &HbOptions, lambda0: f64) -> Result<Self, HbError> {
        if !lambda0.is_finite() {
            return Err(HbError::InvalidInput("λ must be finite".into()));
        }
        let res = HbResidual::new(&family.at(lambda0).0, hb)?;
        let other = HbResidual::new(&family.at(lambda0 + 1e-3 * lambda0.abs().max(1.0)).0, hb)?;
        let scale = res.excitation().iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let moved = res
            .excitation()
            .iter()
            .zip(other.excitation())
            .any(|(a, b)| (a - b).abs() > 1e-14 * scale.max(f64::MIN_POSITIVE));
        if moved {
            return Err(HbError::InvalidInput(
                "the excitation f(θ) of a family must not depend on λ".into(),
            ));
        }
        let galerkin = GalerkinJacobian::new(&res);
        let form = GalerkinForm::new(&res, &family.at(lambda0).0);
        let m = res.len();
        Ok(Self {
            family,
            hb: hb.clone(),
            res,
            galerkin,
            form,
            lv: vec![0.0; m],
            galerkin_at: Vec::with_capacity(m + 1),
        })
    }

    /// The HB options the branch was planned with.
    pub fn options(&self) -> &HbOptions {
        &self.hb
    }

    /// The family.
    pub fn family(&self) -> &F {
        &self.family
    }

    /// The path of the branch from the converged point `start` (`q` then λ) in the
    /// direction of increasing λ if `direction > 0`, with `opts.corrector`:
    /// Broyden on the secant model (Eq. 68–77; `start` is corrected first) or
    /// chord–Newton on the exact Galerkin Jacobian ([`NewtonCorrector`];
    /// `start_iterations` is the start's count).
    ///
    /// Each point is handed out ([`Stepper::next`]) as it is reached, with
    /// Newton after its tangent: where the branch's last Galerkin assembly
    /// is that point's (a point Newton corrected, or every point without
    /// [`ContinuationOptions::second_order_predictor`], whose chord
    /// assembles at the prediction), [`Self::jacobian_samples_at`] gives its
    /// `∂g` samples without another evaluation of `g` (the path points'
    /// stability uses them).
    ///
    /// # Errors
    /// As [`Stepper::new`] and [`correct_at_fixed_lambda`].
    pub fn stepper(
        &mut self,
        start: &[f64],
        start_iterations: usize,
        direction: f64,
        opts: &ContinuationOptions,
    ) -> Result<Stepper<'_, Self>, HbError> {
        let m = self.res.len();
        match opts.corrector {
            Corrector::Broyden => {
                let broyden = Box::new(BroydenCorrector::new(m, &opts.broyden, None));
                Ok(Stepper::new(self, broyden, start, 0, direction, opts)?)
            }
            Corrector::Newton => {
                let mut x = start.to_vec();
                let its = correct_at_fixed_lambda(self, &mut x, opts)?;
                let newton = Box::new(NewtonCorrector::new(m, opts));
                Ok(Stepper::new(
                    self,
                    newton,
                    &x,
                    start_iterations + its,
                    direction,
                    opts,
                )?)
            }
        }
    }

    /// `[∂g/∂x | ∂g/∂v]` at the 2N AFT samples of the orbit `x` (`q` then λ)
    /// when the branch's last Galerkin assembly was at exactly `x` (layout of
    /// [`PeriodicProblem::nonlinear_jacobian_samples`]); `None` otherwise.
    pub fn jacobian_samples_at(&self, x: &[f64]) -> Option<&[f64]> {
        (self.galerkin_at == x).then(|| self.galerkin.samples())
    }

    /// Whether λ moves only the linear part `L(ω)` of the residual: λ is ω_f
    /// ([`Family::is_frequency`]) and `g` does not depend on the velocity.
    fn only_linear_part_moves(&self) -> bool {
        self.family.is_frequency() && !self.res.velocity_dependent()
    }

    /// `∂(L(λ/p) u)/∂λ` into `out`: for R = L(ω_f/p) q + G(q) − F with G
    /// independent of ω_f, `∂R/∂λ` at `u = q` and `(∂J/∂λ) v` at `u = v`. L(ω)u
    /// is quadratic in ω, so its central difference is exact (step ω_f/2: no
    /// cancellation), and `g` is not evaluated.
    fn linear_lambda_derivative(&mut self, u: &[f64], lambda: f64, out: &mut [f64]) {
        let (problem, _) = self.family.at(lambda);
        let p = self.res.subharmonic() as f64;
        let h = 0.5 * lambda.abs().max(f64::MIN_POSITIVE.sqrt());
        let minus = &mut self.lv;
        self.res.apply_linear(&problem, u, (lambda - h) / p, minus);
        self.res.apply_linear(&problem, u, (lambda + h) / p, out);
        for (a, b) in out.iter_mut().zip(minus.iter()) {
            *a = (*a - b) / (2.0 * h);
        }
    }

    /// The problem at λ and the orbit `q` as an [`HbSolution`] of it.
    pub fn solution(&self, q: &[f64], lambda: f64) -> (F::Problem, HbSolution) {
        let (problem, omega_f) = self.family.at(lambda);
        let sol = HbSolution {
            coeffs: q.to_vec(),
            omega_f,
            harmonics: self.hb.harmonics,
            subharmonic: self.hb.subharmonic,
            stats: BroydenStats::default(),
        };
        (problem, sol)
    }
}

impl<F: Family> Branch for FamilyBranch<F> {
    fn len(&self) -> usize {
        self.res.len()
    }
    fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]) {
        let (problem, omega_f) = self.family.at(lambda);
        self.res.eval(&problem, q, omega_f, 1.0, r);
    }
    fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]) {
        let (problem, omega_f) = self.family.at(lambda);
        self.galerkin
            .assemble(&mut self.res, &problem, q, omega_f, 1.0, jac);
        self.galerkin_at.clear();
        self.galerkin_at.extend_from_slice(q);
        self.galerkin_at.push(lambda);
    }
    /// `wᵀL v` exactly plus the sum of the nonlinear part over the AFT grid
    /// (`GalerkinForm`): no `J` is assembled.
    fn bilinear(&mut self, q: &[f64], lambda: f64, w: &[f64], v: &[f64]) -> f64 {
        let (problem, omega_f) = self.family.at(lambda);
        let omega = omega_f / self.res.subharmonic() as f64;
        self.res.apply_linear(&problem, v, omega, &mut self.lv);
        let linear: f64 = w.iter().zip(&self.lv).map(|(a, b)| a * b).sum();
        linear + self.form.value(&problem, q, omega_f, w, v, None)
    }
    /// `L` does not depend on `q`: the gradient is that of the nonlinear part
    /// (O(2N·m), where differencing assembled Jacobians costs 2m assemblies).
    fn jacobian_gradient(&mut self, q: &[f64], lambda: f64, w: &[f64], v: &[f64], out: &mut [f64]) {
        let (problem, omega_f) = self.family.at(lambda);
        self.form.value(&problem, q, omega_f, w, v, Some(out));
    }
    /// Exact and without evaluating `g` where only `L` depends on λ
    /// (`linear_lambda_derivative`), else the central difference.
    fn residual_lambda(&mut self, q: &[f64], lambda: f64, h: f64, out: &mut [f64]) {
        if self.only_linear_part_moves() {
            self.linear_lambda_derivative(q, lambda, out);
        } else {
            residual_lambda_difference(self, q, lambda, h, out);
        }
    }
    /// `wᵀ (∂L/∂λ) v` where only `L` depends on λ, else the central difference.
    fn bilinear_lambda(&mut self, q: &[f64], lambda: f64, h: f64, w: &[f64], v: &[f64]) -> f64 {
        if self.only_linear_part_moves() {
            let mut lv = vec![0.0; v.len()];
            self.linear_lambda_derivative(v, lambda, &mut lv);
            w.iter().zip(&lv).map(|(a, b)| a * b).sum()
        } else {
            bilinear_lambda_difference(self, q, lambda, h, w, v)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::{Duffing, MathieuDuffing};
    use ivt_path::branch::path_lambda_step;

    /// `∂R/∂λ` by a central difference of the whole residual, step `h`.
    fn central<F: Family>(
        branch: &mut FamilyBranch<F>,
        q: &[f64],
        lambda: f64,
        h: f64,
    ) -> Vec<f64> {
        let m = q.len();
        let (mut plus, mut minus) = (vec![0.0; m], vec![0.0; m]);
        Branch::residual(branch, q, lambda + h, &mut plus);
        Branch::residual(branch, q, lambda - h, &mut minus);
        plus.iter()
            .zip(&minus)
            .map(|(a, b)| (a - b) / (2.0 * h))
            .collect()
    }

    /// `∂R/∂λ` of `branch` at `(q, λ)` (the path's step) against
    /// [`central`] with `h` = 1e-4: the column, max |Δ| and max |difference|.
    fn against_central<F: Family>(
        branch: &mut FamilyBranch<F>,
        q: &[f64],
        lambda: f64,
    ) -> (Vec<f64>, f64, f64) {
        let mut exact = vec![0.0; q.len()];
        Branch::residual_lambda(branch, q, lambda, path_lambda_step(lambda), &mut exact);
        let fd = central(branch, q, lambda, 1e-4);
        let scale = fd.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let err = exact
            .iter()
            .zip(&fd)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        (exact, err, scale)
    }

    #[test]
    fn frequency_family_derivative_is_the_linear_parts_exactly() {
        // Duffing at ω_f = 1.3 (p = 1) and with p = 3 (the derivative carries
        // 1/p): a central difference of the whole residual with h = 1e-4 errs
        // by O(h²)·|R'''| ≈ 1e-8 relative, the closed form not at all.
        for p in [1, 3] {
            let duffing = Duffing::fig28();
            assert!(!duffing.velocity_dependent(), "the closed-form path");
            let hb = HbOptions::new(7, 32).with_subharmonic(p);
            let mut branch = FamilyBranch::new(Frequency(&duffing), &hb, 1.3).unwrap();
            let m = branch.len();
            let q: Vec<f64> = (0..m).map(|i| 0.3 / (1.0 + i as f64)).collect();
            let (exact, err, scale) = against_central(&mut branch, &q, 1.3);
            assert!(err <= 1e-8 * scale, "p = {p}: {err:e} of {scale:e}");
            // The fold system's λ entries take the same path: the residual's
            // column, and ∂(wᵀJv)/∂λ against the difference of the whole form.
            let mut column = vec![0.0; m];
            Branch::residual_lambda(&mut branch, &q, 1.3, 1e-4, &mut column);
            assert_eq!(column, exact);
            let w: Vec<f64> = (0..m).map(|i| (0.7 * i as f64).sin()).collect();
            let v: Vec<f64> = (0..m).map(|i| (0.3 * i as f64).cos()).collect();
            let form = Branch::bilinear_lambda(&mut branch, &q, 1.3, 1e-4, &w, &v);
            let fd = bilinear_lambda_difference(&mut branch, &q, 1.3, 1e-4, &w, &v);
            assert!(
                (form - fd).abs() <= 1e-8 * fd.abs(),
                "p = {p}: {form} vs {fd}"
            );
        }
    }

    #[test]
    fn other_families_keep_the_residual_difference() {
        // λ = β of Mathieu–Duffing moves the stiffness, not ω_f: the central
        // difference of the residual with the path's step is used.
        let mut branch = FamilyBranch::new(
            |b: f64| (MathieuDuffing::thesis(b), 2.0),
            &HbOptions::new(7, 32),
            4.0,
        )
        .unwrap();
        let m = branch.len();
        let q: Vec<f64> = (0..m).map(|i| 0.3 / (1.0 + i as f64)).collect();
        let (_, err, scale) = against_central(&mut branch, &q, 4.0);
        assert!(scale > 0.0);
        assert!(err <= 1e-6 * scale, "{err:e} of {scale:e}");
    }
}
