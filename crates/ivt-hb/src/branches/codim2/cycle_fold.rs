//! Folds of limit cycles of an autonomous family in two parameters (issue
//! 27, item 1): how a fold of the cycle branch of [`crate::cycle_branch()`]
//! (a turning point in μ) moves with a second parameter ν of a family
//! `family(μ, ν)`.
//!
//! A limit cycle solves the HB residual `R(q, ω; μ, ν) = 0` (Eq. 61) with ω
//! unknown and the phase condition `b₁ = 0` (the cycle equations of
//! [`crate::cycle_branch()`]); with `u = {q, ω}` its Jacobian is the bordered
//! matrix `J = [[Φ_q, ∂R/∂ω], [e_{b₁}ᵀ, 0]]` (Φ_q: Eq. 56). A fold of cycles
//! in μ is a point where `J` is singular, so the extended system (Keller;
//! the fold systems of AUTO and MATCONT, as [`super::fold_curve`] uses for
//! forced folds)
//!
//! `R = 0`,  `b₁ = 0`,  `J v = 0`,  `(vᵀv − 1)/2 = 0`
//!
//! in the path vector `x = [q, ω, v, μ, ν]` has one equation fewer than
//! unknowns and is followed by the engine's pseudo-arclength continuation
//! ([`ivt_path::continuation::Stepper`], Eq. 68–77) with ν as the path
//! parameter, μ solved along. A cusp of cycle folds (two folds merging) is a
//! turning point of this curve in ν, located as the engine's fold of the
//! extended system; the fold at each requested ν is the crossing of that
//! value (both as the points arrive, as for [`super::fold_curve`]).
//!
//! Other codimension-two points are not detected: a Bautin (generalised
//! Hopf) point, where the fold curve meets the Hopf curve at zero amplitude,
//! shows as the amplitude of the coefficients tending to zero near
//! the end of the curve; the path stops before it (the HB cycle degenerates).

use std::cell::Cell;

use super::fold_system::{null_rows, split_fold_residual, split_fold_vector};
use super::{bounded, crossings, follow_leg, path_interval, Curve, CurveSystem, FoldPoint, Legs};
use crate::branches::cycle_branch::member::Member;
use crate::branches::cycle_branch::CycleSystem;
use crate::branches::events::name_family_failures;
use crate::error::HbError;
use crate::orbit::ihb::{HbOptions, HbSolution};
use crate::problem::PeriodicProblem;
use ivt_num::vector::norm2;
use ivt_path::branch::Branch;
use ivt_path::continuation::ContinuationOptions;
use ivt_path::events::extended::unit_null_vector;
use ivt_path::PathError;

/// One fold of limit cycles on the curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleFoldPoint {
    /// The first parameter at the fold (solved along).
    pub mu: f64,
    /// The fold with `p` = ν (the path parameter), ω the cycle's angular
    /// frequency, its coefficients (phase `b₁ = 0`) and the unit null vector
    /// of the bordered Jacobian in `(q, ω)`.
    pub fold: FoldPoint,
}

/// A curve of folds of limit cycles in (μ, ν); its cusps are turning points
/// in ν.
pub type CycleFoldCurve = Curve<CycleFoldPoint>;

