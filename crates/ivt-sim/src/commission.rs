//! Commissioning against the simulated plant (`ivt rig commission --sim`):
//! the sequences of `ivt_ctrl::commission` run by the controller in this
//! process (SIL) or by the QEMU firmware (PIL, [`crate::pil::Pil`]), in the
//! simulator's closed loop, written as a commissioning recording
//! ([`crate::recording`]) — the channels a rig recording has.
//!
//! The simulated rig is a scene built from the plan: the bench set-points of
//! each stage are its V_m, T_U profiles (a step at each stage's nominal
//! start, from the first pulse), the plant is `[plant]` of a plant file
//! (parsed by the scene's own `[plant]` parser), the controller is the
//! proportional law Eq. 189 of the driving test. Sensors are ideal or carry
//! the noise, quantization and encoder jitter of [`SensorModel::Realistic`].

use std::path::{Path, PathBuf};

use ivt_ctrl::commission::{Plan, Selection, SequenceName, Sequencer};
use ivt_ctrl::{AnyController, ControlOutput};

use crate::backend::ControllerBackend;
use crate::error::SimError;
use crate::recording::{Recording, RecordingMeta};
use crate::run::{controller_config, Simulation};
use crate::scene::{PlantSection, Scene};

/// The simulated sensors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SensorModel {
    /// Exact readings and edge times (up to the timer's tick).
    Ideal,
    /// The drive scene's sensors: V_m noise 0.01 V (σ) on a 0.005 V quantum,
    /// T_U noise 0.02 N·m on 0.01 N·m, and 1 µs (σ) of encoder edge jitter.
    Realistic,
}

/// What to run and how.
#[derive(Clone, Debug)]
pub struct CommissionOptions {
    /// The sequences' parameters.
    pub plan: Plan,
    /// Which of them run.
    pub selection: Selection,
    /// The plant (`[plant]` of a scene or a plant file).
    pub plant: PlantSection,
    /// Sensor model.
    pub sensors: SensorModel,
    /// Gain K of Eq. 189 \[deg of stepper per rpm\] (the printed plant needs
    /// ≈ 5, see scenes/load_step_prop.toml).
    pub k_prop_deg_per_rpm: f64,
    /// Reference speed ω_r \[rpm\].
    pub omega0_rpm: f64,
    /// Seed of the sensor noise.
    pub seed: u64,
}

impl Default for CommissionOptions {
    fn default() -> Self {
        Self {
            plan: Plan::default(),
            selection: Selection::ALL,
            plant: PlantSection::default(),
            sensors: SensorModel::Ideal,
            k_prop_deg_per_rpm: 5.0,
            omega0_rpm: 100.0,
            seed: 1,
        }
    }
}

/// The simulated rig for `opts`: a scene whose inputs follow the plan.
///
/// # Errors
/// [`SimError::Scene`] if the plant or the plan makes no valid scene.
pub fn scene(opts: &CommissionOptions) -> Result<Scene, SimError> {
    let params = opts
        .plant
        .params()
        .map_err(|e| SimError::Scene(e.to_string()))?;
    let r_max = params.r_max as f32;
    let plan = &opts.plan;
    let total = f64::from(plan.duration_s(opts.selection, r_max));
    if !(total.is_finite() && total > 0.0) {
        return Err(SimError::Scene(format!(
            "the commissioning plan has no stage to run (total duration {total} s)"
        )));
    }
    let (mut v_m, mut t_u): (Vec<[f64; 2]>, Vec<[f64; 2]>) = (Vec::new(), Vec::new());
    let mut t = 0.0;
    let mut k = 0;
    while let Some(s) = plan.stage(opts.selection, k, r_max) {
        let [v, u] = s.inputs.map(f64::from);
        // A step at the stage's start: the last knot of the stage before
        // holds its value up to here.
        if let (Some(&[_, v0]), Some(&[_, u0])) = (v_m.last(), t_u.last()) {
            v_m.push([t, v0]);
            t_u.push([t, u0]);
        }
        v_m.push([t + 1e-3 * f64::from(k.min(1)), v]);
        t_u.push([t + 1e-3 * f64::from(k.min(1)), u]);
        t += f64::from(s.duration_s);
        k += 1;
    }
    let (noise, jitter) = match opts.sensors {
        SensorModel::Ideal => ([0.0; 4], 0.0),
        SensorModel::Realistic => ([0.01, 0.005, 0.02, 0.01], 1e-6),
    };
    let src = format!(
        r#"name = "commission"
description = "commissioning sequences against the simulated rig"
duration_s = {duration}
seed = {seed}
[inputs]
v_m = {v_m:?}
t_u = {t_u:?}
[initial]
omega = {omega0}
r = 0.0
[integrator]
method = "rk4"
dtheta = 0.01
[encoder]
ppr = 1200
f_timer_hz = 1e6
jitter_s = {jitter:e}
[sensors]
period_s = 0.01
v_m_noise = {vn:e}
v_m_quantum = {vq:e}
t_u_noise = {tn:e}
t_u_quantum = {tq:e}
[stepper]
steps_per_rev = 3200
max_speed = 8000
accel = 40000
[controller]
law = "prop"
omega0_rpm = {rpm}
k_prop_deg_per_rpm = {k}
prop_period_s = 0.1
feedforward = false
[outputs]
mcap = false
summary = false
[[outputs.channels]]
name = "control"
every = 1
[[outputs.channels]]
name = "stepper"
every = 1
[[outputs.channels]]
name = "sensors"
every = 1
"#,
        duration = total + 0.05,
        seed = opts.seed,
        omega0 = opts.omega0_rpm * std::f64::consts::PI / 30.0,
        vn = noise[0],
        vq = noise[1],
        tn = noise[2],
        tq = noise[3],
        rpm = opts.omega0_rpm,
        k = opts.k_prop_deg_per_rpm,
    );
    let mut scene =
        Scene::parse(&src, "commissioning scene").map_err(|e| SimError::Scene(e.message))?;
    scene.plant = opts.plant.clone();
    Ok(scene)
}

