//! IVT periodic steady state by the modified IHB, Eq. 152–157.
//!
//! In the dimensionless time τ = ω0 t the angle is `θ = τ + C_sᵀ q_p`
//! (Eq. 152), so the time mean of θ̇ is exactly ω0 whatever q_p is; the
//! residual of Eq. 151,
//!
//! ```text
//! R_p = ω0² [J θ₁'' + ½ J_θ (1 + θ₁')²] + ω0 F_m (1 + θ₁') − G r − f1 + f2 r   (Eq. 155)
//! ```
//!
//! is sampled at `samples` equally spaced τ and projected on
//! `C̃_s = {½, cos τ … cos nτ, sin τ … sin nτ}` (alternating frequency–time).
//! The 2n+1 balanced residuals are zeroed in the 2n+1 unknowns `x_p = {r, q_p}`.
//!
//! Solver: Broyden's update (Eq. 156–157, [`IhbMethod::Broyden`], default)
//! through [`ivt_num::broyden`], seeded on a cold start by the exact Jacobian of
//! the sampled residual and along a sweep by the previous point's matrix; or
//! Newton with that exact Jacobian at every step ([`IhbMethod::Newton`], the
//! classic IHB of §3.2.1). The projection is a direct sum over cos/sin tables
//! at the quadrature nodes: for n = 7 that is ~1 k multiply–adds per residual,
//! no cheaper by FFT.
//!
//! Accuracy: f_θ (Eq. 139) jumps at the gear corners, so ω̄(θ) has kinks and
//! θ₁ has Fourier coefficients decaying like k⁻³. The truncation at n
//! harmonics, not the solver, limits how well r̄ matches the exact (shooting)
//! value; `tests::converges_in_n` and docs/guide/src/reproducing.md show r̄(n).

mod gauss;
mod residual;

use super::{averaged_r, check_plant, IvtError, OperatingPoint, Verdict};
use core::f64::consts::PI;
use gauss::gauss_legendre;
use ivt_kin::plant::PlantParams;
use ivt_num::broyden::{broyden_solve, BroydenOptions, BroydenWorkspace};
use ivt_num::{newton, NewtonOptions, NewtonWorkspace, SolveError};
use nalgebra::{DMatrix, DVector};
use residual::{theta1_of, BalancedResidual};

/// Harmonics, sampling and stopping rule of the IHB solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IhbOptions {
    /// Harmonics n of θ₁ (thesis: 7).
    pub harmonics: usize,
    /// Time samples per period for the projection; 0 = automatic
    /// (the smallest power of two ≥ max(64, 8n)).
    pub samples: usize,
    /// Stop when the Euclidean norm of the balanced residual (N·m) is below this
    /// (thesis: 1e-10).
    pub tol: f64,
    /// Newton iteration limit.
    pub max_iter: usize,
    /// How the balanced residual integral is evaluated.
    pub quadrature: Quadrature,
    /// Nonlinear solver for Eq. 156–157.
    pub method: IhbMethod,
}

/// Solver of the balanced equations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum IhbMethod {
    /// Broyden's update, Eq. 156–157 (the thesis's modified IHB), via
    /// [`ivt_num::broyden_solve`]: the exact Jacobian seeds it on a cold
    /// start, and along a sweep the matrix left by the previous point seeds
    /// the next, so most points need no Jacobian at all.
    #[default]
    Broyden,
    /// Newton with the exact Jacobian at every step (the classic IHB, §3.2.1).
    Newton,
}

/// Quadrature of the harmonic-balance integral `(1/π)∫ C̃_s R_p dτ`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Quadrature {
    /// Equally spaced samples (the thesis's FFT/AFT route). The residual jumps
    /// where θ(τ) crosses a gear corner, so this sum converges only like
    /// 1/samples (≈1e-4 relative in r̄ at 1024 samples, see docs/guide/src/reproducing.md).
    Uniform,
    /// Gauss–Legendre on each smooth piece between the τ where θ(τ) crosses a
    /// corner (found by Newton on Eq. 152), with the moving-end terms in the
    /// Jacobian: the integral is exact to round-off, and r̄ converges to the
    /// shooting value as n grows.
    #[default]
    PiecewiseGauss,
}

