//! Backbone curves: the nonlinear normal mode of the undamped, unforced system
//! `M ẍ + K x + g(x, ẋ) = 0` followed in amplitude.
//!
//! Free periodic orbits of a conservative system are not isolated: they form a
//! family in energy, and one of the HB equations (Eq. 61) is redundant. As in
//! the energy-balance formulations of nonlinear modal analysis, a fictitious
//! mass-proportional damping `κ M ẋ` is added with κ an unknown; on a periodic
//! orbit of a conservative system the damping work forces κ = 0, and the
//! system becomes square and regular. With the frequency ω unknown, the phase
//! condition `b₁ = 0` on the reference DOF (as [`crate::branches::autonomous`]) and the
//! amplitude `a₁` of that DOF prescribed, the unknowns are `{q, ω, κ}` and `a₁`
//! is the continuation parameter (pseudo-arclength, Eq. 68–77). The problem
//! must be undamped and unforced (`C = 0`, `f = 0`; checked).

use crate::branches::family::{FamilyBranch, Frequency};
use crate::orbit::ihb::{HbError, HbOptions, HbResidual};
use crate::problem::PeriodicProblem;
use ivt_path::branch::Branch;
use ivt_path::continuation::{
    correct_at_fixed_lambda, BroydenCorrector, ContinuationOptions, Corrector, NewtonCorrector,
    Stepper, Traced, Turn,
};

mod system;
use system::BackboneSystem;

/// Options of [`backbone`].
#[derive(Debug, Clone, PartialEq)]
pub struct BackboneOptions {
    /// Reference DOF: its first cosine coefficient `a₁` is the amplitude and its
    /// `b₁` is held at zero.
    pub dof: usize,
    /// First amplitude `a₁` (small: the start is the linear mode).
    pub amplitude_from: f64,
    /// Last amplitude `a₁`.
    pub amplitude_to: f64,
    /// Path following (λ bounds are set from the amplitudes). Its corrector:
    /// [`Corrector::Broyden`] on the secant model (the default) or
    /// [`Corrector::Newton`] on the exact Jacobian of `{q, ω, κ}` (the
    /// Galerkin Jacobian, so the problem's analytic `∂g` is used).
    pub continuation: ContinuationOptions,
}

impl Default for BackboneOptions {
    fn default() -> Self {
        Self {
            dof: 0,
            amplitude_from: 0.01,
            amplitude_to: 1.0,
            continuation: ContinuationOptions::default(),
        }
    }
}

/// One point of a backbone curve.
#[derive(Debug, Clone, PartialEq)]
pub struct BackbonePoint {
    /// `a₁` of the reference DOF.
    pub amplitude: f64,
    /// Frequency ω of the free oscillation (τ = ωt).
    pub omega: f64,
    /// Fourier coefficients (layout of [`crate::HbSolution::coeffs`]).
    pub coeffs: Vec<f64>,
    /// The unfolding damping κ (zero up to the tolerance for a conservative system).
    pub kappa: f64,
    /// `max_τ |x(τ)|` of the reference DOF ([`crate::orbit::aft::peak`]): the
    /// measure of a response curve's amplitude, so that the backbone can be
    /// drawn over one.
    pub peak: f64,
}

/// A traced backbone curve; its events are the stepper's turning points in
/// the amplitude `a₁` ([`Turn`]: estimated from the three points around
/// each, not located).
pub type Backbone = Traced<BackbonePoint, Turn>;

/// Traces the backbone of the mode with linear frequency `omega0` and shape
/// `mode` (`n_dof` entries, `K mode = ω₀² M mode`) from `opts.amplitude_from`
/// to `opts.amplitude_to` (in `a₁` of the reference DOF). `hb.subharmonic`
/// must be 1.
///
/// # Errors
/// [`HbError::InvalidInput`] for sizes, a zero reference entry of `mode`, bad
/// amplitudes, or a problem with damping or excitation; [`PathError::ContinuationStart`](ivt_path::PathError::ContinuationStart) when the start does not converge.
pub fn backbone(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    omega0: f64,
    mode: &[f64],
    opts: &BackboneOptions,
) -> Result<Backbone, HbError> {
    let problem = &problem;
    if problem.damping().iter().any(|v| *v != 0.0) {
        return Err(HbError::InvalidInput(
            "a backbone needs an undamped, unforced problem (C = 0, f = 0)".into(),
        ));
    }
    modal_path(problem, hb, (omega0, mode), opts)
}

