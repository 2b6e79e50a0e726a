//! `[integrator]`, `[encoder]`, `[sensors]` and `[stepper]`: how the plant
//! is integrated and what the controller sees of it.

use super::keys::check_fields;
use super::Invalid;
use ivt_ctrl::SUPPORTED_PPR;
use serde::Deserialize;

/// `[integrator] method`.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorMethod {
    /// Adaptive Dormand–Prince 5(4).
    #[default]
    Dp5,
    /// Classic RK4 with a fixed largest angle step (`dtheta`).
    Rk4,
}

/// `[integrator]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct IntegratorSection {
    /// `"dp5"` (adaptive, default) or `"rk4"` (fixed angle step).
    pub method: IntegratorMethod,
    /// Relative tolerance (dp5; rk4 start-up phase).
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Largest angle step of rk4 \[rad\].
    pub dtheta: f64,
    /// Speed above which the angle domain is used \[rad/s\].
    pub omega_handover: f64,
}

impl Default for IntegratorSection {
    fn default() -> Self {
        Self {
            method: IntegratorMethod::default(),
            rtol: 1e-8,
            atol: 1e-8,
            dtheta: 0.02,
            omega_handover: 0.5,
        }
    }
}

impl IntegratorSection {
    pub(super) fn validate(&self) -> Result<(), Invalid> {
        check_fields!(self, "integrator", rtol, atol, dtheta, omega_handover)
    }
}

/// `[encoder]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct EncoderSection {
    /// Pulses per revolution of θ (one of [`ivt_ctrl::SUPPORTED_PPR`]).
    pub ppr: usize,
    /// Timer frequency \[Hz\].
    pub f_timer_hz: f64,
    /// Edge-time jitter (standard deviation) \[s\].
    pub jitter_s: f64,
}

impl Default for EncoderSection {
    fn default() -> Self {
        Self {
            ppr: 1200,
            f_timer_hz: 1e6,
            jitter_s: 0.0,
        }
    }
}

impl EncoderSection {
    pub(super) fn validate(&self) -> Result<(), Invalid> {
        Invalid::check(SUPPORTED_PPR.contains(&self.ppr), "encoder.ppr", || {
            format!("must be one of {SUPPORTED_PPR:?}, got {}", self.ppr)
        })?;
        check_fields!(self, "encoder", f_timer_hz, jitter_s)
    }
}

/// `[sensors]`: the slow readings given to `update_inputs`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct SensorsSection {
    /// Sampling period \[s\].
    pub period_s: f64,
    /// V_m noise (std) \[V\].
    pub v_m_noise: f64,
    /// V_m quantum \[V\].
    pub v_m_quantum: f64,
    /// T_U noise (std) \[N·m\].
    pub t_u_noise: f64,
    /// T_U quantum \[N·m\].
    pub t_u_quantum: f64,
}

impl Default for SensorsSection {
    fn default() -> Self {
        Self {
            period_s: 0.01,
            v_m_noise: 0.0,
            v_m_quantum: 0.0,
            t_u_noise: 0.0,
            t_u_quantum: 0.0,
        }
    }
}

impl SensorsSection {
    /// True if any reading is noisy or quantized.
    #[must_use]
    pub fn disturbed(&self) -> bool {
        self.v_m_noise > 0.0
            || self.t_u_noise > 0.0
            || self.v_m_quantum > 0.0
            || self.t_u_quantum > 0.0
    }

    pub(super) fn validate(&self) -> Result<(), Invalid> {
        check_fields!(
            self,
            "sensors",
            period_s,
            v_m_noise,
            v_m_quantum,
            t_u_noise,
            t_u_quantum
        )
    }
}

/// `[stepper]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct StepperSection {
    /// (Micro)steps per revolution of the stepper (Eq. 185 map).
    pub steps_per_rev: f64,
    /// Largest step rate \[steps/s\].
    pub max_speed: f64,
    /// Acceleration \[steps/s²\].
    pub accel: f64,
    /// Probability that a step is lost.
    pub miss_prob: f64,
}

impl Default for StepperSection {
    fn default() -> Self {
        Self {
            steps_per_rev: 3200.0,
            max_speed: 4000.0,
            accel: 40_000.0,
            miss_prob: 0.0,
        }
    }
}

impl StepperSection {
    pub(super) fn validate(&self) -> Result<(), Invalid> {
        check_fields!(self, "stepper", steps_per_rev, max_speed, accel, miss_prob)
    }
}