impl Default for IhbOptions {
    fn default() -> Self {
        Self {
            harmonics: 7,
            samples: 0,
            tol: 1e-10,
            max_iter: 40,
            quadrature: Quadrature::default(),
            method: IhbMethod::default(),
        }
    }
}

impl IhbOptions {
    fn sample_count(&self) -> usize {
        match self.quadrature {
            Quadrature::Uniform if self.samples > 0 => self.samples,
            Quadrature::Uniform => (8 * self.harmonics).max(64).next_power_of_two(),
            // Four smooth pieces per period, `gauss_nodes()` nodes each.
            Quadrature::PiecewiseGauss => 4 * self.gauss_nodes(),
        }
    }

    /// Gauss nodes per smooth piece: `samples/4` if given, else n + 8
    /// (r̄ then agrees with 200 nodes per piece to ≤ 1e-13 relative for n = 7
    /// and 31 at three grid points; n + 4 gives ~1e-10).
    fn gauss_nodes(&self) -> usize {
        if self.samples >= 4 {
            self.samples / 4
        } else {
            self.harmonics + 8
        }
    }
}

/// Most harmonics of the IVT IHB: r̄(n) converges like n⁻³ (8.7e-9 relative
/// at n = 383, docs/guide/src/reproducing.md), and the tables grow like n²
/// (~50 MB and seconds per solve at 511), so more buys nothing.
pub const MAX_HARMONICS: usize = 511;

/// Most explicit quadrature samples per period (tables of samples × n).
pub const MAX_SAMPLES: usize = 65_536;

/// The IHB steady state at one operating point.
#[derive(Clone, Debug, PartialEq)]
pub struct SteadyState {
    /// Operating point solved for.
    pub op: OperatingPoint,
    /// Unconstrained r̄ \[m\] (may be < 0 or > r_max; see `verdict`).
    pub r: f64,
    /// q_p = {q_c1 … q_cn, q_s1 … q_sn} \[rad\], Eq. 152.
    pub q: Vec<f64>,
    /// Smallest ω̄ over 128 equally spaced τ \[rad/s\].
    pub omega_min: f64,
    /// Largest ω̄ over 128 equally spaced τ \[rad/s\].
    pub omega_max: f64,
    /// Where r̄ lies relative to [0, r_max].
    pub verdict: Verdict,
    /// Newton iterations used.
    pub iterations: usize,
    /// Final Euclidean norm of the balanced residual \[N·m\].
    pub residual_norm: f64,
}

impl SteadyState {
    /// θ₁(τ) and its τ-derivative.
    fn theta1(&self, tau: f64) -> (f64, f64) {
        theta1_of(&self.q, tau)
    }

    /// θ(τ) = τ + θ₁(τ), Eq. 152.
    pub fn theta_at_tau(&self, tau: f64) -> f64 {
        tau + self.theta1(tau).0
    }

    /// ω̄(τ) = ω0 (1 + θ₁'(τ)), Eq. 153.
    pub fn omega_at_tau(&self, tau: f64) -> f64 {
        self.op.omega0 * (1.0 + self.theta1(tau).1)
    }

