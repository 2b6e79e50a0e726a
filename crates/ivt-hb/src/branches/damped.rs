//! Damped nonlinear modes by the extended periodic motion concept (EPMC;
//! Krack, J. Sound Vib. 2015; NLvib's `EPMC`): the free, damped system
//! `M ẍ + C ẋ + K x + g(x, ẋ) = 0` is made periodic by a negative
//! mass-proportional damping `κ M ẋ` that cancels, over a period, the energy the
//! system dissipates; `ζ = −κ/(2ω)` is then the modal damping ratio at that
//! amplitude, ω the modal frequency. The unknowns `{q, ω, κ}`, the phase
//! condition `b₁ = 0` and the prescribed amplitude `a₁` of the reference DOF are
//! those of the backbone ([`crate::backbone()`], whose path this traces): for
//! `C = 0` the curve is the backbone (κ = 0), and at vanishing amplitude it
//! is the linear mode: for proportional damping `C = αM + βK`, mode i has
//! `ω = ω_i` and `ζ = (α + βω_i²)/(2ω_i)` exactly.
//!
//! The linear mode (the start) is the `mode`-th eigenpair of `M⁻¹K` by
//! increasing frequency.

use crate::branches::backbone::{modal_path, BackboneOptions};
use crate::error::HbError;
use crate::orbit::ihb::HbOptions;
use crate::problem::PeriodicProblem;
use ivt_path::continuation::Termination;

/// One point of a damped-mode curve.
#[derive(Debug, Clone, PartialEq)]
pub struct DampedModePoint {
    /// `a₁` of the reference DOF.
    pub amplitude: f64,
    /// Modal frequency ω (τ = ωt).
    pub omega: f64,
    /// Modal damping ratio `ζ = −κ/(2ω)`.
    pub damping_ratio: f64,
    /// `max_τ |x(τ)|` of the reference DOF (as [`crate::BackbonePoint::peak`]).
    pub peak: f64,
    /// Fourier coefficients (layout of [`crate::HbSolution::coeffs`]).
    pub coeffs: Vec<f64>,
}

/// A traced damped nonlinear mode.
#[derive(Debug, Clone, PartialEq)]
pub struct DampedModes {
    /// The linear mode's undamped frequency ω₀ (the start).
    pub linear_omega: f64,
    /// The linear mode's shape (`K φ = ω₀² M φ`, first largest entry +1).
    pub linear_mode: Vec<f64>,
    /// Points in path order.
    pub points: Vec<DampedModePoint>,
    /// Why tracing stopped.
    pub termination: Termination,
}

/// The `mode`-th linear mode of `(M, K)` by increasing frequency: `(ω₀, φ)`
/// with `φ` scaled so that its first entry of largest modulus is +1.
///
/// # Errors
/// [`HbError::InvalidInput`] for a singular `M`, a mode index out of range or a
/// mode whose `ω₀²` is not real and positive; [`HbError::Eigen`] if the
/// eigen-solver fails.
pub fn linear_mode<P: PeriodicProblem>(
    problem: &P,
    mode: usize,
) -> Result<(f64, Vec<f64>), HbError> {
    let nd = problem.n_dof();
    if mode >= nd {
        return Err(HbError::InvalidInput(format!(
            "mode {mode} does not exist: the problem has {nd} DOFs"
        )));
    }
    let minv = ivt_num::lu::inverse(problem.mass(), nd).ok_or_else(|| {
        HbError::InvalidInput("the mass matrix must be invertible for the linear modes".into())
    })?;
    let k = problem.stiffness();
    let a = faer::Mat::<f64>::from_fn(nd, nd, |i, j| {
        // NaN if K is not nd×nd.
        (0..nd)
            .map(|e| {
                minv.get(i * nd + e)
                    .zip(k.get(e * nd + j))
                    .map_or(f64::NAN, |(m, k)| m * k)
            })
            .sum()
    });
    let eig = a
        .eigen()
        .map_err(|e| HbError::Eigen(format!("linear modes: {e:?}")))?;
    let (s, u) = (eig.S(), eig.U());
    let mut order: Vec<usize> = (0..nd).collect();
    order.sort_by(|&i, &j| s[i].re.total_cmp(&s[j].re));
    let Some(&col) = order.get(mode) else {
        return Err(HbError::InvalidInput(format!(
            "mode {mode} does not exist: the problem has {nd} DOFs"
        )));
    };
    let lambda = s[col];
    if !(lambda.re > 0.0 && lambda.im.abs() <= 1e-10 * lambda.re) {
        return Err(HbError::InvalidInput(format!(
            "mode {mode} has ω₀² = {lambda:?}, not real and positive"
        )));
    }
    // The eigenvector up to a complex factor: divide by its largest entry.
    // The first entry of largest modulus (ties within 1e-12 keep the first).
    let pivot = (0..nd).fold(faer::c64::new(0.0, 0.0), |best, i| {
        let e = u[(i, col)];
        if e.norm() > best.norm() * (1.0 + 1e-12) {
            e
        } else {
            best
        }
    });
    let shape = (0..nd).map(|i| (u[(i, col)] / pivot).re).collect();
    Ok((lambda.re.sqrt(), shape))
}

/// The damped nonlinear mode `mode` of `problem` (unforced; `C` any) traced in
/// the amplitude `a₁` of `opts.dof` from `opts.amplitude_from` to
/// `opts.amplitude_to` (see the module docs). `hb.subharmonic` must be 1.
///
/// # Errors
/// As [`linear_mode`] and [`crate::backbone()`] (without its `C = 0`); a
/// reference DOF at a node of the mode is [`HbError::InvalidInput`].
pub fn damped_modes(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    mode: usize,
    opts: &BackboneOptions,
) -> Result<DampedModes, HbError> {
    let problem = &problem;
    let (omega0, shape) = linear_mode(problem, mode)?;
    if shape.get(opts.dof).is_none_or(|v| v.abs() < 1e-12) {
        return Err(HbError::InvalidInput(format!(
            "reference DOF {} is at a node of mode {mode}: choose another `dof`",
            opts.dof
        )));
    }
    let path = modal_path(problem, hb, (omega0, &shape), opts)?;
    let points = path
        .points
        .into_iter()
        .map(|p| DampedModePoint {
            amplitude: p.amplitude,
            omega: p.omega,
            damping_ratio: -p.kappa / (2.0 * p.omega),
            peak: p.peak,
            coeffs: p.coeffs,
        })
        .collect();
    Ok(DampedModes {
        linear_omega: omega0,
        linear_mode: shape,
        points,
        termination: path.termination,
    })
}
