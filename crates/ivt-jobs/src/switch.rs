//! Branch switching (issue 27 item 2): from a period doubling or a branch
//! point of a frequency-response curve onto the new branch, continued in ω_f
//! with its own events as [`super::frc()`] traces the first one.
//!
//! - **Period doubling**: the orbit is re-expressed with period 2T and the
//!   odd-harmonic null vector of the period-2 Galerkin Jacobian (Eq. 56) is the
//!   new direction ([`ivt_hb::period_doubled_start`]); the new branch's
//!   coefficients have `2n` harmonics of the response frequency ω_f/2.
//! - **Branch point**: the new direction is a root of the algebraic
//!   bifurcation equation `ψᵀ R''[d, d] = 0` on the null space
//!   `span{v₁, v₂}` of `[∂R/∂q, ∂R/∂ω_f]` (ψ its left null vector, `R''` by a
//!   central second difference of Eq. 61). Of its two roots (the two branches
//!   through the point) the one nearer ω_f = const is taken: the
//!   symmetry-breaking branch of a pitchfork, the branch point of a forced
//!   curve (the traced, symmetric branch crosses ω_f transversally). An event
//!   carries no tangent of the traced branch, so at a transcritical point,
//!   where both branches cross ω_f, this may be the traced one.
//!
//! [`ivt_hb::switch_branch`] corrects the first point at a distance
//! `step · ‖q‖₂` from the bifurcation; the path then runs towards `to`, which
//! must lie on the side where the new branch leaves.

use super::frc::{trace_error, traced_curve};
use super::{finite, FoldPoint, FrcCurve, FrcRequest};
use ivt_hb::branches::events::{dot, Bifurcation, BifurcationKind, LocateOptions};
use ivt_hb::branches::family::{Family, FamilyBranch, Frequency};
use ivt_hb::branches::frc::FrcOptions;
use ivt_hb::branches::switching::{period_doubled_start, switch_branch};
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::HbError;
use ivt_num::vector::norm2;
use ivt_num::BorderedLu;
use ivt_path::branch::Branch;
use ivt_path::continuation::{Corrector, Steps};
use ivt_path::events::extended::{augmented_null_vectors, jacobian_blocks};
use serde::Serialize;
use std::time::Instant;

/// Where the switch happens.
#[derive(Debug, Clone, PartialEq)]
pub enum SwitchStart {
    /// A located period doubling or branch point of `frc(..., events=True)`
    /// (with the same harmonics and samples) by its ω_f and coefficients.
    Given {
        /// [`BifurcationKind::PeriodDoubling`] or [`BifurcationKind::BranchPoint`].
        kind: BifurcationKind,
        /// ω_f there.
        omega: f64,
        /// The orbit there.
        coeffs: Vec<f64>,
    },
    /// The first located period doubling or branch point of this FRC (its
    /// `events` taken as true).
    Search(FrcRequest),
}

/// The bifurcation, the end of the new branch and the path's corrector.
#[derive(Debug, Clone, PartialEq)]
pub struct SwitchRequest {
    /// The bifurcation switched at.
    pub start: SwitchStart,
    /// The new branch is continued from the bifurcation to this ω_f.
    pub to: f64,
    /// Distance of the new branch's first point from the bifurcation,
    /// relative to ‖q‖₂ there (along the new direction).
    pub step: f64,
    /// Corrector of the path.
    pub corrector: Corrector,
    /// The new branch's steps and most points (by default the FRC's:
    /// [`FrcOptions::default`]).
    pub steps: Steps,
}

impl Default for SwitchRequest {
    /// The first event on ω_f ∈ [0.5, 3.0], the new branch to ω_f = 2.0, a
    /// first step of 5 % of the orbit, the Newton–chord corrector.
    fn default() -> Self {
        Self {
            start: SwitchStart::Search(FrcRequest {
                options: FrcOptions {
                    from: 0.5,
                    to: 3.0,
                    ..FrcOptions::default()
                },
                ..FrcRequest::default()
            }),
            to: 2.0,
            step: 0.05,
            corrector: Corrector::Newton,
            steps: Steps::default(),
        }
    }
}