    /// ω̄ at the angle θ (inverts Eq. 152 by Newton on τ; θ(τ) is monotone
    /// because ω̄ > 0).
    pub fn omega_at_theta(&self, theta: f64) -> f64 {
        let mut tau = theta;
        for _ in 0..50 {
            let (v, d) = self.theta1(tau);
            let step = (tau + v - theta) / (1.0 + d);
            tau -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        self.omega_at_tau(tau)
    }
}

/// A plan for one (n, quadrature): node/weight storage, trig tables and the
/// projection matrix, reused over many solves (a sweep makes one per thread).
#[derive(Clone, Debug)]
pub struct IhbSolver {
    opts: IhbOptions,
    /// Quadrature nodes τ_j and weights (Σ w = 2π).
    tau: Vec<f64>,
    weight: Vec<f64>,
    /// Gauss–Legendre nodes/weights on [−1, 1] (piecewise quadrature only).
    gauss: (Vec<f64>, Vec<f64>),
    /// cos(k τ_j), sin(k τ_j) for k = 1..n, row-major [j][k-1].
    cos: Vec<f64>,
    sin: Vec<f64>,
    /// (2n+1) × samples projection on C̃_s (the integral after Eq. 155).
    project: DMatrix<f64>,
    /// samples × (2n+1) derivatives of the sampled residual.
    dres: DMatrix<f64>,
    res: DVector<f64>,
    /// Moving-end (corner-crossing) contributions to the Jacobian.
    jump_jac: DMatrix<f64>,
    /// (sin kτ_c, cos kτ_c) at one corner crossing, k = 1..=n.
    trig_c: Vec<(f64, f64)>,
    /// The projection row weights at one corner crossing (2n+1).
    jump_row: Vec<f64>,
    /// Broyden matrices, kept between solves (warm start along a sweep).
    broyden: BroydenWorkspace,
}

impl IhbSolver {
    /// Plan the tables for `opts`.
    ///
    /// # Errors
    /// [`IvtError::Input`] for n = 0 or too few samples (need > 2n).
    pub fn new(opts: IhbOptions) -> Result<Self, IvtError> {
        let n = opts.harmonics;
        if n == 0 || n > MAX_HARMONICS {
            return Err(IvtError::Input {
                name: "harmonics",
                value: n as f64,
                requirement:
                    "in 1..=511 (MAX_HARMONICS: ~5e-9 relative in r̄, seconds and ~50 MB per solve)",
            });
        }
        if opts.samples > MAX_SAMPLES {
            return Err(IvtError::Input {
                name: "samples",
                value: opts.samples as f64,
                requirement: "at most 65536 (MAX_SAMPLES)",
            });
        }
        let m = opts.sample_count();
        if m <= 2 * n {
            return Err(IvtError::Input {
                name: "samples",
                value: m as f64,
                requirement: "> 2 × harmonics",
            });
        }
        let mut s = Self {
            opts,
            tau: vec![0.0; m],
            weight: vec![2.0 * PI / m as f64; m],
            gauss: gauss_legendre(opts.gauss_nodes()),
            cos: vec![0.0; m * n],
            sin: vec![0.0; m * n],
            project: DMatrix::zeros(2 * n + 1, m),
            dres: DMatrix::zeros(m, 2 * n + 1),
            res: DVector::zeros(m),
            jump_jac: DMatrix::zeros(2 * n + 1, 2 * n + 1),
            trig_c: vec![(0.0, 1.0); n],
            jump_row: vec![0.0; 2 * n + 1],
            broyden: BroydenWorkspace::new(2 * n + 1),
        };
        for (j, tau) in s.tau.iter_mut().enumerate() {
            *tau = 2.0 * PI * j as f64 / m as f64;
        }
        s.fill_tables();
        Ok(s)
    }

    /// The options this plan was made for.
    pub fn options(&self) -> &IhbOptions {
        &self.opts
    }

    /// Solve Eq. 152–157 at `op`. `warm` = a previous solution {r, q_p} of the
    /// same n (a neighbouring grid point); otherwise r starts from the
    /// averaged power balance and q_p from zero.
    ///
    /// # Errors
    /// Bad inputs; [`IvtError::NoConvergence`] with the residual history.
    pub fn solve(
        &mut self,
        plant: &PlantParams,
        op: &OperatingPoint,
        warm: Option<(f64, &[f64])>,
    ) -> Result<SteadyState, IvtError> {
        check_plant(plant)?;
        op.validate()?;
        let n = self.opts.harmonics;
        let dim = 2 * n + 1;
        // x = {r, q_p}
        let x: Vec<f64> = match warm {
            Some((r, q)) if q.len() == 2 * n => {
                core::iter::once(r).chain(q.iter().copied()).collect()
            }
            _ => core::iter::once(averaged_r(plant, op))
                .chain(core::iter::repeat_n(0.0, 2 * n))
                .collect(),
        };
        if self.opts.method == IhbMethod::Broyden {
            return self.solve_broyden(plant, op, x, warm.is_some());
        }
        // Newton with the exact Jacobian; from a cold start the step may be
        // taken without descent after 10 halvings (λ < 1e-3) to leave a
        // shallow minimum of the residual norm.
        let nopts = NewtonOptions {
            ftol: self.opts.tol,
            max_iter: self.opts.max_iter,
            max_halvings: 10,
            accept_no_descent: true,
            ..NewtonOptions::default()
        };
        let mut ws = NewtonWorkspace::new(dim);
        self.run(plant, op, x, |sys, x| {
            newton(sys, x, &mut ws, &nopts)
                .map(|s| (s.iterations, s.residual_norm))
                .map_err(|e| match e {
                    SolveError::SingularJacobian { history, .. } => {
                        ("modified IHB (singular Jacobian)", history)
                    }
                    e => ("modified IHB (Newton)", e.history().to_vec()),
                })
        })
    }