/// The path of [`backbone`] without its check `C = 0`: with damping, the
/// unfolding `κ M ẋ` is the extended periodic motion concept's negative modal
/// damping (Krack 2015), and [`crate::branches::damped`] reads `ζ = −κ/(2ω)` off it.
/// Arguments (`linear` = `(omega0, mode)`) and errors as [`backbone`] (all
/// checked here except `C = 0`).
pub(crate) fn modal_path<P: PeriodicProblem>(
    problem: &P,
    hb: &HbOptions,
    (omega0, mode): (f64, &[f64]),
    opts: &BackboneOptions,
) -> Result<Backbone, HbError> {
    let nd = problem.n_dof();
    let (a_from, a_to) = (opts.amplitude_from, opts.amplitude_to);
    let reference = mode.get(opts.dof).copied().unwrap_or(0.0);
    let problem_text = if hb.subharmonic != 1 || mode.len() != nd || opts.dof >= nd {
        Some(format!(
            "backbone needs subharmonic order 1, a mode of {nd} entries and a reference DOF < {nd}"
        ))
    } else if !(reference != 0.0 && mode.iter().all(|v| v.is_finite())) {
        Some("the mode must be finite with a non-zero reference entry".into())
    } else if !(a_from.is_finite() && a_to.is_finite() && a_from != a_to && omega0 > 0.0) {
        Some("amplitudes must be finite and distinct, ω₀ positive".into())
    } else if HbResidual::new(problem, hb)?
        .excitation()
        .iter()
        .any(|v| *v != 0.0)
    {
        Some("a backbone needs an unforced problem (f = 0)".into())
    } else {
        None
    };
    if let Some(text) = problem_text {
        return Err(HbError::InvalidInput(text));
    }
    let l = 2 * hb.harmonics + 1;
    let indices = (opts.dof * l + 1, opts.dof * l + hb.harmonics + 1);
    let mut system = BackboneSystem::new(
        FamilyBranch::new(Frequency(problem), hb, omega0)?,
        problem.mass(),
        nd,
        hb.harmonics,
        indices,
    );
    let m = system.len() - 2;
    // x = {q, ω, κ, a₁}: the linear mode at the first amplitude.
    let mut x0 = vec![0.0; m + 3];
    for (d, phi) in mode.iter().enumerate() {
        if let Some(x) = x0.get_mut(d * l + 1) {
            *x = a_from * phi / reference;
        }
    }
    // κ of the linear mode, −φᵀCφ/φᵀMφ (zero without damping; exact for
    // proportional damping): the start is then nearly converged, and the
    // path's first secant does not point along κ.
    let quadratic = |a: &[f64]| -> f64 {
        a.chunks_exact(nd.max(1))
            .zip(mode)
            .map(|(row, mi)| mi * row.iter().zip(mode).map(|(v, mj)| v * mj).sum::<f64>())
            .sum()
    };
    let modal_mass = quadratic(problem.mass());
    let kappa0 = if modal_mass != 0.0 && modal_mass.is_finite() {
        -quadratic(problem.damping()) / modal_mass
    } else {
        0.0
    };
    if let Some(tail) = x0.get_mut(m..) {
        tail.copy_from_slice(&[omega0, kappa0, a_from]);
    }
    let mut copts = opts.continuation.clone();
    copts.lambda_min = a_from.min(a_to);
    copts.lambda_max = a_from.max(a_to);
    let direction = a_to - a_from;
    let path = match copts.corrector {
        Corrector::Broyden => {
            let corrector = Box::new(BroydenCorrector::new(m + 2, &copts.broyden, None));
            Stepper::new(&mut system, corrector, &x0, 0, direction, &copts)?.run(|_, _| true)
        }
        Corrector::Newton => {
            let its = correct_at_fixed_lambda(&mut system, &mut x0, &copts)?;
            let corrector = Box::new(NewtonCorrector::new(m + 2, &copts));
            Stepper::new(&mut system, corrector, &x0, its, direction, &copts)?.run(|_, _| true)
        }
    };
    // One point per path point, so that the events' indices stay valid.
    let points = path
        .points
        .iter()
        .map(|p| match p.x.split_at_checked(m) {
            Some((q, &[omega, kappa, amplitude])) => Ok(BackbonePoint {
                amplitude,
                omega,
                coeffs: q.to_vec(),
                kappa,
                peak: crate::orbit::aft::peak(
                    q.get(opts.dof * l..(opts.dof + 1) * l).unwrap_or_default(),
                ),
            }),
            _ => Err(HbError::InvalidInput(
                "backbone: point of the wrong size".into(),
            )),
        })
        .collect::<Result<_, _>>()?;
    Ok(Backbone {
        points,
        events: path.events,
        termination: path.termination,
    })
}
