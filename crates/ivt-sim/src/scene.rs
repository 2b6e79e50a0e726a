//! Scenes: a TOML file that says what to simulate and what to keep.
//!
//! Parsing is strict (`deny_unknown_fields`); every error is one line that
//! names the file position and the key. See `scenes/*.toml` for examples and
//! the crate README for the full key list.

use crate::backend::SUPPORTED_PPR;
use ivt_ctrl::OpenLoopPreset;
use ivt_kin::plant::{GravityModel, PlantParams, PlantPreset};
use serde::Deserialize;

/// A scene error: one line, naming the key and (when known) the line.
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
#[error("{0}")]
pub struct SceneError(pub String);

/// The whole scene file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Short name (used in output file names).
    #[serde(default = "default_name")]
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// Simulated time \[s\].
    pub duration_s: f64,
    /// Seed of all sensor noise and missed steps.
    #[serde(default)]
    pub seed: u64,
    /// Plant preset and overrides.
    #[serde(default)]
    pub plant: PlantSection,
    /// Input profiles.
    pub inputs: InputsSection,
    /// Initial state.
    #[serde(default)]
    pub initial: InitialSection,
    /// Integrator choice.
    #[serde(default)]
    pub integrator: IntegratorSection,
    /// Encoder.
    #[serde(default)]
    pub encoder: EncoderSection,
    /// V_m / T_U readings.
    #[serde(default)]
    pub sensors: SensorsSection,
    /// Stepper motor.
    #[serde(default)]
    pub stepper: StepperSection,
    /// Controller.
    #[serde(default)]
    pub controller: ControllerSection,
    /// Summary metrics.
    #[serde(default)]
    pub metrics: MetricsSection,
    /// What to write.
    #[serde(default)]
    pub outputs: OutputsSection,
}

fn default_name() -> String {
    "scene".into()
}

/// `[plant]`: `preset = "printed"` (Table 1) and any parameter of
/// [`PlantParams`] as an override.
#[derive(Clone, Debug, Deserialize, PartialEq, Default)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct PlantSection {
    /// `"printed"` (Table 1, the default) or `"thesis-ch4"` (k_t, k_e ÷ 10): [`PlantPreset`].
    #[serde(default)]
    pub preset: Option<String>,
    /// `"printed"` (G = g(sin θ + cos θ)) or `"roller_mass"` (m_r g, SPEC §5).
    #[serde(default)]
    pub gravity: Option<String>,
    pub r_a: Option<f64>,
    pub k_e: Option<f64>,
    pub k_t: Option<f64>,
    pub l_a: Option<f64>,
    pub j_n1: Option<f64>,
    pub j_n2: Option<f64>,
    pub j_inshaft: Option<f64>,
    pub j_carrier: Option<f64>,
    pub j_ring: Option<f64>,
    pub j_crk: Option<f64>,
    pub m_r: Option<f64>,
    pub m_dr: Option<f64>,
    pub j_u: Option<f64>,
    pub r_u: Option<f64>,
    pub g: Option<f64>,
    pub sun_to_planet: Option<f64>,
    pub r_max: Option<f64>,
}

/// `[inputs]`: piecewise-linear profiles as `[[t, value], ...]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct InputsSection {
    /// Motor voltage V_m(t) \[V\].
    pub v_m: Vec<[f64; 2]>,
    /// Brake torque T_U(t) \[N·m\].
    pub t_u: Vec<[f64; 2]>,
}

/// `[initial]`.
#[derive(Clone, Debug, Deserialize, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct InitialSection {
    /// θ(0) \[rad\].
    #[serde(default)]
    pub theta: f64,
    /// ω(0) \[rad/s\] (0 = start from rest).
    #[serde(default)]
    pub omega: f64,
    /// Eccentricity at t = 0 \[m\] (stepper position).
    #[serde(default)]
    pub r: f64,
}

/// `[integrator]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSection {
    /// `"dp5"` (adaptive) or `"rk4"` (fixed angle step).
    #[serde(default = "default_method")]
    pub method: String,
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

fn default_method() -> String {
    "dp5".into()
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
            method: default_method(),
            rtol: default_tol(),
            atol: default_tol(),
            dtheta: default_dtheta(),
            omega_handover: default_handover(),
        }
    }
}