    /// Package a converged {r, q_p} with min/max ω̄ and the verdict.
    fn finish(
        &self,
        plant: &PlantParams,
        op: &OperatingPoint,
        x: &[f64],
        iterations: usize,
        norm: f64,
    ) -> Result<SteadyState, IvtError> {
        let Some((&r, q)) = x.split_first() else {
            return Err(IvtError::Input {
                name: "unknowns {r, q_p}",
                value: 0.0,
                requirement: "2n + 1 values",
            });
        };
        let mut st = SteadyState {
            op: *op,
            r,
            q: q.to_vec(),
            omega_min: f64::INFINITY,
            omega_max: f64::NEG_INFINITY,
            verdict: Verdict::classify(r, plant.r_max),
            iterations,
            residual_norm: norm,
        };
        for j in 0..128 {
            let w = st.omega_at_tau(2.0 * PI * j as f64 / 128.0);
            st.omega_min = st.omega_min.min(w);
            st.omega_max = st.omega_max.max(w);
        }
        if st.omega_min <= 0.0 {
            return Err(IvtError::Stall {
                theta: f64::NAN,
                omega: st.omega_min,
                r: st.r,
            });
        }
        Ok(st)
    }

    /// Eq. 156–157 by Broyden's method (the crate's generic solver).
    fn solve_broyden(
        &mut self,
        plant: &PlantParams,
        op: &OperatingPoint,
        x: Vec<f64>,
        warm: bool,
    ) -> Result<SteadyState, IvtError> {
        let dim = x.len();
        let mut ws = core::mem::replace(&mut self.broyden, BroydenWorkspace::new(0));
        if !warm {
            ws = BroydenWorkspace::new(dim); // cold: seed with the exact Jacobian
        }
        // Warm starts carry H forward; B is never read, so it is not updated.
        ws.track_jacobian = false;
        let bopts = BroydenOptions {
            tol: self.opts.tol,
            max_iter: self.opts.max_iter,
            ..Default::default()
        };
        let result = self.run(plant, op, x, |sys, x| {
            broyden_solve(sys, x, &mut ws, &bopts)
                .map(|s| (s.iterations, s.residual_norm))
                .map_err(|e| ("modified IHB (Broyden, Eq. 156-157)", e.history().to_vec()))
        });
        // A failed solve leaves no matrix worth carrying to the next point.
        self.broyden = if result.is_ok() {
            ws
        } else {
            BroydenWorkspace::new(dim)
        };
        result
    }

    /// Runs `solver` on the balanced residual from `x`: a convergence
    /// (iterations, ‖R‖) is packaged by [`Self::finish`], a failure (method,
    /// ‖R‖ history) becomes [`IvtError::NoConvergence`].
    fn run(
        &mut self,
        plant: &PlantParams,
        op: &OperatingPoint,
        mut x: Vec<f64>,
        solver: impl FnOnce(
            &mut BalancedResidual<'_>,
            &mut [f64],
        ) -> Result<(usize, f64), (&'static str, Vec<f64>)>,
    ) -> Result<SteadyState, IvtError> {
        let mut sys = BalancedResidual {
            solver: self,
            plant,
            op,
        };
        match solver(&mut sys, &mut x) {
            Ok((iterations, norm)) => self.finish(plant, op, &x, iterations, norm),
            Err((method, history)) => Err(IvtError::NoConvergence {
                method,
                iterations: history.len().saturating_sub(1),
                history,
            }),
        }
    }
}

/// One-shot convenience: plan and solve with `opts`.
///
/// # Errors
/// As [`IhbSolver::solve`].
pub fn solve_steady_state(
    plant: &PlantParams,
    op: &OperatingPoint,
    opts: IhbOptions,
) -> Result<SteadyState, IvtError> {
    IhbSolver::new(opts)?.solve(plant, op, None)
}
