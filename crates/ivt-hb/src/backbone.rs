//! Backbone curves: the nonlinear normal mode of the undamped, unforced system
//! `M ẍ + K x + g(x, ẋ) = 0` followed in amplitude.
//!
//! Free periodic orbits of a conservative system are not isolated: they form a
//! family in energy, and one of the HB equations (Eq. 61) is redundant. As in
//! the energy-balance formulations of nonlinear modal analysis, a fictitious
//! mass-proportional damping `κ M ẋ` is added with κ an unknown; on a periodic
//! orbit of a conservative system the damping work forces κ = 0, and the
//! system becomes square and regular. With the frequency ω unknown, the phase
//! condition `b₁ = 0` on the reference DOF (as [`crate::autonomous`]) and the
//! amplitude `a₁` of that DOF prescribed, the unknowns are `{q, ω, κ}` and `a₁`
//! is the continuation parameter ([`pseudo_arclength`], Eq. 68–77). The problem
//! must be undamped and unforced (`C = 0`, `f = 0`; checked).

use crate::continuation::{pseudo_arclength, ContinuationOptions, Termination};
use crate::ihb::{HbError, HbOptions, HbResidual};
use crate::problem::PeriodicProblem;

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
    /// Path following (λ bounds are set from the amplitudes).
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
}

/// A traced backbone curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Backbone {
    /// Points in path order.
    pub points: Vec<BackbonePoint>,
    /// Why tracing stopped.
    pub termination: Termination,
}

/// Adds the Galerkin projection of the unfolding damping `κ M ẋ` (τ = ωt) to
/// `r`: harmonic h gives `κhω M b_h` to the cosine rows and `−κhω M a_h` to the
/// sine rows (the damping part of Eq. 60 with `C = κM`).
fn add_unfolding(mass: &[f64], nd: usize, n: usize, q: &[f64], kappa_omega: f64, r: &mut [f64]) {
    let l = 2 * n + 1;
    for d in 0..nd {
        for e in 0..nd {
            let me = mass[d * nd + e] * kappa_omega;
            for h in 1..=n {
                let s = h as f64 * me;
                r[d * l + h] += s * q[e * l + n + h];
                r[d * l + n + h] -= s * q[e * l + h];
            }
        }
    }
}

/// Traces the backbone of the mode with linear frequency `omega0` and shape
/// `mode` (`n_dof` entries, `K mode = ω₀² M mode`) from `opts.amplitude_from`
/// to `opts.amplitude_to` (in `a₁` of the reference DOF). `hb.subharmonic`
/// must be 1.
///
/// # Errors
/// [`HbError::InvalidInput`] for sizes, a zero reference entry of `mode`, bad
/// amplitudes, or a problem with damping or excitation; [`HbError::ContinuationStart`] when the start does not converge.
pub fn backbone<P: PeriodicProblem>(
    problem: &P,
    hb: &HbOptions,
    omega0: f64,
    mode: &[f64],
    opts: &BackboneOptions,
) -> Result<Backbone, HbError> {
    let nd = problem.n_dof();
    let (a_from, a_to) = (opts.amplitude_from, opts.amplitude_to);
    if hb.subharmonic != 1 || mode.len() != nd || opts.dof >= nd {
        return Err(HbError::InvalidInput(format!(
            "backbone needs subharmonic order 1, a mode of {nd} entries and a reference DOF < {nd}"
        )));
    }
    if !(mode[opts.dof] != 0.0 && mode.iter().all(|v| v.is_finite())) {
        return Err(HbError::InvalidInput(
            "the mode must be finite with a non-zero reference entry".into(),
        ));
    }
    if !(a_from.is_finite() && a_to.is_finite() && a_from != a_to && omega0 > 0.0) {
        return Err(HbError::InvalidInput(
            "amplitudes must be finite and distinct, ω₀ positive".into(),
        ));
    }
    let mut res = HbResidual::new(problem, hb)?;
    if problem
        .damping()
        .iter()
        .chain(res.excitation())
        .any(|v| *v != 0.0)
    {
        return Err(HbError::InvalidInput(
            "a backbone needs an undamped, unforced problem (C = 0, f = 0)".into(),
        ));
    }
    let m = res.len();
    let l = 2 * hb.harmonics + 1;
    let (a1, b1) = (opts.dof * l + 1, opts.dof * l + hb.harmonics + 1);
    // x = {q, ω, κ, a₁}: the linear mode at the first amplitude.
    let mut x0 = vec![0.0; m + 3];
    for (d, phi) in mode.iter().enumerate() {
        x0[d * l + 1] = a_from * phi / mode[opts.dof];
    }
    x0[m] = omega0;
    x0[m + 2] = a_from;
    let mut copts = opts.continuation.clone();
    copts.lambda_min = a_from.min(a_to);
    copts.lambda_max = a_from.max(a_to);
    let path = pseudo_arclength(
        |x: &[f64], r: &mut [f64]| {
            res.eval(problem, &x[..m], x[m], 1.0, &mut r[..m]);
            add_unfolding(
                problem.mass(),
                nd,
                hb.harmonics,
                &x[..m],
                x[m + 1] * x[m],
                r,
            );
            r[m] = x[b1];
            r[m + 1] = x[a1] - x[m + 2];
        },
        &x0,
        None,
        a_to - a_from,
        &copts,
        |_| true,
    )?;
    let points = path
        .points
        .iter()
        .map(|p| BackbonePoint {
            amplitude: p.x[m + 2],
            omega: p.x[m],
            coeffs: p.x[..m].to_vec(),
            kappa: p.x[m + 1],
        })
        .collect();
    Ok(Backbone {
        points,
        termination: path.termination,
    })
}