/// One pulse's answer while a sequence runs (the fields of
/// `ivt_wire::Reply::Sequenced`; SIL forms the same).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sequenced {
    /// The controller's output.
    pub out: ControlOutput,
    /// Global index of the current stage.
    pub stage: u32,
    /// A stage started at this pulse.
    pub started: bool,
    /// The pulse falls in a pulse-log stage.
    pub pulse_log: bool,
}

/// A controller that runs commissioning sequences.
pub trait SequencedBackend {
    /// One pulse through the sequencer and the controller.
    ///
    /// # Errors
    /// Backend I/O or protocol.
    fn sequenced_pulse(&mut self, ticks: u32) -> Result<Sequenced, SimError>;
    /// Slow readings V_m \[V\], T_U \[N·m\].
    ///
    /// # Errors
    /// Backend I/O or protocol.
    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), SimError>;
}

/// SIL: the ivt-ctrl controller and sequencer in this process.
pub struct SilSequenced {
    ctrl: Box<AnyController>,
    seq: Sequencer,
}

impl SequencedBackend for SilSequenced {
    fn sequenced_pulse(&mut self, ticks: u32) -> Result<Sequenced, SimError> {
        let st = self.ctrl.sequence_pulse(&mut self.seq, ticks);
        Ok(Sequenced {
            out: st.out,
            stage: st.stage,
            started: st.started.is_some(),
            pulse_log: st.pulse_log,
        })
    }
    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), SimError> {
        self.ctrl.update_inputs(v_m, t_u);
        Ok(())
    }
}

/// A pulse with something to record: its index and timestamp.
#[derive(Clone, Copy, Debug)]
struct Event {
    pulse: usize,
    ticks: u32,
    stage: u32,
    started: bool,
    pulse_log: bool,
}

/// The closed loop's backend: passes every pulse through the sequencer and
/// notes the stage starts and the logged edges.
struct Noting<B> {
    inner: std::rc::Rc<std::cell::RefCell<B>>,
    events: std::rc::Rc<std::cell::RefCell<Vec<Event>>>,
    pulses: usize,
}

impl<B: SequencedBackend> ControllerBackend for Noting<B> {
    fn on_pulse(&mut self, ticks: u32) -> Result<ControlOutput, SimError> {
        let s = self.inner.borrow_mut().sequenced_pulse(ticks)?;
        if s.started || s.pulse_log {
            self.events.borrow_mut().push(Event {
                pulse: self.pulses,
                ticks,
                stage: s.stage,
                started: s.started,
                pulse_log: s.pulse_log,
            });
        }
        self.pulses += 1;
        Ok(s.out)
    }
    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), SimError> {
        self.inner.borrow_mut().update_inputs(v_m, t_u)
    }
}

/// What a commissioning run produced.
#[derive(Clone, Debug, PartialEq)]
pub struct CommissionSummary {
    /// Encoder pulses simulated.
    pub pulses: u64,
    /// Simulated time \[s\].
    pub duration_s: f64,
    /// Stages run.
    pub stages: u64,
    /// Messages per channel.
    pub channels: std::collections::BTreeMap<String, u64>,
    /// The recording.
    pub out: PathBuf,
}

/// Runs the plan against the simulated rig with the controller in this
/// process (SIL) and writes the recording `out`.
///
/// # Errors
/// Scene, integration, backend or output failures.
pub fn run_sil(opts: &CommissionOptions, out: &Path) -> Result<CommissionSummary, SimError> {
    let scene = scene(opts)?;
    let config = rig_config(&scene)?;
    let ctrl = AnyController::new(scene.encoder.ppr, config).map_err(SimError::UnsupportedPpr)?;
    let seq = Sequencer::new(opts.plan, opts.selection, config.f_timer_hz);
    let backend = SilSequenced {
        ctrl: Box::new(ctrl),
        seq,
    };
    run_with(opts, &scene, backend, out).map(|(s, _)| s)
}

