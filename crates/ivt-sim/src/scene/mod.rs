//! Scenes: a TOML file that says what to simulate and what to keep.
//!
//! Parsing is strict (`deny_unknown_fields`; laws, methods, routes, presets
//! are enums); every error is one line `origin:line:column: `key` message`,
//! the position taken from toml's own spans. Each section validates itself
//! next to its definition. See `scenes/*.toml` for examples and the crate
//! guide's Scenes chapter (docs/guide/src/controller/scenes.md) for the full key list and the limits ([`MAX_DURATION_S`],
//! `[outputs] max_bytes`).

mod budget;
mod controller;
mod hardware;
mod inputs;
pub mod keys;
pub mod locate;
mod outputs;
mod plant;

pub use budget::{EventEstimate, DEFAULT_MAX_EVENTS};
pub use controller::{ControllerSection, Law, MetricsSection, OpenLoopLaw};
pub use hardware::{
    EncoderSection, IntegratorMethod, IntegratorSection, SensorsSection, StepperSection,
};
pub use inputs::{InitialSection, InputsSection};
pub use outputs::{ChannelSpec, OutputsSection, Route, RouteRequest, DEFAULT_MAX_BYTES};
pub use plant::{Gravity, PlantSection, PresetName};

use ivt_kin::plant::PlantParams;
use serde::Deserialize;

pub use ivt_kin::params::MAX_DURATION_S;

/// Rough size of one recorded field \[bytes\]: a CSV number or a JSON
/// `"key":value` pair of the MCAP message before compression.
const BYTES_PER_FIELD: f64 = 24.0;

/// A scene error: one line, naming the position and the key.
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
#[error("{message}")]
pub struct SceneError {
    /// The line.
    pub message: String,
    /// A file could not be read (missing, not a regular file, over its size
    /// budget: [`crate::input::open`]) — the CLI's kind `io`; otherwise the
    /// text is not a valid scene or plant file.
    pub unreadable: bool,
}

impl SceneError {
    /// Invalid text (TOML, a key, a value).
    #[must_use]
    pub fn invalid(message: String) -> Self {
        Self {
            message,
            unreadable: false,
        }
    }

    /// `path` could not be read ([`crate::input`]); not UTF-8 text is
    /// invalid text instead.
    #[must_use]
    pub fn reading(path: &std::path::Path, e: &std::io::Error) -> Self {
        Self {
            message: format!("{}: {e}", path.display()),
            unreadable: e.kind() != std::io::ErrorKind::InvalidData,
        }
    }

    /// The same error with `prefix` in front of its message.
    #[must_use]
    pub fn within(self, prefix: &str) -> Self {
        Self {
            message: format!("{prefix}{}", self.message),
            ..self
        }
    }
}

/// A validation failure: the dotted key path (`controller.law`,
/// `outputs.channels[1].name`) and what is wrong with its value.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{key}` {message}")]
pub struct Invalid {
    /// Key path.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl Invalid {
    fn new(key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            message: message.into(),
        }
    }

    fn check(
        ok: bool,
        key: impl Into<String>,
        message: impl FnOnce() -> String,
    ) -> Result<(), Self> {
        if ok {
            Ok(())
        } else {
            Err(Self::new(key, message()))
        }
    }
}

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
    /// Simulated time \[s\], at most [`MAX_DURATION_S`].
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

impl Scene {
    /// Parse and validate a scene. `origin` names the source in errors; a
    /// relative `[plant] file` is taken from the working directory.
    ///
    /// # Errors
    /// One-line [`SceneError`] naming the position and the key.
    pub fn parse(src: &str, origin: &str) -> Result<Self, SceneError> {
        Self::parse_in(src, origin, std::path::Path::new("."))
    }

    /// As [`Self::parse`], a relative `[plant] file` taken from `base` (the
    /// scene file's directory). The plant file's `[plant]` table is merged
    /// into the scene's ([`PlantSection::resolve`]) before validation.
    ///
    /// # Errors
    /// One-line [`SceneError`] naming the position and the key (the plant
    /// file's own position for an error inside it).
    pub fn parse_in(src: &str, origin: &str, base: &std::path::Path) -> Result<Self, SceneError> {
        let doc = locate::Doc::new(src);
        let at = |span: Option<std::ops::Range<usize>>| doc.at(origin, span);
        let mut scene: Scene =
            toml::from_str(src).map_err(|e| SceneError::invalid(doc.serde_error(origin, &e)))?;
        if scene.plant.file.is_some() {
            for key in ["plant.preset", "plant.gravity"] {
                if let Some(span) = doc.span_of(key) {
                    return Err(SceneError::invalid(format!(
                        "{}: `{key}` comes from `plant.file`; give it there, not beside it",
                        at(Some(span))
                    )));
                }
            }
            scene.plant = scene.plant.resolve(base).map_err(|e| {
                e.within(&format!(
                    "{}: `plant.file`: ",
                    at(doc.span_of("plant.file"))
                ))
            })?;
        }
        scene
            .validate()
            .map_err(|e| SceneError::invalid(format!("{}: {e}", at(doc.span_of(&e.key)))))?;
        Ok(scene)
    }

