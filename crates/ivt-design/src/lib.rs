#![doc = include_str!("../README.md")]
// Dense kernels index several arrays with the same row/column counters; iterator
// chains would hide the matrix structure the equations are written in.
#![allow(clippy::needless_range_loop)]
//! IVT design tools (thesis §4.2–4.3): the periodic steady state of Eq. 151
//! at a prescribed mean speed ω0, the open-loop law `u_ol(V_m, T_U)` built from
//! it, and the local stability of the integral time-delay feedback Eq. 171.
//!
//! One job per module:
//! - [`pieces`]: the smooth pieces of θ for the order-6 Runge–Kutta of
//!   [`ivt_num`] (the corners of `f` at π/4 + kπ/2 are step ends);
//! - [`shooting`]: the independent reference — Eq. 162 integrated in θ with
//!   Newton on (ω(0), r) through the variational equations;
//! - [`steady`]: the modified IHB of Eq. 152–157, unknowns {r, q_p};
//! - [`polish`]: r̄ accurate by default (IHB seed, θ-shooting polish) with an
//!   error estimate;
//! - [`sweep`]: r̄ over a (V_m, T_U) grid, warm starts along rows, rayon across rows;
//! - [`fit`]: least-squares refit of the Eq. 158 form and of the Eq. 159 boundary;
//! - [`open_loop`]: the whole refit in one call (sweep, fit, boundaries, ω_a errors);
//! - [`delay`]: Eq. 174 (Appendix B) discretized by the Chebyshev spectral Tau
//!   method (Eq. 175–179, Appendix C) and its monodromy matrix;
//! - [`gains`]: the gain-design helper.
//!
//! Units are SI inside: rad/s, m, V, N·m. rpm only through [`rpm_to_rad_s`].

pub mod delay;
pub mod delay_sim;
pub mod fit;
pub mod gains;
pub mod identify;
pub mod open_loop;
pub mod pieces;
pub mod polish;
pub mod shooting;
pub mod steady;
pub mod sweep;

use ivt_kin::plant::{ParamError, PlantParams};

pub use ivt_kin::units::{rad_s_to_rpm, rpm_to_rad_s};

/// The thesis's target mean speed, ω0 = 100 rpm (§4.2.1), in rad/s.
pub fn thesis_omega0() -> f64 {
    rpm_to_rad_s(100.0)
}

/// One operating point: motor voltage, brake torque and target mean speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OperatingPoint {
    /// Motor supply voltage V_m \[V\].
    pub v_m: f64,
    /// Brake torque T_U \[N·m\].
    pub t_u: f64,
    /// Target time-mean of ω, ω0 \[rad/s\].
    pub omega0: f64,
}

impl OperatingPoint {
    /// Point at ω0 = 100 rpm, the thesis's target.
    pub fn at_100_rpm(v_m: f64, t_u: f64) -> Self {
        Self {
            v_m,
            t_u,
            omega0: thesis_omega0(),
        }
    }

    /// Reject NaN/inf inputs and a non-positive ω0.
    ///
    /// # Errors
    /// [`IvtError::Input`] naming the offending field.
    pub fn validate(&self) -> Result<(), IvtError> {
        finite("v_m", self.v_m)?;
        finite("t_u", self.t_u)?;
        if !(self.omega0.is_finite() && self.omega0 > 0.0) {
            return Err(IvtError::Input {
                name: "omega0",
                value: self.omega0,
                requirement: "finite and > 0",
            });
        }
        Ok(())
    }
}

fn finite(name: &'static str, value: f64) -> Result<(), IvtError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(IvtError::Input {
            name,
            value,
            requirement: "finite",
        })
    }
}

/// Where the unconstrained r̄ lies relative to the mechanism's range [0, r_max] (§4.2.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// r̄ < 0: even r = 0 leaves the motor slower than ω0 (not enough voltage).
    UnderDrive,
    /// 0 ≤ r̄ ≤ r_max: the target is reachable.
    Feasible,
    /// r̄ > r_max: even r_max leaves the motor faster than ω0 (§4.2.1 "over-drive").
    OverDrive,
}