impl SwitchRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for a kind other than period doubling or
    /// branch point, a non-finite or non-positive frequency, `to` equal to the
    /// event's ω_f, non-finite coefficients or `step` outside (0, 1].
    pub fn validate(&self) -> Result<(), HbError> {
        let to = finite("to", self.to)?;
        let step = finite("step", self.step)?;
        if !(step > 0.0 && step <= 1.0) {
            return Err(HbError::InvalidInput(format!(
                "`step` = {step:?} must be in (0, 1]"
            )));
        }
        match &self.start {
            SwitchStart::Given {
                kind,
                omega,
                coeffs,
            } => {
                switchable(*kind)?;
                let omega = finite("omega", *omega)?;
                if !(omega > 0.0 && to > 0.0 && omega != to) {
                    return Err(HbError::InvalidInput(format!(
                        "the event's ω_f = {omega:?} and `to` = {to:?} must be > 0 and distinct"
                    )));
                }
                if coeffs.iter().any(|c| !c.is_finite()) {
                    return Err(HbError::InvalidInput(
                        "the event's coefficients must be finite".into(),
                    ));
                }
                Ok(())
            }
            SwitchStart::Search(frc) => frc.validate(),
        }
    }
}

/// `Ok` for the kinds a branch can be switched at; otherwise the error names
/// the kind.
fn switchable(kind: BifurcationKind) -> Result<(), HbError> {
    match kind {
        BifurcationKind::PeriodDoubling | BifurcationKind::BranchPoint => Ok(()),
        other => Err(HbError::InvalidInput(format!(
            "cannot switch branches at a {}: only at a period doubling or a branch point",
            other.words()
        ))),
    }
}

/// The new branch: the keys of [`FrcCurve`] (its points, events, termination)
/// and where it starts.
#[derive(Debug, Clone, Serialize)]
pub struct SwitchedBranch {
    /// The bifurcation switched at.
    pub kind: BifurcationKind,
    /// Its ω_f.
    pub start_omega: f64,
    /// Harmonics of the new branch's coefficients (2n after a period
    /// doubling).
    pub harmonics: usize,
    /// Response period over excitation period of the new branch (2 after a
    /// period doubling): harmonic k of `coeffs` has frequency k ω_f / this.
    pub subharmonic: usize,
    /// The new branch from its first point towards `to`.
    #[serde(flatten)]
    pub curve: FrcCurve<FoldPoint>,
}

/// Switch at `req.start` onto the new branch of `problem`'s frequency
/// response and continue it to `req.to`.
///
/// # Errors
/// [`SwitchRequest::validate`]'s; an input error when a searched FRC has no
/// located period doubling or branch point, when the new branch leaves the
/// bifurcation on the side away from `to`, or (branch point) when the
/// bifurcation equation has no two real roots; the corrector's and the
/// path's failures.
pub fn switch(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    req: &SwitchRequest,
) -> Result<SwitchedBranch, HbError> {
    let problem = &problem;
    req.validate()?;
    let t0 = Instant::now();
    let (kind, omega, coeffs) = match &req.start {
        SwitchStart::Given {
            kind,
            omega,
            coeffs,
        } => (*kind, *omega, coeffs.clone()),
        SwitchStart::Search(frc) => first_event(problem, hb, frc)?,
    };
    let family = Frequency(problem);
    let opts = LocateOptions::default();
    let h = req.step * norm2(&coeffs).max(f64::MIN_POSITIVE);
    let (mut branch, q1, w1) = if kind == BifurcationKind::PeriodDoubling {
        let pd = Bifurcation {
            kind,
            q: coeffs,
            lambda: omega,
            multipliers: Vec::new(),
            null_vectors: Vec::new(),
            iterations: 0,
            residual_norm: 0.0,
        };
        let (branch, q1, w1) =
            period_doubled_start(family, hb, &pd, h, &opts).map_err(trace_error)?;
        (branch, q1, w1)
    } else {
        let mut branch = FamilyBranch::new(family, hb, omega)?;
        let d = new_direction(&mut branch, &coeffs, omega, &opts)?;
        // Towards `to` when the new branch crosses ω_f (a pitchfork's leaves
        // at constant ω_f to first order: either sign).
        let d_omega = d.last().copied().unwrap_or(0.0);
        let sign = if d_omega * (req.to - omega) < 0.0 {
            -1.0
        } else {
            1.0
        };
        let (q1, w1) =
            switch_branch(&mut branch, &coeffs, omega, &d, sign * h, &opts).map_err(trace_error)?;
        (branch, q1, w1)
    };
    if (w1 - omega) * (req.to - omega) < 0.0 {
        return Err(HbError::InvalidInput(format!(
            "the new branch leaves the {} at ω_f = {omega:?} towards ω_f = {w1:?}: \
             `to` = {:?} must lie on that side",
            kind.words(),
            req.to
        )));
    }
    let (harmonics, subharmonic) = (branch.options().harmonics, branch.options().subharmonic);
    let sweep = FrcOptions::stepped_sweep(w1, req.to, req.corrector, &req.steps)
        .map_err(HbError::InvalidInput)?;
    let curve = traced_curve(&mut branch, &q1, &sweep, t0)?;
    Ok(SwitchedBranch {
        kind,
        start_omega: omega,
        harmonics,
        subharmonic,
        curve,
    })
}

