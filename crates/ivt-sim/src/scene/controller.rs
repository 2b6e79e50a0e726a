//! `[controller]` (law, gains, feed-forward) and `[metrics]`.

use super::inputs::{knots, profile_ok, within_r_max};
use super::keys::{check_fields, fits_f32, Typed, NOT_F32};
use super::Invalid;
use ivt_ctrl::{LawKind, OpenLoopPreset};
use serde::{Deserialize, Serialize};

/// `[controller] law`.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Law {
    /// Integral law with the one-revolution delay, Eq. 180.
    #[default]
    Delay,
    /// Integral law without the delay, Eq. 181.
    #[serde(rename = "nodelay")]
    NoDelay,
    /// Sampled proportional law, Eq. 189.
    Prop,
    /// u_ol only, Eq. 160.
    Open,
    /// No controller: r follows `r_schedule`.
    None,
}

impl Law {
    /// The name used in scenes and summaries.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Delay => "delay",
            Self::NoDelay => "nodelay",
            Self::Prop => "prop",
            Self::Open => "open",
            Self::None => "none",
        }
    }

    /// The ivt-ctrl law (None for `"none"`: no controller runs).
    #[must_use]
    pub fn kind(self) -> Option<LawKind> {
        match self {
            Self::Delay => Some(LawKind::Delay),
            Self::NoDelay => Some(LawKind::NoDelay),
            Self::Prop => Some(LawKind::Prop),
            Self::Open => Some(LawKind::Open),
            Self::None => None,
        }
    }
}

/// `[controller] open_loop`: the coefficient set of u_ol (Eq. 158–160).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum OpenLoopLaw {
    /// Refitted on the printed plant by `ivt ol fit` (SPEC §5).
    #[default]
    Refit,
    /// Eq. 158–160 as printed.
    Thesis,
}

impl From<OpenLoopLaw> for OpenLoopPreset {
    fn from(o: OpenLoopLaw) -> Self {
        match o {
            OpenLoopLaw::Refit => Self::Refit,
            OpenLoopLaw::Thesis => Self::Thesis,
        }
    }
}

/// `[controller]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct ControllerSection {
    /// `"delay"` (Eq. 180), `"nodelay"` (Eq. 181), `"prop"` (Eq. 189),
    /// `"open"` (u_ol only, Eq. 160) or `"none"` (r from `r_schedule`, no controller).
    pub law: Law,
    /// Target ω0 \[rpm\].
    pub omega0_rpm: f64,
    /// k of Eq. 180/181 in the thesis's "mm·rad⁻¹" (ivt-ctrl `units`: ×1e-3 → m·s/rad²).
    pub k_mm_per_rad: f64,
    /// k2 of Eq. 180/181 in "mm·rad⁻¹".
    pub k2_mm_per_rad: f64,
    /// K of Eq. 189 \[deg of stepper per rpm\].
    pub k_prop_deg_per_rpm: f64,
    /// Sample period of Eq. 189 \[s\].
    pub prop_period_s: f64,
    /// Add u_ol (Eq. 160) to r.
    pub feedforward: bool,
    /// Open-loop coefficients: `"refit"` (default) or `"thesis"`.
    pub open_loop: OpenLoopLaw,
    /// r(t) for `law = "none"`: `[[t, r], ...]` \[s, m\].
    #[serde(deserialize_with = "knots")]
    pub r_schedule: Vec<[f64; 2]>,
}

impl Default for ControllerSection {
    fn default() -> Self {
        Self {
            law: Law::default(),
            omega0_rpm: 100.0,
            k_mm_per_rad: 1.0,
            k2_mm_per_rad: 2.0,
            k_prop_deg_per_rpm: 50.0,
            prop_period_s: 0.1,
            feedforward: true,
            open_loop: OpenLoopLaw::default(),
            r_schedule: vec![],
        }
    }
}

impl ControllerSection {
    pub(super) fn validate(&self, r_max: f64) -> Result<(), Invalid> {
        check_fields!(
            self,
            "controller",
            omega0_rpm,
            k_mm_per_rad,
            k2_mm_per_rad,
            k_prop_deg_per_rpm,
            prop_period_s
        )?;
        if self.law == Law::None {
            Invalid::check(!self.r_schedule.is_empty(), "controller.r_schedule", || {
                "is required when law = \"none\"".into()
            })?;
        }
        if !self.r_schedule.is_empty() {
            // the controller holds r as an f32
            let r_ok = |r: f64| {
                if fits_f32(r) {
                    within_r_max(r, r_max)
                } else {
                    Err(format!("= {} m {NOT_F32}", Typed(r)))
                }
            };
            profile_ok(&self.r_schedule, "controller.r_schedule", r_ok)?;
        }
        Ok(())
    }
}

/// `[metrics]`: how the summary is measured on ω_a (exact, from the
/// simulated pulse times).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct MetricsSection {
    /// Metrics use t ≥ from_s only \[s\] (at or past `duration_s` the
    /// window is empty and the summary's metrics are null with a reason).
    pub from_s: f64,
    /// Settling band, relative to ω0.
    pub band: f64,
    /// Static error = mean(ω_a − ω0) over the last `static_window_s` \[s\].
    pub static_window_s: f64,
}

impl Default for MetricsSection {
    fn default() -> Self {
        Self {
            from_s: 0.0,
            band: 0.02,
            static_window_s: 2.0,
        }
    }
}

impl MetricsSection {
    pub(super) fn validate(&self) -> Result<(), Invalid> {
        check_fields!(self, "metrics", from_s, band, static_window_s)
    }
}
