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

use crate::continuation::{
    correct_at_fixed_lambda, pseudo_arclength, pseudo_arclength_exact, ContinuationOptions,
    Corrector, PathSystem, Termination,
};
use crate::family::{FamilyBranch, Frequency};
use crate::ihb::{HbError, HbOptions, HbResidual};
use crate::problem::PeriodicProblem;
use faer::Mat;

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
    /// The path's corrector: [`Corrector::Broyden`] on the secant model (the
    /// default) or [`Corrector::Newton`] on the exact Jacobian of `{q, ω, κ}`
    /// (the Galerkin Jacobian, so the problem's analytic `∂g` is used).
    pub corrector: Corrector,
}

impl Default for BackboneOptions {
    fn default() -> Self {
        Self {
            dof: 0,
            amplitude_from: 0.01,
            amplitude_to: 1.0,
            continuation: ContinuationOptions::default(),
            corrector: Corrector::Broyden,
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

/// The backbone equations `[R(q, ω) + κω D q; b₁; a₁ − λ] = 0` in the unknowns
/// `{q, ω, κ}` at `λ` = the prescribed `a₁`, with their exact Jacobian for
/// [`pseudo_arclength_exact`]: `∂R/∂q` is the Galerkin Jacobian (Eq. 56) of
/// the frequency family at ω, `∂R/∂ω` its exact ω-derivative
/// ([`Frequency`]), and the unfolding `κω D q` is linear in each unknown.
struct BackboneSystem<'a, P: PeriodicProblem> {
    branch: FamilyBranch<Frequency<'a, P>>,
    mass: &'a [f64],
    nd: usize,
    n: usize,
    /// Indices of `a₁` and `b₁` of the reference DOF in `q`.
    a1: usize,
    b1: usize,
    /// `∂R/∂q` of the branch, `∂R/∂ω`, and `D q` scratch (`m` each).
    jq: Mat<f64>,
    column: Vec<f64>,
    dq: Vec<f64>,
}

impl<P: PeriodicProblem> BackboneSystem<'_, P> {
    /// `D q` (the unfolding per unit κω) into `self.dq`.
    fn unfolding_of(&mut self, q: &[f64]) {
        self.dq.fill(0.0);
        add_unfolding(self.mass, self.nd, self.n, q, 1.0, &mut self.dq);
    }
}

impl<P: PeriodicProblem> PathSystem for BackboneSystem<'_, P> {
    fn dim(&self) -> usize {
        self.dq.len() + 2
    }
    fn residual(&mut self, u: &[f64], lambda: f64, r: &mut [f64]) {
        let m = self.dq.len();
        let (q, omega, kappa) = (&u[..m], u[m], u[m + 1]);
        PathSystem::residual(&mut self.branch, q, omega, &mut r[..m]);
        add_unfolding(self.mass, self.nd, self.n, q, kappa * omega, r);
        r[m] = u[self.b1];
        r[m + 1] = u[self.a1] - lambda;
    }
    fn residual_jacobian(&mut self, u: &[f64], lambda: f64, r: &mut [f64], jac: &mut Mat<f64>) {
        let m = self.dq.len();
        let (q, omega, kappa) = (&u[..m], u[m], u[m + 1]);
        self.branch
            .residual_jacobian(q, omega, &mut r[..m], &mut self.jq);
        add_unfolding(self.mass, self.nd, self.n, q, kappa * omega, r);
        r[m] = u[self.b1];
        r[m + 1] = u[self.a1] - lambda;
        jac.fill(0.0);
        jac.as_mut().submatrix_mut(0, 0, m, m).copy_from(&self.jq);
        // ∂(κω D q)/∂q = κω D, column k the image of the unit vector e_k.
        let mut unit = vec![0.0; m];
        for k in 0..m {
            unit[k] = 1.0;
            self.unfolding_of(&unit);
            unit[k] = 0.0;
            for (i, d) in self.dq.iter().enumerate() {
                jac[(i, k)] += kappa * omega * d;
            }
        }
        let mut column = std::mem::take(&mut self.column);
        self.branch.d_residual_d_lambda(q, omega, &mut column);
        self.unfolding_of(q);
        for i in 0..m {
            jac[(i, m)] = column[i] + kappa * self.dq[i];
            jac[(i, m + 1)] = omega * self.dq[i];
        }
        self.column = column;
        jac[(m, self.b1)] = 1.0;
        jac[(m + 1, self.a1)] = 1.0;
    }
    fn d_residual_d_lambda(&mut self, _u: &[f64], _lambda: f64, r_lambda: &mut [f64]) {
        r_lambda.fill(0.0);
        let m = self.dq.len();
        r_lambda[m + 1] = -1.0;
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
    if problem.damping().iter().any(|v| *v != 0.0) {
        return Err(HbError::InvalidInput(
            "a backbone needs an undamped, unforced problem (C = 0, f = 0)".into(),
        ));
    }
    modal_path(problem, hb, omega0, mode, opts)
}

/// The path of [`backbone`] without its check `C = 0`: with damping, the
/// unfolding `κ M ẋ` is the extended periodic motion concept's negative modal
/// damping (Krack 2015), and [`crate::damped`] reads `ζ = −κ/(2ω)` off it.
/// Arguments and errors as [`backbone`] (all checked here except `C = 0`).
pub(crate) fn modal_path<P: PeriodicProblem>(
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
    if res.excitation().iter().any(|v| *v != 0.0) {
        return Err(HbError::InvalidInput(
            "a backbone needs an unforced problem (f = 0)".into(),
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
    // κ of the linear mode, −φᵀCφ/φᵀMφ (zero without damping; exact for
    // proportional damping): the start is then nearly converged, and the
    // path's first secant does not point along κ.
    let quadratic = |a: &[f64]| -> f64 {
        (0..nd)
            .map(|i| {
                (0..nd)
                    .map(|j| mode[i] * a[i * nd + j] * mode[j])
                    .sum::<f64>()
            })
            .sum()
    };
    let modal_mass = quadratic(problem.mass());
    if modal_mass != 0.0 && modal_mass.is_finite() {
        x0[m + 1] = -quadratic(problem.damping()) / modal_mass;
    }
    x0[m + 2] = a_from;
    let mut copts = opts.continuation.clone();
    copts.lambda_min = a_from.min(a_to);
    copts.lambda_max = a_from.max(a_to);
    let path = match opts.corrector {
        Corrector::Broyden => pseudo_arclength(
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
        )?,
        Corrector::Newton => {
            let mut system = BackboneSystem {
                branch: FamilyBranch::new(Frequency(problem), hb, omega0)?,
                mass: problem.mass(),
                nd,
                n: hb.harmonics,
                a1,
                b1,
                jq: Mat::zeros(m, m),
                column: vec![0.0; m],
                dq: vec![0.0; m],
            };
            let its = correct_at_fixed_lambda(&mut system, &mut x0, &copts)?;
            pseudo_arclength_exact(&mut system, &x0, its, a_to - a_from, &copts, |_, _| true)?
        }
    };
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