/// The first located period doubling or branch point of the FRC `frc` of
/// `problem` (traced with events): `(kind, ω_f, coefficients)`.
fn first_event<P: PeriodicProblem>(
    problem: &P,
    hb: &HbOptions,
    frc: &FrcRequest,
) -> Result<(BifurcationKind, f64, Vec<f64>), HbError> {
    let req = FrcRequest {
        events: true,
        ..frc.clone()
    };
    let curve = super::frc(problem, hb, &req)?;
    curve
        .bifurcations
        .into_iter()
        .filter(|e| e.located && switchable(e.kind).is_ok())
        .find_map(|e| Some((e.kind, e.omega?, e.coeffs?.0)))
        .ok_or_else(|| {
            HbError::InvalidInput(format!(
                "the FRC from ω_f = {:?} to {:?} has no located period doubling or branch point",
                req.options.from, req.options.to
            ))
        })
}

/// The direction of the new branch at the branch point `(q, λ)` (`m + 1`
/// entries, unit): the root nearer λ = const of the bifurcation equation
/// `ψᵀ R''[d, d] = 0`, `d = cos φ v₁ + sin φ v₂` (see the module docs).
pub(super) fn new_direction<F: Family>(
    branch: &mut FamilyBranch<F>,
    q: &[f64],
    lambda: f64,
    opts: &LocateOptions,
) -> Result<Vec<f64>, HbError> {
    let m = branch.len();
    if q.len() != m {
        return Err(HbError::InvalidInput(format!(
            "the event's coefficients must have {m} entries (the same `n`), got {}",
            q.len()
        )));
    }
    let n1 = m + 1;
    let (jac, r_lambda) = jacobian_blocks(branch, q, lambda, opts);
    // [[R_q, R_λ], [uᵀ]] is singular with the null vector in null(A) ⊥ u and
    // the left one (ψ, 0): u = e_λ gives v₁ (at constant λ) and ψ, u = v₁
    // gives v₂.
    let mut aug = BorderedLu::new(m, 1);
    let seed: Vec<f64> = (0..n1).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
    let mut e_lambda = vec![0.0; n1];
    if let Some(l) = e_lambda.last_mut() {
        *l = 1.0;
    }
    let (mut v1, mut left) = (seed.clone(), seed.clone());
    augmented_null_vectors(&mut aug, (&jac, &r_lambda, &e_lambda), &mut v1, &mut left)?;
    unit(&mut v1)?;
    let (mut v2, mut unused) = (seed.clone(), seed);
    augmented_null_vectors(&mut aug, (&jac, &r_lambda, &v1), &mut v2, &mut unused)?;
    let along = dot(&v2, &v1);
    v2.iter_mut().zip(&v1).for_each(|(a, b)| *a -= along * b);
    unit(&mut v2)?;
    let psi = left.get(..m).unwrap_or(&[]);
    // ψᵀ R''[d, d] by a central second difference (R(x*) = 0 to the solver's
    // tolerance; R' d = 0).
    let scale = q.iter().fold(lambda.abs(), |a, v| a.max(v.abs())).max(1.0);
    let eps = 1e-4 * scale;
    let mut r = vec![0.0; m];
    let mut quad = |d: &[f64]| {
        let mut sum = 0.0;
        for s in [eps, -eps, 0.0] {
            let qs: Vec<f64> = q.iter().zip(d).map(|(a, b)| a + s * b).collect();
            let ls = lambda + s * d.last().copied().unwrap_or(0.0);
            branch.residual(&qs, ls, &mut r);
            sum += if s == 0.0 { -2.0 } else { 1.0 } * dot(psi, &r);
        }
        sum / (eps * eps)
    };
    let mix: Vec<f64> = v1.iter().zip(&v2).map(|(a, b)| a + b).collect();
    let (c11, c22, cmix) = (quad(&v1), quad(&v2), quad(&mix));
    let c12 = 0.5 * (cmix - c11 - c22);
    // Q(φ) = A + B cos 2φ + C sin 2φ = 0: R cos(2φ − α) = −A.
    let (a, b, c) = (0.5 * (c11 + c22), 0.5 * (c11 - c22), c12);
    let (radius, alpha) = (b.hypot(c), c.atan2(b));
    let two_roots = radius.is_finite() && a.abs() < radius;
    if !two_roots {
        return Err(HbError::InvalidInput(format!(
            "not a simple branch point at ω_f = {lambda:?}: its bifurcation equation has no two real roots"
        )));
    }
    let spread = (-a / radius).acos();
    let phi = [0.5 * (alpha + spread), 0.5 * (alpha - spread)]
        .into_iter()
        .fold(f64::NAN, |best: f64, p| {
            if best.is_nan() || p.sin().abs() < best.sin().abs() {
                p
            } else {
                best
            }
        });
    let mut d: Vec<f64> = v1
        .iter()
        .zip(&v2)
        .map(|(x, y)| phi.cos() * x + phi.sin() * y)
        .collect();
    unit(&mut d)?;
    Ok(d)
}

