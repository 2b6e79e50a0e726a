//! `[outputs]`: what is computed and written, how the scene is answered, and
//! the output-size cap.

use super::Invalid;
use crate::record::{Channel, Panel};
use serde::{Deserialize, Serialize};

/// How a scene is answered (see [`crate::steady`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Route {
    /// The periodic steady state by the modified IHB, no transient.
    IhbSteadyState,
    /// Closed-loop time integration of the scene.
    TimeIntegration,
}

impl Route {
    /// The name used in scenes, the CLI and the summary.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::IhbSteadyState => "ihb_steady_state",
            Self::TimeIntegration => "time_integration",
        }
    }

    /// The route with this name (`"auto"` and unknown names give None).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "ihb_steady_state" => Some(Self::IhbSteadyState),
            "time_integration" => Some(Self::TimeIntegration),
            _ => None,
        }
    }
}

/// `[outputs] route`: a route, or `"auto"` (the default).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum RouteRequest {
    /// The IHB steady state when the scene asks only for steady-state
    /// metrics ([`super::Scene::ihb_route_blocker`]), else time integration.
    #[default]
    Auto,
    /// Forced [`Route::IhbSteadyState`].
    IhbSteadyState,
    /// Forced [`Route::TimeIntegration`].
    TimeIntegration,
}

impl RouteRequest {
    /// The forced route (None for `"auto"`).
    #[must_use]
    pub fn forced(self) -> Option<Route> {
        match self {
            Self::Auto => None,
            Self::IhbSteadyState => Some(Route::IhbSteadyState),
            Self::TimeIntegration => Some(Route::TimeIntegration),
        }
    }
}

/// One logged channel group.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ChannelSpec {
    /// The channel, by name ([`Channel::name`]).
    pub name: Channel,
    /// Keep every n-th sample (pulses; sensor samples for `"sensors"`).
    #[serde(default = "default_every")]
    pub every: usize,
}

fn default_every() -> usize {
    1
}

/// Default of `[outputs] max_bytes`: 1 GB.
pub const DEFAULT_MAX_BYTES: f64 = 1e9;

/// `[outputs]`: only what is named here is computed and written.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct OutputsSection {
    /// Write `<name>.mcap` with the channels.
    pub mcap: bool,
    /// Write one `<name>_<channel>.csv` per channel.
    pub csv: bool,
    /// Write `<name>_summary.json`.
    pub summary: bool,
    /// Plots to draw into `<name>.png`, one panel each, by name
    /// ([`Panel::name`]).
    pub plots: Vec<Panel>,
    /// Logged channel groups.
    pub channels: Vec<ChannelSpec>,
    /// Ask for the steady-state metrics at the scene's (constant) inputs:
    /// mean speed ω_a, min/max ω over a revolution, the r held, r̄ and the
    /// feasibility verdict (see [`crate::steady`]).
    pub steady_state: bool,
    /// How the scene is answered: `"auto"` (default), `"ihb_steady_state"`
    /// or `"time_integration"` (forced).
    pub route: RouteRequest,
    /// Largest estimated size of the recorded channels \[bytes\]
    /// ([`super::Scene::estimated_output_bytes`]); a scene above it is
    /// refused before it runs.
    pub max_bytes: f64,
}

impl Default for OutputsSection {
    fn default() -> Self {
        Self {
            mcap: false,
            csv: false,
            summary: false,
            plots: vec![],
            channels: vec![],
            steady_state: false,
            route: RouteRequest::default(),
            max_bytes: DEFAULT_MAX_BYTES,
        }
    }
}

impl OutputsSection {
    /// Decimation of `channel` (`every` n-th sample), `None` if not logged.
    #[must_use]
    pub fn every(&self, channel: Channel) -> Option<usize> {
        self.channels
            .iter()
            .find(|c| c.name == channel)
            .map(|c| c.every)
    }

    pub(super) fn validate(&self) -> Result<(), Invalid> {
        for (k, ch) in self.channels.iter().enumerate() {
            let at = |field: &str| format!("outputs.channels[{k}].{field}");
            Invalid::check(ch.every >= 1, at("every"), || "must be ≥ 1".into())?;
            Invalid::check(
                !self.channels.iter().take(k).any(|c| c.name == ch.name),
                at("name"),
                || format!("\"{}\" is listed twice", ch.name.name()),
            )?;
        }
        super::keys::check("outputs.max_bytes", self.max_bytes)
    }
}
