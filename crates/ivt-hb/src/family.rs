//! One-parameter families of periodic problems: the HB residual Eq. 61 as a branch
//! `R(q, λ) = 0` in any parameter λ (the excitation frequency, a stiffness, a
//! parametric amplitude, …), with the exact Galerkin Jacobian Eq. 56.
//!
//! A family maps λ to a problem and its excitation frequency ω_f. The excitation
//! `f(θ)` is projected once (it is part of the planned residual), so it must not
//! depend on λ; [`FamilyBranch::new`] checks this.

use crate::fold::Branch;
use crate::ihb::{GalerkinJacobian, HbError, HbOptions, HbResidual, HbSolution};
use crate::problem::PeriodicProblem;
use crate::BroydenStats;

/// A one-parameter family of periodic problems.
pub trait Family {
    /// The problem type.
    type Problem: PeriodicProblem;
    /// The problem and its excitation frequency ω_f at parameter λ.
    fn at(&self, lambda: f64) -> (Self::Problem, f64);
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
        Ok(Self {
            family,
            hb: hb.clone(),
            res,
            galerkin,
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

    /// The problem at λ and the orbit `q` as an [`HbSolution`] of it.
    pub fn solution(&self, q: &[f64], lambda: f64) -> (F::Problem, HbSolution) {
        let (problem, omega_f) = self.family.at(lambda);
        let sol = HbSolution {
            coeffs: q.to_vec(),
            omega_f,
            harmonics: self.hb.harmonics,
            subharmonic: self.hb.subharmonic,
            stats: BroydenStats {
                iterations: 0,
                residual_evals: 0,
                jacobian_refreshes: 0,
                residual_norm: 0.0,
            },
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
    }
}