/// `[encoder]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EncoderSection {
    /// Pulses per revolution of θ (one of the compiled SIL resolutions).
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

/// `[controller]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ControllerSection {
    /// `"delay"` (Eq. 180), `"nodelay"` (Eq. 181), `"prop"` (Eq. 189),
    /// `"open"` (u_ol only, Eq. 160) or `"none"` (r from `r_schedule`, no controller).
    #[serde(default = "default_law")]
    pub law: String,
    /// Target ω0 \[rpm\].
    #[serde(default = "default_omega0")]
    pub omega0_rpm: f64,
    /// k of Eq. 180/181 in the thesis's "mm·rad⁻¹" (ivt-ctrl `units`: ×1e-3 → m·s/rad²).
    #[serde(default = "default_k")]
    pub k_mm_per_rad: f64,
    /// k2 of Eq. 180/181 in "mm·rad⁻¹".
    #[serde(default = "default_k2")]
    pub k2_mm_per_rad: f64,
    /// K of Eq. 189 \[deg of stepper per rpm\].
    #[serde(default = "default_k_prop")]
    pub k_prop_deg_per_rpm: f64,
    /// Sample period of Eq. 189 \[s\].
    #[serde(default = "default_prop_period")]
    pub prop_period_s: f64,
    /// Add u_ol (Eq. 160) to r.
    #[serde(default = "default_true")]
    pub feedforward: bool,
    /// Open-loop coefficients: `"refit"` (default: refitted on the printed
    /// plant by `ivt ol fit`, SPEC §5) or `"thesis"` (Eq. 158–160 as printed).
    #[serde(default = "default_open_loop")]
    pub open_loop: String,
    /// r(t) for `law = "none"`: `[[t, r], ...]` \[s, m\].
    #[serde(default)]
    pub r_schedule: Vec<[f64; 2]>,
}

fn default_law() -> String {
    "delay".into()
}
fn default_omega0() -> f64 {
    100.0
}
fn default_k() -> f64 {
    1.0
}
fn default_k2() -> f64 {
    2.0
}
fn default_k_prop() -> f64 {
    50.0
}
fn default_prop_period() -> f64 {
    0.1
}
fn default_true() -> bool {
    true
}
fn default_open_loop() -> String {
    OpenLoopPreset::default().name().into()
}

impl Default for ControllerSection {
    fn default() -> Self {
        Self {
            law: default_law(),
            omega0_rpm: default_omega0(),
            k_mm_per_rad: default_k(),
            k2_mm_per_rad: default_k2(),
            k_prop_deg_per_rpm: default_k_prop(),
            prop_period_s: default_prop_period(),
            feedforward: true,
            open_loop: default_open_loop(),
            r_schedule: vec![],
        }
    }
}

/// `[metrics]`: how the summary is measured on ω_a (exact, from the
/// simulated pulse times).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MetricsSection {
    /// Metrics use t ≥ from_s only \[s\].
    #[serde(default)]
    pub from_s: f64,
    /// Settling band, relative to ω0.
    #[serde(default = "default_band")]
    pub band: f64,
    /// Static error = mean(ω_a − ω0) over the last `static_window_s` \[s\].
    #[serde(default = "default_static_window")]
    pub static_window_s: f64,
}

fn default_band() -> f64 {
    0.02
}
fn default_static_window() -> f64 {
    2.0
}

impl Default for MetricsSection {
    fn default() -> Self {
        Self {
            from_s: 0.0,
            band: default_band(),
            static_window_s: default_static_window(),
        }
    }
}

/// One logged channel group.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ChannelSpec {
    /// `"plant"`, `"control"`, `"stepper"` or `"sensors"`.
    pub name: String,
    /// Keep every n-th sample (pulses; sensor samples for `"sensors"`).
    #[serde(default = "default_every")]
    pub every: usize,
}

fn default_every() -> usize {
    1
}