/// The controller configuration of the simulated rig.
pub(crate) fn rig_config(scene: &Scene) -> Result<ivt_ctrl::Config, SimError> {
    let params = scene
        .plant_params()
        .map_err(|e| SimError::Scene(e.to_string()))?;
    controller_config(scene, params.r_max)
        .ok_or_else(|| SimError::Scene("the commissioning scene has no controller".into()))
}

/// Runs `backend` in the closed loop of `scene` and writes the recording;
/// also returns the backend (PIL ends its session with it).
pub(crate) fn run_with<B: SequencedBackend + 'static>(
    opts: &CommissionOptions,
    scene: &Scene,
    backend: B,
    out: &Path,
) -> Result<(CommissionSummary, B), SimError> {
    let inner = std::rc::Rc::new(std::cell::RefCell::new(backend));
    let events = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
    let noting = Noting {
        inner: inner.clone(),
        events: events.clone(),
        pulses: 0,
    };
    let result = Simulation::new(scene).backend(Box::new(noting)).run()?;
    let params = scene
        .plant_params()
        .map_err(|e| SimError::Scene(e.to_string()))?;
    let ch = &result.channels;
    let control = ch.control.as_deref().unwrap_or(&[]);
    let mut rec = Recording::create(
        out,
        &RecordingMeta {
            frame_version: ivt_wire::telemetry::TELEMETRY_VERSION,
            ppr: scene.encoder.ppr as u32,
            f_timer_hz: scene.encoder.f_timer_hz,
            plant: Some(plant_json(&params)),
            steps_per_rev: Some(scene.stepper.steps_per_rev),
            source: "simulated rig".into(),
        },
    )?;
    for s in control {
        rec.sample(s)?;
    }
    for s in ch.stepper.as_deref().unwrap_or(&[]) {
        rec.sample(s)?;
    }
    for s in ch.sensors.as_deref().unwrap_or(&[]) {
        rec.sample(s)?;
    }
    let t_of = |e: &Event| control.get(e.pulse).map_or(f64::NAN, |c| c.t);
    let r_max = params.r_max as f32;
    let mut stages = 0;
    let mut batch: (Vec<f64>, Vec<u32>) = (Vec::new(), Vec::new());
    for e in events.borrow().iter() {
        if e.started {
            if let Some(s) = opts.plan.stage(opts.selection, e.stage, r_max) {
                flush(&mut rec, &mut batch)?;
                rec.stage(t_of(e), s.sequence, s.index, s.theta_ct_deg, s.hold)?;
                stages += 1;
            }
        }
        if e.pulse_log {
            batch.0.push(t_of(e));
            batch.1.push(e.ticks);
            if batch.1.len() == ivt_wire::telemetry::PULSES_PER_FRAME {
                flush(&mut rec, &mut batch)?;
            }
        }
    }
    flush(&mut rec, &mut batch)?;
    let channels = rec.finish()?;
    drop(events);
    let backend = std::rc::Rc::try_unwrap(inner)
        .map_err(|_| SimError::BackendIo("the backend is still in use".into()))?
        .into_inner();
    Ok((
        CommissionSummary {
            pulses: result.summary.pulses,
            duration_s: result.summary.duration_s,
            stages,
            channels,
            out: out.to_path_buf(),
        },
        backend,
    ))
}

fn flush(rec: &mut Recording, batch: &mut (Vec<f64>, Vec<u32>)) -> Result<(), SimError> {
    if !batch.1.is_empty() {
        rec.pulses(&batch.0, &batch.1)?;
        batch.0.clear();
        batch.1.clear();
    }
    Ok(())
}

/// The plant's parameters as JSON (the recording's metadata): the keys and
/// values of a `[plant]` table, so that a reader rebuilds it with the scene's parser.
fn plant_json(p: &ivt_kin::plant::PlantParams) -> serde_json::Value {
    let gravity = match p.gravity {
        ivt_kin::plant::GravityModel::Printed => "printed",
        ivt_kin::plant::GravityModel::RollerMass => "roller_mass",
    };
    serde_json::json!({
        "r_a": p.r_a, "k_e": p.k_e, "k_t": p.k_t, "l_a": p.l_a,
        "j_n1": p.j_n1, "j_n2": p.j_n2, "j_inshaft": p.j_inshaft, "j_carrier": p.j_carrier,
        "j_ring": p.j_ring, "j_crk": p.j_crk, "m_r": p.m_r, "m_dr": p.m_dr, "j_u": p.j_u,
        "r_u": p.r_u, "g": p.g, "sun_to_planet": p.sun_to_planet,
        "gravity": gravity, "r_max": p.r_max,
    })
}

/// The sequence names of a selection, in run order.
#[must_use]
pub fn selected_names(sel: Selection) -> Vec<&'static str> {
    SequenceName::ALL
        .into_iter()
        .filter(|s| sel.contains(*s))
        .map(SequenceName::as_str)
        .collect()
}