/// Scales `v` to unit length; an error if it is zero or not finite.
fn unit(v: &mut [f64]) -> Result<(), HbError> {
    let n = norm2(v);
    if !(n.is_finite() && n > 0.0) {
        return Err(HbError::InvalidInput(
            "no null vector at the branch point (a singular or non-finite Jacobian)".into(),
        ));
    }
    v.iter_mut().for_each(|x| *x /= n);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folds_and_neimark_sacker_points_are_refused_by_name() {
        for (kind, name) in [
            (BifurcationKind::Fold, "fold"),
            (BifurcationKind::NeimarkSacker, "Neimark–Sacker"),
        ] {
            let req = SwitchRequest {
                start: SwitchStart::Given {
                    kind,
                    omega: 1.0,
                    coeffs: vec![0.0; 3],
                },
                ..SwitchRequest::default()
            };
            let e = req.validate().unwrap_err();
            assert_eq!(e.kind(), "input");
            assert!(e.to_string().contains(name), "{e}");
        }
    }

    #[test]
    fn bad_step_and_to_are_input_errors() {
        for (step, to) in [(0.0, 2.0), (2.0, 2.0), (0.05, f64::NAN), (0.05, 1.0)] {
            let req = SwitchRequest {
                start: SwitchStart::Given {
                    kind: BifurcationKind::PeriodDoubling,
                    omega: 1.0,
                    coeffs: vec![0.0; 3],
                },
                step,
                to,
                ..SwitchRequest::default()
            };
            assert_eq!(req.validate().unwrap_err().kind(), "input", "{step} {to}");
        }
    }
}