/// `[outputs]`: only what is named here is computed and written.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OutputsSection {
    /// Write `<name>.mcap` with the channels.
    #[serde(default)]
    pub mcap: bool,
    /// Write one `<name>_<channel>.csv` per channel.
    #[serde(default)]
    pub csv: bool,
    /// Write `<name>_summary.json`.
    #[serde(default)]
    pub summary: bool,
    /// Plots to draw into `<name>.png`, one panel each: any of `"omega"`,
    /// `"omega_a"`, `"r"`, `"v_m"`, `"t_u"`.
    #[serde(default)]
    pub plots: Vec<String>,
    /// Logged channel groups.
    #[serde(default)]
    pub channels: Vec<ChannelSpec>,
    /// Ask for the steady-state metrics at the scene's (constant) inputs:
    /// mean speed ω_a, min/max ω over a revolution, the r held, r̄ and the
    /// feasibility verdict (see [`crate::steady`]).
    #[serde(default)]
    pub steady_state: bool,
    /// How the scene is answered: `"auto"` (default: the IHB steady state when
    /// the scene asks only for steady-state metrics, see
    /// [`Scene::ihb_route_blocker`], else time integration),
    /// `"ihb_steady_state"` or `"time_integration"` (forced).
    #[serde(default = "default_route")]
    pub route: String,
}

fn default_route() -> String {
    "auto".into()
}

impl OutputsSection {
    /// Decimation of channel `name` (`every` n-th sample), `None` if not logged.
    #[must_use]
    pub fn every(&self, name: &str) -> Option<usize> {
        self.channels
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.every)
    }
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
            route: default_route(),
        }
    }
}

/// Values of `outputs.route`.
pub const ROUTES: [&str; 3] = ["auto", "ihb_steady_state", "time_integration"];

/// Channel groups a scene may log.
pub const CHANNELS: [&str; 4] = ["plant", "control", "stepper", "sensors"];
/// Plot panels a scene may ask for.
pub const PLOTS: [&str; 5] = ["omega", "omega_a", "r", "v_m", "t_u"];
/// Laws a scene may name.
pub const LAWS: [&str; 5] = ["delay", "nodelay", "prop", "open", "none"];

/// The 1-based line of the first `key = ...` in `src` (for validation errors).
fn line_of(src: &str, key: &str) -> Option<usize> {
    let last = key.rsplit('.').next().unwrap_or(key);
    src.lines()
        .position(|l| {
            let l = l.trim_start();
            l.strip_prefix(last)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        })
        .map(|i| i + 1)
}

/// Line of a validation error: for `outputs.channels[k]` errors the k-th
/// `name`/`every` after the first `[[outputs.channels]]`, else [`line_of`].
fn locate(src: &str, key: &str, msg: &str) -> Option<usize> {
    let k: Option<usize> = msg
        .strip_prefix("(outputs.channels[")
        .and_then(|m| m.split(']').next())
        .and_then(|d| d.parse().ok());
    let Some(k) = k else {
        return line_of(src, key);
    };
    let start = src
        .lines()
        .position(|l| l.trim() == "[[outputs.channels]]")?;
    let mut seen = 0;
    let mut table = 0;
    for (i, l) in src.lines().enumerate().skip(start) {
        let t = l.trim_start();
        if t.starts_with("[[outputs.channels]]") {
            table += 1;
        }
        if table == k + 1
            && t.strip_prefix(key)
                .is_some_and(|r| r.trim_start().starts_with('='))
        {
            seen += 1;
            if seen == 1 {
                return Some(i + 1);
            }
        }
    }
    None
}

impl Scene {
    /// Parse and validate a scene. `origin` names the source in errors.
    ///
    /// # Errors
    /// One-line [`SceneError`] naming the position and the key.
    pub fn parse(src: &str, origin: &str) -> Result<Self, SceneError> {
        let scene: Scene = toml::from_str(src).map_err(|e| {
            let line = e
                .span()
                .map(|s| src[..s.start.min(src.len())].matches('\n').count() + 1);
            let msg = e.message().replace('\n', " ");
            match line {
                Some(l) => {
                    let text = src.lines().nth(l - 1).unwrap_or("").trim();
                    SceneError(format!("{origin}:{l}: {} (at `{text}`)", msg.trim()))
                }
                None => SceneError(format!("{origin}: {}", msg.trim())),
            }
        })?;
        scene
            .validate()
            .map_err(|(key, msg)| match locate(src, key, &msg) {
                Some(l) => SceneError(format!("{origin}:{l}: `{key}` {msg}")),
                None => SceneError(format!("{origin}: `{key}` {msg}")),
            })?;
        Ok(scene)
    }