/// Follows the fold of limit cycles of `family(μ, ν)` (autonomous: no
/// excitation) at `start` (a located fold of [`crate::cycle_branch()`] at
/// `(mu, nu_start)`: its coefficients with phase `b₁ = 0` and ω) in ν,
/// first towards `nu_from` of `(nu_from, nu_to)` until ν leaves the
/// interval between them, then from the start towards `nu_to` (`Legs`);
/// the folds at each ν of `at` and the cusps are located (module docs).
///
/// # Errors
/// [`HbError::InvalidInput`] for sizes or bounds (`nu_start` must lie in the
/// interval); `family(mu, nu_start)`'s error; [`PathError::SingularStart`]
/// if no null vector is found at the start; the start's failures as
/// [`follow_residual`](ivt_path::continuation::follow_residual)'s. Later, a (μ, ν) where `family` fails is a failed step,
/// and an `at` point or cusp whose location fails is reported in
/// [`Curve::unlocated`] with the reason (the curve is kept).
pub fn cycle_fold_curve<P, F>(
    family: F,
    hb: &HbOptions,
    start: &HbSolution,
    (mu, nu_start): (f64, f64),
    (nu_from, nu_to): (f64, f64),
    at: &[f64],
    opts: &ContinuationOptions,
) -> Result<CycleFoldCurve, HbError>
where
    P: PeriodicProblem,
    F: Fn(f64, f64) -> Result<P, HbError>,
{
    let omega = start.omega_f;
    let (lo, hi) = path_interval("cycle fold curve", omega, nu_start, nu_from, nu_to)?;
    if !mu.is_finite() {
        return Err(HbError::InvalidInput(
            "cycle fold curve: μ must be finite".into(),
        ));
    }
    let n_dof = family(mu, nu_start)?.n_dof();
    let nu = Cell::new(nu_start);
    let member = |m: f64| Member::new(family(m, nu.get()), n_dof, m, None);
    let mut sys = CycleFoldSystem::new(CycleSystem::new(&member, hb, mu)?, &nu);
    let m1 = sys.m1;
    if start.coeffs.len() + 1 != m1 {
        return Err(HbError::InvalidInput(format!(
            "the start fold must have {} coefficients",
            m1.saturating_sub(1)
        )));
    }
    let mut u0 = start.coeffs.clone();
    u0.push(omega);
    let v0 = sys.null_vector(&u0, mu)?;
    let mut x0 = u0;
    x0.extend_from_slice(&v0);
    x0.extend([mu, nu_start]);
    let copts = bounded(opts, (lo, hi));
    let watch = crossings(x0.len() - 1, at, norm2(&start.coeffs));
    let legs = Legs::follow((nu_start, nu_from, nu_to), |direction| {
        let residual = |x: &[f64], r: &mut [f64]| sys.residual(x, r);
        follow_leg(residual, &x0, direction, &copts, (&watch, true), |_| true)
    })?;
    let mut curve = legs.joined().curve(&watch, |x| sys.point(x));
    name_family_failures(&mut curve.unlocated, |nu, near| family(near.mu, nu).err());
    Ok(curve)
}

/// The extended system of a cycle fold: the cycle equations of
/// [`CycleSystem`] in `u = {q, ω}` at μ, with ν set through the shared cell
/// the family reads, and the null vector of their Jacobian.
struct CycleFoldSystem<'f, 'c, F> {
    cycle: CycleSystem<'f, F>,
    nu: &'c Cell<f64>,
    /// The bordered Jacobian `J` (row-major, `m1 × m1`).
    jac: Vec<f64>,
    /// Unknowns `m1 = m + 1` of `u` (and of `v`).
    m1: usize,
}

impl<'f, 'c, P: PeriodicProblem, F: Fn(f64) -> Member<'static, P>> CycleFoldSystem<'f, 'c, F> {
    fn new(cycle: CycleSystem<'f, F>, nu: &'c Cell<f64>) -> Self {
        let m1 = cycle.len();
        Self {
            cycle,
            nu,
            jac: vec![0.0; m1 * m1],
            m1,
        }
    }

    /// A unit null vector of `J` at a located fold `u` at μ (ν as set), by
    /// two steps of inverse iteration.
    fn null_vector(&mut self, u: &[f64], mu: f64) -> Result<Vec<f64>, HbError> {
        self.cycle.jacobian(u, mu, &mut self.jac);
        unit_null_vector(&self.jac, self.m1)
            .ok_or(HbError::Path(PathError::SingularStart { lambda: mu }))
    }
}

impl<P: PeriodicProblem, F: Fn(f64) -> Member<'static, P>> CurveSystem
    for CycleFoldSystem<'_, '_, F>
{
    type Point = CycleFoldPoint;

    /// `[R; b₁; J v; (vᵀv − 1)/2]` at `x = [u, v, μ, ν]`; `None` if the
    /// sizes disagree.
    fn try_residual(&mut self, x: &[f64], r: &mut [f64]) -> Option<()> {
        let (u, v, mu, nu) = split_fold_vector(x, self.m1)?;
        let (r_cycle, r_null, r_norm) = split_fold_residual(r, self.m1)?;
        self.nu.set(nu);
        self.cycle.residual(u, mu, r_cycle);
        self.cycle.jacobian(u, mu, &mut self.jac);
        null_rows(&self.jac, v, r_null, r_norm);
        Some(())
    }

    /// The fold at `x = [u, v, μ, ν]` (`None` if `x` is short).
    fn point(&self, x: &[f64]) -> Option<CycleFoldPoint> {
        let (u, v, mu, nu) = split_fold_vector(x, self.m1)?;
        let (&omega, q) = u.split_last()?;
        let fold = FoldPoint {
            omega,
            p: nu,
            coeffs: q.to_vec(),
            null_vector: v.to_vec(),
        };
        Some(CycleFoldPoint { mu, fold })
    }
}