impl Verdict {
    /// Classify r̄ against [0, r_max].
    pub fn classify(r_bar: f64, r_max: f64) -> Self {
        if r_bar < 0.0 {
            Self::UnderDrive
        } else if r_bar > r_max {
            Self::OverDrive
        } else {
            Self::Feasible
        }
    }

    /// Stable lower-case name for JSON/CLI output.
    pub fn as_str(&self) -> &'static str {
        match self {
            Self::UnderDrive => "under-drive",
            Self::Feasible => "feasible",
            Self::OverDrive => "over-drive",
        }
    }
}

/// Failures of the design tools.
#[derive(Debug, thiserror::Error)]
pub enum IvtError {
    /// An input that is NaN/inf or out of its range.
    #[error("invalid input `{name}` = {value:?}: must be {requirement}")]
    Input {
        /// Name of the argument.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What it must satisfy.
        requirement: &'static str,
    },
    /// A plant parameter out of range.
    #[error("{0}")]
    Plant(#[from] ParamError),
    /// A grid with no points.
    #[error("empty grid: {0}")]
    EmptyGrid(&'static str),
    /// The speed reached zero or became non-finite: the torque cannot keep the
    /// IVT turning at this r (Eq. 162 needs ω > 0, Prop. 2).
    #[error("stall: ω = {omega:?} rad/s at θ = {theta:?} rad with r = {r:?} m")]
    Stall {
        /// Angle where it happened.
        theta: f64,
        /// Speed there.
        omega: f64,
        /// Eccentricity in use.
        r: f64,
    },
    /// An iterative solver that did not reach its tolerance.
    #[error("{method} did not converge in {iterations} iterations; residual history {history:?}")]
    NoConvergence {
        /// Which solver.
        method: &'static str,
        /// Iterations spent.
        iterations: usize,
        /// Residual norm after each iteration.
        history: Vec<f64>,
    },
    /// Every point of a map failed: there is no answer to report.
    #[error("every one of the {points} points failed (first: {first})")]
    AllFailed {
        /// Points attempted.
        points: usize,
        /// Why the first one failed.
        first: String,
    },
}

impl IvtError {
    /// `Ok` when at least one of these per-point results is solved, else
    /// [`IvtError::AllFailed`] with the first failure: a sweep or map of
    /// failures has no answer to report.
    ///
    /// # Errors
    /// [`IvtError::AllFailed`] when every result is an error (or there are none).
    pub fn unless_some_solved<'a, T: 'a>(
        results: impl Iterator<Item = &'a Result<T, String>> + Clone,
    ) -> Result<(), IvtError> {
        if results.clone().any(|r| r.is_ok()) {
            return Ok(());
        }
        let points = results.clone().count();
        Err(IvtError::AllFailed {
            points,
            first: results
                .filter_map(|r| r.as_ref().err())
                .next()
                .cloned()
                .unwrap_or_default(),
        })
    }
}

/// Validate the plant once at every public entry point.
pub(crate) fn check_plant(plant: &PlantParams) -> Result<(), IvtError> {
    plant.validate().map_err(IvtError::from)
}

/// Averaged power balance (SPEC §5): with ω ≈ ω0, ⟨f⟩ = 1 and ⟨f²⟩ ≈ 1.0095,
/// `a V_m = c ω0 + b T_U r` gives the seed r for the exact solvers.
pub fn averaged_r(plant: &PlantParams, op: &OperatingPoint) -> f64 {
    let a = plant.motor_gain();
    let c = plant.motor_damping() * ivt_kin::variant::mean_f_squared();
    let b = plant.load_gain();
    (a * op.v_m - c * op.omega0) / (b * op.t_u.abs().max(1e-3))
}
