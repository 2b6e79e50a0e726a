//! The fold system of a family `family(p)` (Keller; the fold systems of
//! AUTO and MATCONT): `R(q, ω; p) = 0` (Eq. 61), `Φ_q(q, ω; p) v = 0`
//! (Eq. 56), `(vᵀv − 1)/2 = 0` in the path vector `x = [q, v, ω, p]`, with
//! the residual planned anew when `p` changes (the excitation may depend on
//! it).

use super::CurveSystem;
use super::FoldPoint;
use crate::error::HbError;
use crate::orbit::galerkin::GalerkinJacobian;
use crate::orbit::ihb::{HbOptions, HbResidual};
use crate::problem::PeriodicProblem;
use ivt_num::vector::{dot, matvec};
use ivt_path::events::extended::unit_null_vector;
use ivt_path::PathError;

/// The fold system of one family, with the residual planned at the last `p`.
pub(super) struct FoldSystem<'f, F> {
    family: &'f F,
    hb: HbOptions,
    /// `p` the residual and Jacobian scratch were planned for.
    planned: f64,
    res: HbResidual,
    galerkin: GalerkinJacobian,
    jac: Vec<f64>,
    /// Unknowns `m` of `q` (and of `v`).
    pub(super) m: usize,
}

impl<'f, P: PeriodicProblem, F: Fn(f64) -> Result<P, HbError>> FoldSystem<'f, F> {
    pub(super) fn new(family: &'f F, hb: &HbOptions, p: f64) -> Result<Self, HbError> {
        let res = HbResidual::new(&family(p)?, hb)?;
        let m = res.len();
        Ok(Self {
            family,
            hb: hb.clone(),
            planned: p,
            galerkin: GalerkinJacobian::new(&res),
            res,
            jac: vec![0.0; m * m],
            m,
        })
    }

    /// Plans the residual for `p` (the excitation may depend on it); `None`
    /// where the family fails.
    fn plan(&mut self, p: f64) -> Option<P> {
        let problem = (self.family)(p).ok()?;
        if p != self.planned {
            self.res = HbResidual::new(&problem, &self.hb).ok()?;
            self.planned = p;
        }
        Some(problem)
    }

    /// A unit null vector of `Φ_q` at a located fold, by two steps of inverse
    /// iteration.
    pub(super) fn null_vector(
        &mut self,
        q: &[f64],
        omega: f64,
        p: f64,
    ) -> Result<Vec<f64>, HbError> {
        let problem = self
            .plan(p)
            .ok_or_else(|| HbError::InvalidInput("the family fails at p_start".into()))?;
        self.galerkin
            .assemble(&mut self.res, &problem, q, omega, 1.0, &mut self.jac);
        unit_null_vector(&self.jac, self.m)
            .ok_or(HbError::Path(PathError::SingularStart { lambda: p }))
    }
}

impl<P: PeriodicProblem, F: Fn(f64) -> Result<P, HbError>> CurveSystem for FoldSystem<'_, F> {
    type Point = FoldPoint;

    /// `[R; Φ_q v; (vᵀv − 1)/2]` at `x = [q, v, ω, p]`; `None` if the sizes
    /// disagree or `p` cannot be planned.
    fn try_residual(&mut self, x: &[f64], r: &mut [f64]) -> Option<()> {
        let m = self.m;
        let (q, v, omega, p) = split_fold_vector(x, m)?;
        let (r_orbit, r_null, r_norm) = split_fold_residual(r, m)?;
        let problem = self.plan(p)?;
        self.res.eval(&problem, q, omega, 1.0, r_orbit);
        self.galerkin
            .assemble(&mut self.res, &problem, q, omega, 1.0, &mut self.jac);
        null_rows(&self.jac, v, r_null, r_norm);
        Some(())
    }

    /// The fold at `x = [q, v, ω, p]` (`None` if `x` is short).
    fn point(&self, x: &[f64]) -> Option<FoldPoint> {
        let (q, v, omega, p) = split_fold_vector(x, self.m)?;
        Some(FoldPoint {
            omega,
            p,
            coeffs: q.to_vec(),
            null_vector: v.to_vec(),
        })
    }
}

/// The parts `(u, v, a, b)` of the path vector `x = [u, v, a, b]` of a fold
/// system, `u` and its null vector `v` of `m` entries each; `None` if the
/// sizes disagree.
pub(super) fn split_fold_vector(x: &[f64], m: usize) -> Option<(&[f64], &[f64], f64, f64)> {
    let (u, rest) = x.split_at_checked(m)?;
    let (v, &[a, b]) = rest.split_at_checked(m)? else {
        return None;
    };
    Some((u, v, a, b))
}

/// The rows `(r_u, r_null, r_norm)` of the residual `[R; J v; (vᵀv − 1)/2]`
/// of a fold system with `m` unknowns in `u`; `None` if the sizes disagree.
pub(super) fn split_fold_residual(
    r: &mut [f64],
    m: usize,
) -> Option<(&mut [f64], &mut [f64], &mut f64)> {
    let (r_u, rest) = r.split_at_mut_checked(m)?;
    let (r_null, [r_norm]) = rest.split_at_mut_checked(m)? else {
        return None;
    };
    Some((r_u, r_null, r_norm))
}

/// The null-vector rows of a fold system: `J v` (`J` row-major, square in
/// the size of `v`) into `r_null` and the norm `(vᵀv − 1)/2`.
pub(super) fn null_rows(jac: &[f64], v: &[f64], r_null: &mut [f64], r_norm: &mut f64) {
    matvec(jac, v.len(), v.len(), v, r_null);
    *r_norm = 0.5 * (dot(v, v) - 1.0);
}