    /// Read and parse a scene file.
    ///
    /// # Errors
    /// I/O or scene errors, one line.
    pub fn load(path: &std::path::Path) -> Result<Self, SceneError> {
        let src = std::fs::read_to_string(path)
            .map_err(|e| SceneError(format!("{}: {e}", path.display())))?;
        Self::parse(&src, &path.display().to_string())
    }

    /// Plant parameters: preset plus overrides.
    ///
    /// # Errors
    /// An unknown preset/gravity or an invalid parameter.
    pub fn plant_params(&self) -> Result<PlantParams, (&'static str, String)> {
        let p = &self.plant;
        let mut params = match p.preset.as_deref() {
            None => PlantParams::printed(),
            Some(name) => PlantPreset::from_name(name)
                .map(PlantPreset::params)
                .ok_or((
                    "plant.preset",
                    format!("must be \"printed\" or \"thesis-ch4\", got \"{name}\""),
                ))?,
        };
        params.gravity = match p.gravity.as_deref() {
            None | Some("printed") => GravityModel::Printed,
            Some("roller_mass") => GravityModel::RollerMass,
            Some(other) => {
                return Err((
                    "plant.gravity",
                    format!("must be \"printed\" or \"roller_mass\", got \"{other}\""),
                ))
            }
        };
        let overrides: [(Option<f64>, &mut f64); 17] = [
            (p.r_a, &mut params.r_a),
            (p.k_e, &mut params.k_e),
            (p.k_t, &mut params.k_t),
            (p.l_a, &mut params.l_a),
            (p.j_n1, &mut params.j_n1),
            (p.j_n2, &mut params.j_n2),
            (p.j_inshaft, &mut params.j_inshaft),
            (p.j_carrier, &mut params.j_carrier),
            (p.j_ring, &mut params.j_ring),
            (p.j_crk, &mut params.j_crk),
            (p.m_r, &mut params.m_r),
            (p.m_dr, &mut params.m_dr),
            (p.j_u, &mut params.j_u),
            (p.r_u, &mut params.r_u),
            (p.g, &mut params.g),
            (p.sun_to_planet, &mut params.sun_to_planet),
            (p.r_max, &mut params.r_max),
        ];
        for (v, slot) in overrides {
            if let Some(v) = v {
                *slot = v;
            }
        }
        params.validate().map_err(|e| {
            let key: &'static str = match e.name {
                "r_a" => "plant.r_a",
                "k_e" => "plant.k_e",
                "k_t" => "plant.k_t",
                "l_a" => "plant.l_a",
                "j_n1" => "plant.j_n1",
                "j_n2" => "plant.j_n2",
                "j_crk" => "plant.j_crk",
                "r_u" => "plant.r_u",
                "r_max" => "plant.r_max",
                "sun_to_planet" => "plant.sun_to_planet",
                "j_inshaft" => "plant.j_inshaft",
                "j_carrier" => "plant.j_carrier",
                "j_ring" => "plant.j_ring",
                "m_r" => "plant.m_r",
                "m_dr" => "plant.m_dr",
                "j_u" => "plant.j_u",
                _ => "plant.g",
            };
            (key, format!("= {} must be {}", e.value, e.requirement))
        })?;
        Ok(params)
    }

    /// Why the scene cannot be answered by the IHB steady state (None: it
    /// can). The IHB route (thesis §4.2.1: the periodic steady state without
    /// the transient) answers exactly what the time integration would settle
    /// to only when the scene asks for nothing but steady-state metrics at
    /// constant inputs, with a law whose equilibrium is the periodic orbit at
    /// constant r, and without random disturbances.
    #[must_use]
    pub fn ihb_route_blocker(&self) -> Option<String> {
        let constant = |p: &[[f64; 2]]| p.iter().all(|k| k[1] == p[0][1]);
        let o = &self.outputs;
        let c = &self.controller;
        let s = &self.sensors;
        if !o.steady_state {
            Some("the scene does not ask for steady-state metrics (outputs.steady_state)".into())
        } else if o.mcap || o.csv || !o.plots.is_empty() || !o.channels.is_empty() {
            Some("the scene asks for channels, plots, MCAP or CSV (a transient)".into())
        } else if !constant(&self.inputs.v_m) || !constant(&self.inputs.t_u) {
            Some("the inputs V_m, T_U are not constant".into())
        } else if c.law == "nodelay" || c.law == "prop" {
            Some(format!(
                "law \"{}\": its equilibrium is not the periodic orbit at constant r (Eq. 181 holds the θ-mean of ω, Eq. 189 samples in time)",
                c.law
            ))
        } else if c.law == "none" && !constant(&c.r_schedule) {
            Some("the r schedule is not constant".into())
        } else if s.v_m_noise > 0.0
            || s.t_u_noise > 0.0
            || s.v_m_quantum > 0.0
            || s.t_u_quantum > 0.0
            || self.encoder.jitter_s > 0.0
            || self.stepper.miss_prob > 0.0
        {
            Some("sensor noise/quantization, encoder jitter or missed steps are set".into())
        } else if self.plant.l_a.is_some_and(|l| l > 0.0) {
            Some("the motor inductance L_a > 0 (the IHB model is Eq. 151 with L_a = 0)".into())
        } else {
            None
        }
    }

    /// All range and consistency checks; `Err((key, message))`.
    fn validate(&self) -> Result<(), (&'static str, String)> {
        fn check(ok: bool, key: &'static str, msg: String) -> Result<(), (&'static str, String)> {
            if ok {
                Ok(())
            } else {
                Err((key, msg))
            }
        }
        let pos = |x: f64| x.is_finite() && x > 0.0;
        let nonneg = |x: f64| x.is_finite() && x >= 0.0;
        check(
            pos(self.duration_s) && self.duration_s <= 1e6,
            "duration_s",
            format!("must be in (0, 1e6] s, got {}", self.duration_s),
        )?;
        let params = self.plant_params()?;
        check(
            params.l_a == 0.0 || params.l_a >= 1e-7,
            "plant.l_a",
            format!(
                "= {} H: below 1e-7 H the current mode (R_a/L_a > 2e6 /s) is too stiff for the explicit integrators; use 0 (Eq. 138)",
                params.l_a
            ),
        )?;
        profile_ok(
            &self.inputs.v_m,
            "inputs.v_m",
            f64::NEG_INFINITY,
            f64::INFINITY,
        )?;
        profile_ok(&self.inputs.t_u, "inputs.t_u", 0.0, f64::INFINITY)?;
        let i = &self.initial;
        check(
            i.theta.is_finite(),
            "initial.theta",
            format!("must be finite, got {}", i.theta),
        )?;
        check(
            nonneg(i.omega),
            "initial.omega",
            format!("must be finite and ≥ 0, got {}", i.omega),
        )?;
        check(
            nonneg(i.r) && i.r <= params.r_max,
            "initial.r",
            format!("must be in [0, r_max = {}] m, got {}", params.r_max, i.r),
        )?;
        let g = &self.integrator;
        check(
            g.method == "dp5" || g.method == "rk4",
            "integrator.method",
            format!("must be \"dp5\" or \"rk4\", got \"{}\"", g.method),
        )?;
        check(
            pos(g.rtol) && g.rtol < 1.0,
            "integrator.rtol",
            format!("must be in (0, 1), got {}", g.rtol),
        )?;
        check(
            pos(g.atol) && g.atol < 1.0,
            "integrator.atol",
            format!("must be in (0, 1), got {}", g.atol),
        )?;
        check(
            pos(g.dtheta) && g.dtheta <= 1.0,
            "integrator.dtheta",
            format!("must be in (0, 1] rad, got {}", g.dtheta),
        )?;
        check(
            pos(g.omega_handover),
            "integrator.omega_handover",
            format!("must be > 0 rad/s, got {}", g.omega_handover),
        )?;
        let e = &self.encoder;
        check(
            SUPPORTED_PPR.contains(&e.ppr),
            "encoder.ppr",
            format!("must be one of {SUPPORTED_PPR:?}, got {}", e.ppr),
        )?;
        check(
            pos(e.f_timer_hz) && e.f_timer_hz <= 1e9,
            "encoder.f_timer_hz",
            format!("must be in (0, 1e9] Hz, got {}", e.f_timer_hz),
        )?;
        check(
            nonneg(e.jitter_s),
            "encoder.jitter_s",
            format!("must be ≥ 0 s, got {}", e.jitter_s),
        )?;
        let s = &self.sensors;
        check(
            pos(s.period_s),
            "sensors.period_s",
            format!("must be > 0 s, got {}", s.period_s),
        )?;
        for (v, k) in [
            (s.v_m_noise, "sensors.v_m_noise"),
            (s.v_m_quantum, "sensors.v_m_quantum"),
            (s.t_u_noise, "sensors.t_u_noise"),
            (s.t_u_quantum, "sensors.t_u_quantum"),
        ] {
            check(nonneg(v), k, format!("must be finite and ≥ 0, got {v}"))?;
        }
        let st = &self.stepper;
        check(
            pos(st.steps_per_rev),
            "stepper.steps_per_rev",
            format!("must be > 0, got {}", st.steps_per_rev),
        )?;
        check(
            pos(st.max_speed),
            "stepper.max_speed",
            format!("must be > 0 steps/s, got {}", st.max_speed),
        )?;
        check(
            pos(st.accel),
            "stepper.accel",
            format!("must be > 0 steps/s², got {}", st.accel),
        )?;
        check(
            (0.0..=1.0).contains(&st.miss_prob),
            "stepper.miss_prob",
            format!("must be in [0, 1], got {}", st.miss_prob),
        )?;
        let c = &self.controller;
        check(
            LAWS.contains(&c.law.as_str()),
            "controller.law",
            format!("must be one of {LAWS:?}, got \"{}\"", c.law),
        )?;
        check(
            pos(c.omega0_rpm) && c.omega0_rpm < 1e4,
            "controller.omega0_rpm",
            format!("must be in (0, 1e4) rpm, got {}", c.omega0_rpm),
        )?;
        for (v, k) in [
            (c.k_mm_per_rad, "controller.k_mm_per_rad"),
            (c.k2_mm_per_rad, "controller.k2_mm_per_rad"),
            (c.k_prop_deg_per_rpm, "controller.k_prop_deg_per_rpm"),
        ] {
            check(v.is_finite(), k, format!("must be finite, got {v}"))?;
        }
        check(
            pos(c.prop_period_s),
            "controller.prop_period_s",
            format!("must be > 0 s, got {}", c.prop_period_s),
        )?;
        check(
            OpenLoopPreset::from_name(&c.open_loop).is_some(),
            "controller.open_loop",
            format!(
                "must be \"refit\" (the default) or \"thesis\", got \"{}\"",
                c.open_loop
            ),
        )?;
        if c.law == "none" {
            check(
                !c.r_schedule.is_empty(),
                "controller.r_schedule",
                "is required when law = \"none\"".into(),
            )?;
        }
        if !c.r_schedule.is_empty() {
            profile_ok(&c.r_schedule, "controller.r_schedule", 0.0, params.r_max)?;
        }
        let m = &self.metrics;
        check(
            nonneg(m.from_s),
            "metrics.from_s",
            format!("must be ≥ 0 s, got {}", m.from_s),
        )?;
        check(
            pos(m.band) && m.band < 1.0,
            "metrics.band",
            format!("must be in (0, 1), got {}", m.band),
        )?;
        check(
            pos(m.static_window_s),
            "metrics.static_window_s",
            format!("must be > 0 s, got {}", m.static_window_s),
        )?;
        let o = &self.outputs;
        check(
            ROUTES.contains(&o.route.as_str()),
            "outputs.route",
            format!("must be one of {ROUTES:?}, got \"{}\"", o.route),
        )?;
        if o.route == "ihb_steady_state" {
            if let Some(why) = self.ihb_route_blocker() {
                return Err((
                    "outputs.route",
                    format!("= \"ihb_steady_state\" is not possible: {why}"),
                ));
            }
        }
        for p in &o.plots {
            check(
                PLOTS.contains(&p.as_str()),
                "plots",
                format!("entry \"{p}\" is not one of {PLOTS:?}"),
            )?;
        }
        for (k, ch) in o.channels.iter().enumerate() {
            check(
                CHANNELS.contains(&ch.name.as_str()),
                "name",
                format!(
                    "(outputs.channels[{k}]) \"{}\" is not one of {CHANNELS:?}",
                    ch.name
                ),
            )?;
            check(
                ch.every >= 1,
                "every",
                format!("(outputs.channels[{k}]) must be ≥ 1"),
            )?;
            check(
                !o.channels[..k].iter().any(|c| c.name == ch.name),
                "name",
                format!("(outputs.channels[{k}]) \"{}\" is listed twice", ch.name),
            )?;
        }
        if !self
            .name
            .chars()
            .all(|ch| ch.is_ascii_alphanumeric() || ch == '_' || ch == '-')
            || self.name.is_empty()
        {
            return Err((
                "name",
                format!("must be non-empty [A-Za-z0-9_-], got \"{}\"", self.name),
            ));
        }
        Ok(())
    }
}

