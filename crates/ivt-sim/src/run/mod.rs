//! Running a scene: the [`Simulation`] builder, the closed loop
//! (`closed_loop`, in named stages) and what a run produces (channels and
//! the [`Summary`]).
//!
//! ```no_run
//! # use ivt_sim::{run::Simulation, scene::Scene};
//! let scene = Scene::load("scenes/drive.toml".as_ref()).unwrap();
//! let result = Simulation::new(&scene).run().unwrap(); // time integration
//! let answer = Simulation::new(&scene).answer().unwrap(); // by the scene's route
//! ```

mod closed_loop;
mod metrics;

use crate::backend::{self, ControllerBackend};
use crate::error::SimError;
use crate::integrate::Reached;
pub use crate::record::{
    Channels, ControlSample, PlantSample, Sample, SensorSample, StepperSample,
};
use crate::scene::{Law, Route, Scene};
use closed_loop::ClosedLoop;
use ivt_ctrl::{units, ActuatorMap, Config, Gains, OpenLoopPreset, StepperLimits};
use serde::Serialize;
use std::time::Instant;

/// The summary of a run (SPEC §3: settling time, overshoot, static error,
/// control effort).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Law that ran.
    pub law: Law,
    /// Encoder resolution.
    pub ppr: usize,
    /// Simulated time \[s\].
    pub duration_s: f64,
    /// Target ω0 \[rad/s\].
    pub omega0_rad_s: f64,
    /// Encoder pulses simulated.
    pub pulses: u64,
    /// Time from `metrics.from_s` until ω_a stays within the band (None:
    /// never settles, or an empty metrics window).
    pub settling_time_s: Option<f64>,
    /// max(ω_a − ω0)/ω0 after `from_s` \[%\].
    pub overshoot_pct: f64,
    /// max(ω0 − ω_a)/ω0 after `from_s` \[%\].
    pub undershoot_pct: f64,
    /// mean(ω_a − ω0) over the last `static_window_s` \[rad/s\].
    pub static_error_rad_s: f64,
    /// ω_a at the end \[rad/s\].
    pub final_omega_a_rad_s: f64,
    /// RMS of dr/dθ of the commanded r after `from_s` (the control effort) \[m/rad\].
    pub rms_control_effort_m_per_rad: f64,
    /// RMS of dr/dt \[m/s\].
    pub rms_dr_dt_m_per_s: f64,
    /// max |dr/dt| \[m/s\].
    pub max_abs_dr_dt_m_per_s: f64,
    /// Fraction of pulses with r saturated.
    pub saturated_fraction: f64,
    /// Why the metrics after `metrics.from_s` are NaN (null in JSON): no
    /// pulse, or no full revolution, in that window. Absent when they exist.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub metrics_note: Option<String>,
    /// Pulses with a non-zero fault code.
    pub fault_pulses: u64,
    /// Steps lost by the stepper.
    pub missed_steps: u64,
    /// Accepted integrator steps (time domain, angle domain), rejected steps.
    pub integrator_steps: [u64; 3],
    /// Wall-clock run time \[s\].
    pub wall_time_s: f64,
    /// Simulated time / wall time.
    pub realtime_factor: f64,
}

/// The outcome of [`Simulation::run`].
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Metrics.
    pub summary: Summary,
    /// Recorded channels.
    pub channels: Channels,
}

/// The `ivt-ctrl` configuration a scene describes (None for `law = "none"`).
#[must_use]
pub fn controller_config(scene: &Scene, r_max: f64) -> Option<Config> {
    let c = &scene.controller;
    let law = c.law.kind()?;
    let mut open_loop = OpenLoopPreset::from(c.open_loop).coeffs();
    open_loop.r_max = r_max as f32;
    Some(Config {
        f_timer_hz: scene.encoder.f_timer_hz as f32,
        omega0: units::rpm_to_rad_s(c.omega0_rpm as f32),
        decimation: 1,
        law,
        gains: Gains {
            k: units::gain_from_mm_per_rad(c.k_mm_per_rad as f32),
            k2: units::gain_from_mm_per_rad(c.k2_mm_per_rad as f32),
            k_prop: units::prop_gain_from_deg_per_rpm(c.k_prop_deg_per_rpm as f32),
            prop_period_s: c.prop_period_s as f32,
        },
        open_loop,
        feedforward: c.feedforward,
        actuator: ActuatorMap::sgivt(scene.stepper.steps_per_rev as f32),
        stepper: StepperLimits {
            max_speed: scene.stepper.max_speed as f32,
            accel: scene.stepper.accel as f32,
        },
        initial_inputs: [
            first_value(&scene.inputs.v_m),
            first_value(&scene.inputs.t_u),
        ],
        ..Config::default()
    })
}

