//! `[integrator]`, `[encoder]`, `[sensors]` and `[stepper]`: how the plant
//! is integrated and what the controller sees of it.

use super::Invalid;
use ivt_ctrl::SUPPORTED_PPR;
use serde::Deserialize;

fn pos(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

fn nonneg(x: f64) -> bool {
    x.is_finite() && x >= 0.0
}

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
#[serde(deny_unknown_fields)]
pub struct IntegratorSection {
    /// `"dp5"` (adaptive, default) or `"rk4"` (fixed angle step).
    #[serde(default)]
    pub method: IntegratorMethod,
    /// Relative tolerance (dp5; rk4 start-up phase).
    #[serde(default = "default_tol")]
    pub rtol: f64,
    /// Absolute tolerance.
    #[serde(default = "default_tol")]
    pub atol: f64,
    /// Largest angle step of rk4 \[rad\].
    #[serde(default = "default_dtheta")]
    pub dtheta: f64,
    /// Speed above which the angle domain is used \[rad/s\].
    #[serde(default = "default_handover")]
    pub omega_handover: f64,
}

fn default_tol() -> f64 {
    1e-8
}
fn default_dtheta() -> f64 {
    0.02
}
fn default_handover() -> f64 {
    0.5
}

impl Default for IntegratorSection {
    fn default() -> Self {
        Self {
            method: IntegratorMethod::default(),
            rtol: default_tol(),
            atol: default_tol(),
            dtheta: default_dtheta(),
            omega_handover: default_handover(),
        }
    }
}

impl IntegratorSection {
    pub(super) fn validate(&self) -> Result<(), Invalid> {
        for (v, key) in [
            (self.rtol, "integrator.rtol"),
            (self.atol, "integrator.atol"),
        ] {
            Invalid::check(pos(v) && v < 1.0, key, || {
                format!("must be in (0, 1), got {v}")
            })?;
        }
        Invalid::check(
            pos(self.dtheta) && self.dtheta <= 1.0,
            "integrator.dtheta",
            || format!("must be in (0, 1] rad, got {}", self.dtheta),
        )?;
        Invalid::check(
            pos(self.omega_handover),
            "integrator.omega_handover",
            || format!("must be > 0 rad/s, got {}", self.omega_handover),
        )
    }
}

/// `[encoder]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EncoderSection {
    /// Pulses per revolution of θ (one of [`ivt_ctrl::SUPPORTED_PPR`]).
    #[serde(default = "default_ppr")]
    pub ppr: usize,
    /// Timer frequency \[Hz\].
    #[serde(default = "default_f_timer")]
    pub f_timer_hz: f64,
    /// Edge-time jitter (standard deviation) \[s\].
    #[serde(default)]
    pub jitter_s: f64,
}

fn default_ppr() -> usize {
    1200
}
fn default_f_timer() -> f64 {
    1e6
}

impl Default for EncoderSection {
    fn default() -> Self {
        Self {
            ppr: default_ppr(),
            f_timer_hz: default_f_timer(),
            jitter_s: 0.0,
        }
    }
}

impl EncoderSection {
    pub(super) fn validate(&self) -> Result<(), Invalid> {
        Invalid::check(SUPPORTED_PPR.contains(&self.ppr), "encoder.ppr", || {
            format!("must be one of {SUPPORTED_PPR:?}, got {}", self.ppr)
        })?;
        Invalid::check(
            pos(self.f_timer_hz) && self.f_timer_hz <= 1e9,
            "encoder.f_timer_hz",
            || format!("must be in (0, 1e9] Hz, got {}", self.f_timer_hz),
        )?;
        Invalid::check(nonneg(self.jitter_s), "encoder.jitter_s", || {
            format!("must be ≥ 0 s, got {}", self.jitter_s)
        })
    }
}

/// `[sensors]`: the slow readings given to `update_inputs`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SensorsSection {
    /// Sampling period \[s\].
    #[serde(default = "default_sensor_period")]
    pub period_s: f64,
    /// V_m noise (std) \[V\].
    #[serde(default)]
    pub v_m_noise: f64,
    /// V_m quantum \[V\].
    #[serde(default)]
    pub v_m_quantum: f64,
    /// T_U noise (std) \[N·m\].
    #[serde(default)]
    pub t_u_noise: f64,
    /// T_U quantum \[N·m\].
    #[serde(default)]
    pub t_u_quantum: f64,
}

fn default_sensor_period() -> f64 {
    0.01
}

impl Default for SensorsSection {
    fn default() -> Self {
        Self {
            period_s: default_sensor_period(),
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
        Invalid::check(pos(self.period_s), "sensors.period_s", || {
            format!("must be > 0 s, got {}", self.period_s)
        })?;
        for (v, key) in [
            (self.v_m_noise, "sensors.v_m_noise"),
            (self.v_m_quantum, "sensors.v_m_quantum"),
            (self.t_u_noise, "sensors.t_u_noise"),
            (self.t_u_quantum, "sensors.t_u_quantum"),
        ] {
            Invalid::check(nonneg(v), key, || {
                format!("must be finite and ≥ 0, got {v}")
            })?;
        }
        Ok(())
    }
}

/// `[stepper]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StepperSection {
    /// (Micro)steps per revolution of the stepper (Eq. 185 map).
    #[serde(default = "default_steps_per_rev")]
    pub steps_per_rev: f64,
    /// Largest step rate \[steps/s\].
    #[serde(default = "default_max_speed")]
    pub max_speed: f64,
    /// Acceleration \[steps/s²\].
    #[serde(default = "default_accel")]
    pub accel: f64,
    /// Probability that a step is lost.
    #[serde(default)]
    pub miss_prob: f64,
}

fn default_steps_per_rev() -> f64 {
    3200.0
}
fn default_max_speed() -> f64 {
    4000.0
}
fn default_accel() -> f64 {
    40_000.0
}

impl Default for StepperSection {
    fn default() -> Self {
        Self {
            steps_per_rev: default_steps_per_rev(),
            max_speed: default_max_speed(),
            accel: default_accel(),
            miss_prob: 0.0,
        }
    }
}

impl StepperSection {
    pub(super) fn validate(&self) -> Result<(), Invalid> {
        Invalid::check(pos(self.steps_per_rev), "stepper.steps_per_rev", || {
            format!("must be > 0, got {}", self.steps_per_rev)
        })?;
        Invalid::check(pos(self.max_speed), "stepper.max_speed", || {
            format!("must be > 0 steps/s, got {}", self.max_speed)
        })?;
        Invalid::check(pos(self.accel), "stepper.accel", || {
            format!("must be > 0 steps/s², got {}", self.accel)
        })?;
        Invalid::check(
            (0.0..=1.0).contains(&self.miss_prob),
            "stepper.miss_prob",
            || format!("must be in [0, 1], got {}", self.miss_prob),
        )
    }
}