fn profile_ok(
    p: &[[f64; 2]],
    key: &'static str,
    lo: f64,
    hi: f64,
) -> Result<(), (&'static str, String)> {
    if p.is_empty() {
        return Err((key, "needs at least one [t, value] knot".into()));
    }
    for (k, &[t, v]) in p.iter().enumerate() {
        if !(t.is_finite() && t >= 0.0) {
            return Err((
                key,
                format!("knot {k}: time must be finite and ≥ 0, got {t}"),
            ));
        }
        if !(v.is_finite() && v >= lo && v <= hi) {
            return Err((key, format!("knot {k}: value {v} outside [{lo}, {hi}]")));
        }
        if k > 0 && t <= p[k - 1][0] {
            return Err((
                key,
                format!(
                    "knot {k}: times must increase strictly ({} then {t})",
                    p[k - 1][0]
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const OK: &str = r#"
duration_s = 2.0
[inputs]
v_m = [[0.0, 8.0]]
t_u = [[0.0, 4.0]]
"#;

    fn err(src: &str) -> String {
        let e = Scene::parse(src, "s.toml").unwrap_err().0;
        assert!(!e.contains('\n'), "multi-line error: {e}");
        e
    }

    #[test]
    fn minimal_scene_parses_with_defaults() {
        let s = Scene::parse(OK, "s.toml").unwrap();
        assert_eq!(s.encoder.ppr, 1200);
        assert_eq!(s.controller.law, "delay");
        assert_eq!(s.controller.open_loop, "refit");
        assert!(!s.outputs.mcap && s.outputs.channels.is_empty());
    }

    #[test]
    fn errors_are_one_line_and_name_the_problem() {
        let e = err(&format!("{OK}\n[encoder]\nbogus = 3\n"));
        assert!(e.contains("s.toml:8") && e.contains("bogus"), "{e}");
        let e = err(&OK.replace("duration_s = 2.0", "duration_s = \"long\""));
        assert!(e.contains("s.toml:2") && e.contains("duration"), "{e}");
        let e = err(&OK.replace("duration_s = 2.0", "duration_s = -1.0"));
        assert!(e.contains("s.toml:2") && e.contains("`duration_s`"), "{e}");
        let e = err(&OK.replace("[[0.0, 8.0]]", "[[0.0, 8.0], [2.0, 9.0], [1.0, 7.0]]"));
        assert!(e.contains("inputs.v_m") && e.contains("increase"), "{e}");
        let e = err(&OK.replace("[[0.0, 4.0]]", "[[0.0, -4.0]]"));
        assert!(e.contains("inputs.t_u") && e.contains("s.toml:5"), "{e}");
        let e = err(&format!("{OK}\n[encoder]\nppr = 7\n"));
        assert!(e.contains("encoder.ppr"), "{e}");
        let e = err(&format!("{OK}\n[plant]\nr_a = -0.2\n"));
        assert!(e.contains("plant.r_a"), "{e}");
        let e = err(&format!("{OK}\n[controller]\nlaw = \"pid\"\n"));
        assert!(e.contains("controller.law"), "{e}");
        let e = err(&format!("{OK}\n[controller]\nopen_loop = \"printed\"\n"));
        assert!(
            e.contains("s.toml:8") && e.contains("controller.open_loop") && e.contains("refit"),
            "{e}"
        );
        let e = err(&format!(
            "{OK}\n[[outputs.channels]]\nname = \"plant\"\n[[outputs.channels]]\nname = \"nope\"\n"
        ));
        assert!(e.contains("nope") && e.contains("s.toml:10"), "{e}");
        let e = err("duration_s = 1.0\n");
        assert!(e.contains("inputs"), "{e}");
        let e = err("duration_s = \n");
        assert!(e.contains("s.toml:1"), "{e}");
    }
}
