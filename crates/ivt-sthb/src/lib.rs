#![doc = include_str!("../README.md")]
//! Spatial and temporal harmonic balance (STHB, thesis §3.3) for the string
//! with geometric nonlinearity, Eq. 103:
//!
//! `ω² w_tt + ω c_d w_t − w_xx − k_d w_x² w_xx − y0 sin(πx) cos t = 0`.
//!
//! The nonlinear term is balanced on an `(N_s − 1) × M_s` grid (Eq. 91–97):
//! the spatial projection is a DST-I (sine basis) or DCT-I (cosine basis) and
//! the temporal one a real FFT, so no modal ODE is derived by hand.
//!
//! * [`StringHb`] — residual Eq. 116 and the exact Jacobian `J = J_lin − S_T`
//!   (Eq. 115–125) from the Toeplitz form of the balanced partial derivatives.
//! * [`StringHb::solve`] — Newton–Raphson; [`spring`] — the spring boundary
//!   (§3.3.5) traced with the engine's Broyden continuation as in the thesis.
//! * [`stability`] — Hill's method (Eq. 126–131) and a monodromy matrix of the
//!   same linearization, with the classification stable / fold / period
//!   doubling / Neimark–Sacker.
//! * [`frc`] — curves ‖a‖(ω) (Figs. 34–36) traced by the engine's
//!   exact-Jacobian pseudo-arclength, as the engine's [`ivt_hb::Frc`], in the
//!   branch's invariant subspace (`reduced`: odd harmonics × odd modes, the
//!   Jacobian's block structure in modes × harmonics).
//! * [`modal`] — the "traditional route": the Galerkin modal ODEs derived in
//!   closed form, used as an independent reference in tests and benches.
//!
//! # Temporal basis
//! The thesis uses complex exponentials `a_m, m = −M..M`. We use the real basis
//! `{1, cos kt, sin kt}` (`k = 1..M`): `a_0 = A_0`, `a_{±k} = (A^c_k ∓ j A^s_k)/2`.
//! The real equations are `R^c_k = 2 Re R_k`, `R^s_k = −2 Im R_k`, an invertible
//! linear map of the complex ones, so zeros, Newton iterates and the Jacobian's
//! singularity are the same; the Toeplitz blocks `S_m` of Eq. 99 map to the real
//! blocks in [`toeplitz`]. The norm reported for Figs. 34–35 is the Euclidean
//! norm of the complex `a` (Eq. 114), see [`StringHb::complex_norm`].

pub mod frc;
mod hb;
pub mod modal;
mod reduced;
mod spatial;
pub mod spring;
pub mod stability;
pub mod toeplitz;

pub use hb::StringHb;

use ivt_hb::HbError;

/// Boundary condition at `x = 1` (`w(0, t) = 0` always).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Boundary {
    /// Fixed–fixed string, Eq. 104; trial functions `sin nπx`.
    Fixed,
    /// Spring `k0 w(1) = w_x(1)`, Eq. 132, by the spectral Tau method (Eq. 133–136):
    /// trial functions `sin nπx` plus `e(x) = x`, the boundary equation Eq. 134
    /// replacing the last test function.
    Spring {
        /// Spring stiffness `k0`.
        k0: f64,
    },
}

/// Parameters of Eq. 103 and of its discretization. Defaults are those of §3.3.4.
#[derive(Clone, Debug, PartialEq)]
pub struct StringParams {
    /// Nonlinear stiffness `k_d` (10 weak, 30 strong).
    pub kd: f64,
    /// Damping `c_d`.
    pub cd: f64,
    /// Excitation amplitude `y0`.
    pub y0: f64,
    /// Number of sine trial functions `N`.
    pub modes: usize,
    /// Number of harmonics `M`.
    pub harmonics: usize,
    /// Spatial grid `N_s` (points `x_k = k/N_s`); needs `N_s > 2N` for the exact Jacobian.
    pub ns: usize,
    /// Temporal samples `M_s`; needs `M_s > 2M`.
    pub ms: usize,
    /// Boundary condition at `x = 1`.
    pub boundary: Boundary,
}

impl Default for StringParams {
    fn default() -> Self {
        Self {
            kd: 10.0,
            cd: 0.8,
            y0: 0.5,
            modes: 5,
            harmonics: 19,
            ns: 64,
            ms: 128,
            boundary: Boundary::Fixed,
        }
    }
}

impl StringParams {
    /// Check sizes and values; STHB needs `N_s > 2N` and `M_s > 2M`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] naming the offending parameter.
    pub fn validate(&self) -> Result<(), HbError> {
        let bad = |m: String| Err(HbError::InvalidInput(m));
        if self.modes == 0 || self.harmonics == 0 {
            return bad("modes and harmonics must be at least 1".into());
        }
        if let Some(why) = ivt_hb::limits::unknowns_error(self.modes, self.harmonics) {
            return bad(why);
        }
        // The space–time grid holds ns·ms samples.
        if self.ns.saturating_mul(self.ms) > ivt_hb::limits::MAX_SAMPLES {
            return bad(format!(
                "ns·ms = {}·{} exceeds the limit of {} space–time samples",
                self.ns,
                self.ms,
                ivt_hb::limits::MAX_SAMPLES
            ));
        }
        if self.ns <= 2 * self.modes + 1 {
            return bad(format!(
                "ns = {} must exceed 2·modes + 1 = {} (spatial products of the Jacobian)",
                self.ns,
                2 * self.modes + 1
            ));
        }
        if self.ms <= 2 * self.harmonics + 1 {
            return bad(format!(
                "ms = {} must exceed 2·harmonics + 1 = {}",
                self.ms,
                2 * self.harmonics + 1
            ));
        }
        for (name, v) in [("kd", self.kd), ("cd", self.cd), ("y0", self.y0)] {
            if !v.is_finite() {
                return bad(format!("{name} = {v} is not finite"));
            }
        }
        if let Boundary::Spring { k0 } = self.boundary {
            if !k0.is_finite() || (k0 - 1.0).abs() < 1e-12 {
                return bad(format!(
                    "k0 = {k0} must be finite and ≠ 1 (Eq. 134 loses q_(N+1))"
                ));
            }
        }
        Ok(())
    }
}