/// The value of a profile's first knot as the controller reads it (NaN for
/// a profile without knots, which scene validation refuses).
fn first_value(profile: &[[f64; 2]]) -> f32 {
    profile.first().map_or(f32::NAN, |&[_, v]| v as f32)
}

/// What runs a scene: the closed-loop time integration ([`Simulation::run`])
/// or the scene's answer by its route ([`Simulation::answer`], in
/// [`crate::steady`]). Defaults: the in-process ivt-ctrl controller (SIL), no
/// progress report, no streaming sink, the route the scene asks for.
pub struct Simulation<'a> {
    pub(crate) scene: &'a Scene,
    backend: Option<Box<dyn ControllerBackend>>,
    pub(crate) route: Option<Route>,
    pub(crate) progress: Option<&'a mut dyn FnMut(f64)>,
    sink: Option<&'a mut dyn FnMut(Sample)>,
    pub(crate) max_events: f64,
}

impl<'a> Simulation<'a> {
    /// A simulation of `scene` with the defaults.
    #[must_use]
    pub fn new(scene: &'a Scene) -> Self {
        Self {
            scene,
            backend: None,
            route: None,
            progress: None,
            sink: None,
            max_events: crate::scene::DEFAULT_MAX_EVENTS,
        }
    }

    /// Put this controller in the loop instead of the in-process one (e.g.
    /// the QEMU firmware, [`crate::pil`]).
    #[must_use]
    pub fn backend(mut self, backend: Box<dyn ControllerBackend>) -> Self {
        self.backend = Some(backend);
        self
    }

    /// Force a route for [`Simulation::answer`] (the CLI's `--route`);
    /// None keeps the scene's `outputs.route`.
    #[must_use]
    pub fn route(mut self, route: Option<Route>) -> Self {
        self.route = route;
        self
    }

    /// Call `progress` now and then with the fraction of simulated time done.
    #[must_use]
    pub fn progress(mut self, progress: &'a mut dyn FnMut(f64)) -> Self {
        self.progress = Some(progress);
        self
    }

    /// Hand every recorded channel sample to `sink` as soon as it is
    /// recorded (the MCAP writer thread of [`crate::output::run_and_write`]
    /// serializes and compresses them while the loop goes on).
    #[must_use]
    pub fn sink(mut self, sink: &'a mut dyn FnMut(Sample)) -> Self {
        self.sink = Some(sink);
        self
    }

    /// Refuse a time integration of more than `max_events` events
    /// ([`Scene::estimated_events`]; default [`crate::scene::DEFAULT_MAX_EVENTS`]).
    #[must_use]
    pub fn max_events(mut self, max_events: f64) -> Self {
        self.max_events = max_events;
        self
    }

    /// The closed-loop time integration of the scene.
    ///
    /// # Errors
    /// A scene over the work budget ([`Self::max_events`]), scene,
    /// integration or controller-backend failures.
    pub fn run(self) -> Result<RunResult, SimError> {
        let wall = Instant::now();
        let scene = self.scene;
        scene
            .check_events(self.max_events)
            .map_err(SimError::Budget)?;
        let backend = match self.backend {
            Some(b) => Some(b),
            None => default_backend(scene)?,
        };
        let mut no_progress = |_: f64| {};
        let progress = self.progress.unwrap_or(&mut no_progress);
        let mut no_sink = |_: Sample| {};
        let sink = self.sink.unwrap_or(&mut no_sink);
        let mut sim = ClosedLoop::new(scene, backend)?;
        let duration = scene.duration_s;
        let mut last_progress = 0.0;
        loop {
            sim.read_sensors(sink)?;
            if sim.t() >= duration {
                break;
            }
            if sim.advance_plant()? == Reached::Time {
                continue;
            }
            sim.on_pulse(sink)?;
            let t = sim.t();
            if t - last_progress > 0.01 * duration {
                last_progress = t;
                progress(t / duration);
            }
        }
        progress(1.0);
        Ok(sim.finish(wall.elapsed().as_secs_f64()))
    }
}

/// The in-process controller the scene describes (None for `law = "none"`).
fn default_backend(scene: &Scene) -> Result<Option<Box<dyn ControllerBackend>>, SimError> {
    let params = scene
        .plant_params()
        .map_err(|e| SimError::Scene(e.to_string()))?;
    match controller_config(scene, params.r_max) {
        Some(cfg) => Ok(Some(backend::sil(scene.encoder.ppr, cfg)?)),
        None => Ok(None),
    }
}

impl crate::profile::Drive {
    /// `(V_m, T_U)` at `t` (inherent shortcut for [`crate::integrate::InputProfile::at`]).
    pub fn at_time(&self, t: f64) -> (f64, f64) {
        (self.v_m.at(t), self.t_u.at(t))
    }
}

#[cfg(test)]
mod tests;