    /// Read and parse a scene file.
    ///
    /// # Errors
    /// I/O or scene errors, one line.
    pub fn load(path: &std::path::Path) -> Result<Self, SceneError> {
        let src = crate::input::read_text_bounded(path, crate::input::MAX_SCENE_BYTES)
            .map_err(|e| SceneError::reading(path, &e))?;
        let base = path.parent().unwrap_or(std::path::Path::new("."));
        Self::parse_in(&src, &path.display().to_string(), base)
    }

    /// Plant parameters: preset plus overrides ([`PlantSection::params`]).
    ///
    /// # Errors
    /// An invalid parameter.
    pub fn plant_params(&self) -> Result<PlantParams, Invalid> {
        self.plant.params()
    }

    /// ω0 as the controller holds it (f32 rpm → rad/s) \[rad/s\].
    #[must_use]
    pub fn omega0_rad_s(&self) -> f64 {
        f64::from(ivt_ctrl::units::rpm_to_rad_s(
            self.controller.omega0_rpm as f32,
        ))
    }

    /// Upper estimate of the bytes the recorded channels take (in memory,
    /// and once more per file format asked for): the pulses at ω0 (or the
    /// initial speed, if larger) over `duration_s`, decimated per channel,
    /// times `BYTES_PER_FIELD` per field (uncompressed; the MCAP log is
    /// zstd-compressed and smaller).
    #[must_use]
    pub fn estimated_output_bytes(&self) -> f64 {
        let o = &self.outputs;
        let omega = self.omega0_rad_s().max(self.initial.omega);
        let pulses = self.duration_s * omega * self.encoder.ppr as f64 / std::f64::consts::TAU;
        let sensor_samples = self.duration_s / self.sensors.period_s;
        let copies = 1.0 + f64::from(u8::from(o.mcap)) + f64::from(u8::from(o.csv));
        o.channels
            .iter()
            .map(|c| {
                let n = if c.name == crate::record::Channel::Sensors {
                    sensor_samples
                } else {
                    pulses
                };
                let fields = c.name.fields().len() as f64;
                (n / c.every.max(1) as f64).ceil() * fields * BYTES_PER_FIELD
            })
            .sum::<f64>()
            * copies
    }

    /// Why the scene cannot be answered by the IHB steady state (None: it
    /// can). The IHB route (thesis §4.2.1: the periodic steady state without
    /// the transient) answers exactly what the time integration would settle
    /// to only when the scene asks for nothing but steady-state metrics at
    /// constant inputs, with a law whose equilibrium is the periodic orbit at
    /// constant r, and without random disturbances.
    #[must_use]
    pub fn ihb_route_blocker(&self) -> Option<String> {
        let constant = |p: &[[f64; 2]]| p.iter().all(|k| Some(&k[1]) == p.first().map(|f| &f[1]));
        let o = &self.outputs;
        let c = &self.controller;
        if !o.steady_state {
            Some("the scene does not ask for steady-state metrics (outputs.steady_state)".into())
        } else if o.mcap || o.csv || !o.plots.is_empty() || !o.channels.is_empty() {
            Some("the scene asks for channels, plots, MCAP or CSV (a transient)".into())
        } else if !constant(&self.inputs.v_m) || !constant(&self.inputs.t_u) {
            Some("the inputs V_m, T_U are not constant".into())
        } else if matches!(c.law, Law::NoDelay | Law::Prop) {
            Some(format!(
                "law \"{}\": its equilibrium is not the periodic orbit at constant r (Eq. 181 holds the θ-mean of ω, Eq. 189 samples in time)",
                c.law.name()
            ))
        } else if c.law == Law::None && !constant(&c.r_schedule) {
            Some("the r schedule is not constant".into())
        } else if self.sensors.disturbed()
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

    /// All range and consistency checks, section by section.
    fn validate(&self) -> Result<(), Invalid> {
        keys::check("duration_s", self.duration_s)?;
        let params = self.plant.params()?;
        self.inputs.validate()?;
        self.initial.validate(params.r_max)?;
        self.integrator.validate()?;
        self.encoder.validate()?;
        self.sensors.validate()?;
        self.stepper.validate()?;
        self.controller.validate(params.r_max)?;
        self.metrics.validate()?;
        self.outputs.validate()?;
        if self.outputs.route == RouteRequest::IhbSteadyState {
            if let Some(why) = self.ihb_route_blocker() {
                return Err(Invalid::new(
                    "outputs.route",
                    format!("= \"ihb_steady_state\" is not possible: {why}"),
                ));
            }
        }
        let bytes = self.estimated_output_bytes();
        Invalid::check(bytes <= self.outputs.max_bytes, "outputs.max_bytes", || {
            format!(
                "the recorded channels would take about {:.3e} bytes, more than the cap {:.3e}: shorten duration_s, raise `every`, or raise max_bytes",
                bytes, self.outputs.max_bytes
            )
        })?;
        Invalid::check(
            !self.name.is_empty()
                && self
                    .name
                    .chars()
                    .all(|ch| ch.is_ascii_alphanumeric() || ch == '_' || ch == '-'),
            "name",
            || format!("must be non-empty [A-Za-z0-9_-], got \"{}\"", self.name),
        )
    }
}

#[cfg(test)]
mod tests;
