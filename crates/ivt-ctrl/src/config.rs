//! The controller's configuration: the feedback law, its gains (SI) and
//! every limit, with the thesis setup as `Config::default()`.

use crate::actuator::{ActuatorMap, StepperLimits};
use crate::open_loop::{OpenLoopCoeffs, REFIT};
use crate::units;

/// Which feedback law runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LawKind {
    /// Integral time-delay law, Eq. 180.
    #[default]
    Delay,
    /// No-delay law, Eq. 181.
    NoDelay,
    /// Proportional increment at a fixed period, Eq. 189.
    Prop,
    /// Open loop only, Eq. 160.
    Open,
}

/// Gains in SI. Build from the thesis's printed values with
/// [`Gains::from_thesis_mm_per_rad`] (the unit interpretation is in [`crate::units`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains {
    /// k of Eq. 180/181 \[m·s/rad²\].
    pub k: f32,
    /// k2 of Eq. 180/181 \[m·s/rad² for Eq. 180, m·s/rad for Eq. 181\].
    pub k2: f32,
    /// K_r of Eq. 189 in eccentricity \[m per rad/s\].
    pub k_prop: f32,
    /// Sample period of Eq. 189 \[s\].
    pub prop_period_s: f32,
}

impl Gains {
    /// Gains from the thesis's printed "mm·rad⁻¹" values (e.g. 0.01, 0.02 for
    /// Eq. 180); the Eq. 189 part is K = 50 deg/rpm every 0.1 s.
    #[must_use]
    pub fn from_thesis_mm_per_rad(k: f32, k2: f32) -> Self {
        Self {
            k: units::gain_from_mm_per_rad(k),
            k2: units::gain_from_mm_per_rad(k2),
            ..Self::default()
        }
    }
}

impl Default for Gains {
    /// Eq. 180 with k = 0.01, k2 = 0.02 mm·rad⁻¹ (§4.3, Fig. 42), Eq. 189 with
    /// K = 50 (§4.4.3) and a 0.1 s sample period (the thesis gives none: an
    /// assumption, configurable).
    fn default() -> Self {
        Self {
            k: units::gain_from_mm_per_rad(0.01),
            k2: units::gain_from_mm_per_rad(0.02),
            k_prop: units::prop_gain_from_deg_per_rpm(units::THESIS_PROP_K_DEG_PER_RPM),
            prop_period_s: 0.1,
        }
    }
}

/// Everything a controller needs; `Config::default()` is the thesis setup
/// (100 rpm, PPR from the type, 1 MHz timer, Eq. 180 with the Fig. 42 gains,
/// SGIVT actuator map with 3200 steps/rev) with the open-loop law refitted on
/// the printed plant ([`REFIT`], SPEC §5: the printed `THESIS` polynomial does
/// not hold ω0 on the printed plant and stays selectable as a preset).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// Timer frequency of the timestamps \[Hz\].
    pub f_timer_hz: f32,
    /// Target speed ω0 \[rad/s\].
    pub omega0: f32,
    /// Encoder pulses per controller sample (≥ 1): the encoder has
    /// `PPR·decimation` pulses per revolution and the law runs on every
    /// `decimation`-th one (RAM for resolution).
    pub decimation: u16,
    /// The feedback law.
    pub law: LawKind,
    /// Gains (SI).
    pub gains: Gains,
    /// Open-loop coefficients (Eq. 158–160); also gives r_max.
    pub open_loop: OpenLoopCoeffs,
    /// Add u_ol to r (true: Eq. 180/181; false: r = r_d alone, as the
    /// driving test of §4.4.3 ran Eq. 189 without feed-forward).
    pub feedforward: bool,
    /// Eccentricity → stepper position.
    pub actuator: ActuatorMap,
    /// Stepper speed/acceleration limits.
    pub stepper: StepperLimits,
    /// No pulse for this long → `Fault::Stall` \[s\].
    pub stall_timeout_s: f32,
    /// Pulse intervals shorter than this speed implies are rejected \[rad/s\].
    pub omega_max: f32,
    /// Eccentricity commanded in the stall/config safe state \[m\].
    pub safe_r: f32,
    /// Plausible V_m sensor range \[V\]; outside → `Fault::InputInvalid`.
    pub v_m_valid: [f32; 2],
    /// Plausible T_U sensor range \[N·m\]; outside → `Fault::InputInvalid`.
    pub t_u_valid: [f32; 2],
    /// Inputs assumed until the first valid `update_inputs` (V, N·m): the
    /// §4.3 scene's 8 V / 8 N·m.
    pub initial_inputs: [f32; 2],
}

impl Default for Config {
    fn default() -> Self {
        Self {
            f_timer_hz: 1.0e6,
            omega0: units::rpm_to_rad_s(100.0),
            decimation: 1,
            law: LawKind::Delay,
            gains: Gains::default(),
            open_loop: REFIT,
            feedforward: true,
            actuator: ActuatorMap::sgivt(3200.0),
            stepper: StepperLimits {
                max_speed: 4000.0,
                accel: 40_000.0,
            },
            stall_timeout_s: 0.5,
            omega_max: 200.0,
            safe_r: 0.0,
            v_m_valid: [-1.0, 48.0],
            t_u_valid: [-1.0, 50.0],
            initial_inputs: [8.0, 8.0],
        }
    }
}

impl Config {
    pub(crate) fn is_valid(&self, ppr: usize) -> bool {
        let pos = |x: f32| x.is_finite() && x > 0.0;
        let ordered = |r: [f32; 2]| r[0].is_finite() && r[1].is_finite() && r[0] <= r[1];
        (1..=1 << 20).contains(&ppr)
            && pos(self.f_timer_hz)
            && pos(self.omega0)
            && pos(self.omega_max)
            && pos(self.stall_timeout_s)
            && self.decimation >= 1
            && self.gains.k.is_finite()
            && self.gains.k2.is_finite()
            && self.gains.k_prop.is_finite()
            && pos(self.gains.prop_period_s)
            && self.open_loop.is_valid()
            && self.actuator.is_valid()
            && self.stepper.is_valid()
            && self.safe_r.is_finite()
            && ordered(self.v_m_valid)
            && ordered(self.t_u_valid)
    }
}
