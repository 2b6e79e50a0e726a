//! The closed loop: plant ⟶ encoder pulses ⟶ controller backend ⟶ stepper ⟶ r.
//!
//! Event loop (one iteration per encoder pulse):
//! 1. integrate the plant to the next pulse angle θ_k = k·2π/PPR (exactly, in
//!    the angle domain once ω > 0; stopping for sensor samples in between);
//! 2. timestamp the pulse with the encoder's timer (and jitter), hand it to
//!    the backend (`on_pulse`, the call the firmware makes);
//! 3. move the stepper model towards `stepper_target` (rate/accel limits,
//!    missed steps) and take r from its real position;
//! 4. update the metrics and the channels the scene asked for.
//!
//! Every `sensors.period_s` the true V_m, T_U are read (noise, quantization)
//! and given to `update_inputs`.

use crate::backend::{self, BackendError, ControllerBackend};
use crate::integrate::{IntegrateError, Method, PlantIntegrator, Reached};
use crate::ode::Tolerance;
use crate::plant::Plant;
use crate::profile::{Drive, Pwl};
use crate::record::Sample;
use crate::scene::Scene;
use crate::sensors::{Encoder, Reading, Rng, Stepper};
use ivt_ctrl::{units, ActuatorMap, Config, Gains, LawKind, OpenLoopPreset, StepperLimits};
use serde::Serialize;
use std::time::Instant;

/// A failed run.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The scene is inconsistent.
    #[error("scene: {0}")]
    Scene(String),
    /// The integrator failed.
    #[error(transparent)]
    Integrate(#[from] IntegrateError),
    /// The controller backend failed.
    #[error(transparent)]
    Backend(#[from] BackendError),
}

/// One `plant` channel sample (at a pulse).
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct PlantSample {
    /// Time \[s\].
    pub t: f64,
    /// θ \[rad\].
    pub theta: f64,
    /// ω \[rad/s\].
    pub omega: f64,
    /// ω_a from the exact pulse times (NaN for the first revolution) \[rad/s\].
    pub omega_a: f64,
    /// Real eccentricity r \[m\].
    pub r: f64,
    /// True V_m \[V\].
    pub v_m: f64,
    /// True T_U \[N·m\].
    pub t_u: f64,
    /// Armature current (0 with L_a = 0) \[A\].
    pub i_a: f64,
}

/// One `control` channel sample: the backend's [`ivt_ctrl::ControlOutput`].
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct ControlSample {
    /// Time \[s\].
    pub t: f64,
    /// Timer capture \[ticks\].
    pub ticks: u32,
    /// ω \[rad/s\].
    pub omega: f32,
    /// ω_a \[rad/s\].
    pub omega_a: f32,
    /// ω_T \[rad/s\].
    pub omega_t: f32,
    /// u_ol \[m\].
    pub r_ol: f32,
    /// r_d \[m\].
    pub r_d: f32,
    /// Commanded r \[m\].
    pub r: f32,
    /// Stepper target \[steps\].
    pub stepper_target: i32,
    /// r at a bound.
    pub saturated: bool,
    /// Fault code.
    pub fault: u8,
}

/// One `stepper` channel sample.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct StepperSample {
    /// Time \[s\].
    pub t: f64,
    /// Target from the controller \[steps\].
    pub target: i64,
    /// Steps issued \[steps\].
    pub commanded: i64,
    /// Real position \[steps\].
    pub position: i64,
    /// Steps lost so far.
    pub missed: u64,
}

/// One `sensors` channel sample (what the controller was given).
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct SensorSample {
    /// Time \[s\].
    pub t: f64,
    /// V_m reading \[V\].
    pub v_m: f64,
    /// T_U reading \[N·m\].
    pub t_u: f64,
}

/// The channels that were asked for (None = not recorded at all).
#[derive(Clone, Debug, Default)]
pub struct Channels {
    /// `plant` samples.
    pub plant: Option<Vec<PlantSample>>,
    /// `control` samples.
    pub control: Option<Vec<ControlSample>>,
    /// `stepper` samples.
    pub stepper: Option<Vec<StepperSample>>,
    /// `sensors` samples.
    pub sensors: Option<Vec<SensorSample>>,
    /// Series for the plots (only when plots are asked for): (t, ω, ω_a, r, V_m, T_U).
    pub plot: Option<Vec<[f64; 6]>>,
}

/// The summary of a run (SPEC §3: settling time, overshoot, static error,
/// control effort).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Law that ran.
    pub law: String,
    /// Encoder resolution.
    pub ppr: usize,
    /// Simulated time \[s\].
    pub duration_s: f64,
    /// Target ω0 \[rad/s\].
    pub omega0_rad_s: f64,
    /// Encoder pulses simulated.
    pub pulses: u64,
    /// Time from `metrics.from_s` until ω_a stays within the band (None: never settles).
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

/// The outcome of [`run`].
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Metrics.
    pub summary: Summary,
    /// Recorded channels.
    pub channels: Channels,
}

#[derive(Default)]
struct Metrics {
    dtheta: f64,
    from: f64,
    band: f64,
    static_from: f64,
    omega0: f64,
    last_out: Option<f64>,
    seen: bool,
    max_dev: f64,
    min_dev: f64,
    static_sum: f64,
    static_n: u64,
    drdth_sq: f64,
    drdt_sq: f64,
    max_drdt: f64,
    n_rate: u64,
    saturated: u64,
    pulses: u64,
    faults: u64,
    final_omega_a: f64,
}

impl Metrics {
    fn pulse(&mut self, t: f64, omega_a: f64, dr: f64, dt: f64, sat: bool, fault: bool) {
        self.pulses += 1;
        self.faults += u64::from(fault);
        if omega_a.is_finite() {
            self.final_omega_a = omega_a;
        }
        if t < self.from {
            return;
        }
        self.saturated += u64::from(sat);
        if dt > 0.0 {
            let rate = dr / dt;
            self.drdt_sq += rate * rate;
            self.max_drdt = self.max_drdt.max(rate.abs());
        }
        self.drdth_sq += (dr / self.dtheta) * (dr / self.dtheta);
        self.n_rate += 1;
        if !omega_a.is_finite() {
            self.last_out = Some(t);
            return;
        }
        self.seen = true;
        let dev = omega_a - self.omega0;
        self.max_dev = self.max_dev.max(dev);
        self.min_dev = self.min_dev.min(dev);
        if dev.abs() > self.band * self.omega0 {
            self.last_out = Some(t);
        }
        if t >= self.static_from {
            self.static_sum += dev;
            self.static_n += 1;
        }
    }
}

fn law_kind(name: &str) -> Option<LawKind> {
    match name {
        "delay" => Some(LawKind::Delay),
        "nodelay" => Some(LawKind::NoDelay),
        "prop" => Some(LawKind::Prop),
        "open" => Some(LawKind::Open),
        _ => None,
    }
}

/// The `ivt-ctrl` configuration a scene describes (None for `law = "none"`).
pub fn controller_config(scene: &Scene, r_max: f64) -> Option<Config> {
    let c = &scene.controller;
    let law = law_kind(&c.law)?;
    // Validated by `Scene::parse`; an unknown name cannot reach here.
    let mut open_loop = OpenLoopPreset::from_name(&c.open_loop)
        .unwrap_or_default()
        .coeffs();
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
        initial_inputs: [scene.inputs.v_m[0][1] as f32, scene.inputs.t_u[0][1] as f32],
        ..Config::default()
    })
}

fn pwl(knots: &[[f64; 2]]) -> Pwl {
    Pwl::new(knots.iter().map(|&[t, v]| (t, v)).collect())
}

/// Run a scene. `progress` is called now and then with the fraction done.
///
/// # Errors
/// Integration or backend failures.
pub fn run(scene: &Scene, progress: &mut dyn FnMut(f64)) -> Result<RunResult, SimError> {
    run_to(scene, progress, &mut |_| {})
}

/// [`run`], handing every recorded channel sample to `sink` as soon as it
/// is recorded (the MCAP writer thread of [`crate::output::run_and_write`]
/// serializes and compresses them while the loop goes on).
///
/// # Errors
/// Integration or backend failures.
pub fn run_to(
    scene: &Scene,
    progress: &mut dyn FnMut(f64),
    sink: &mut dyn FnMut(Sample),
) -> Result<RunResult, SimError> {
    let params = scene
        .plant_params()
        .map_err(|(k, m)| SimError::Scene(format!("`{k}` {m}")))?;
    let config = controller_config(scene, params.r_max);
    let backend = match config {
        Some(cfg) => Some(backend::sil(scene.encoder.ppr, cfg)?),
        None => None,
    };
    run_with_backend_to(scene, backend, progress, sink)
}

/// Run a scene with a given controller backend (SIL or PIL); `None` runs
/// the `r_schedule` open loop.
///
/// # Errors
/// Integration or backend failures.
pub fn run_with_backend(
    scene: &Scene,
    backend: Option<Box<dyn ControllerBackend>>,
    progress: &mut dyn FnMut(f64),
) -> Result<RunResult, SimError> {
    run_with_backend_to(scene, backend, progress, &mut |_| {})
}

/// [`run_with_backend`] with a streaming `sink` as in [`run_to`].
///
/// # Errors
/// Integration or backend failures.
pub fn run_with_backend_to(
    scene: &Scene,
    mut backend: Option<Box<dyn ControllerBackend>>,
    progress: &mut dyn FnMut(f64),
    sink: &mut dyn FnMut(Sample),
) -> Result<RunResult, SimError> {
    let wall = Instant::now();
    let params = scene
        .plant_params()
        .map_err(|(k, m)| SimError::Scene(format!("`{k}` {m}")))?;
    let plant = Plant::new(params);
    let g = &scene.integrator;
    let tol = Tolerance {
        rtol: g.rtol,
        atol: g.atol,
    };
    let method = if g.method == "rk4" {
        Method::Rk4 {
            dtheta: g.dtheta,
            startup: tol,
        }
    } else {
        Method::Dp5(tol)
    };
    let drive = Drive {
        v_m: pwl(&scene.inputs.v_m),
        t_u: pwl(&scene.inputs.t_u),
    };
    let r_schedule =
        (!scene.controller.r_schedule.is_empty()).then(|| pwl(&scene.controller.r_schedule));
    let mut rng = Rng::new(scene.seed);
    let enc = Encoder {
        ppr: scene.encoder.ppr,
        f_timer_hz: scene.encoder.f_timer_hz,
        jitter_s: scene.encoder.jitter_s,
    };
    let dtheta = enc.dtheta();
    let v_read = Reading {
        noise: scene.sensors.v_m_noise,
        quantum: scene.sensors.v_m_quantum,
    };
    let t_read = Reading {
        noise: scene.sensors.t_u_noise,
        quantum: scene.sensors.t_u_quantum,
    };
    let map = ActuatorMap::sgivt(scene.stepper.steps_per_rev as f32);
    let r_per_step = 1.0 / f64::from(map.steps_per_metre);
    let st = &scene.stepper;
    let mut stepper = Stepper::new(
        st.max_speed,
        st.accel,
        st.miss_prob,
        r_per_step,
        (scene.initial.r / r_per_step).round() as i64,
    );
    let v0 = drive.v_m.at(0.0);
    let i0 = plant.quasi_static_current(scene.initial.theta, scene.initial.omega, v0);
    let mut integ = PlantIntegrator::new(
        plant,
        method,
        0.0,
        scene.initial.theta,
        scene.initial.omega,
        i0,
    );
    integ.omega_handover = g.omega_handover;

    // channel buffers: only what is asked for
    let every = |name: &str| scene.outputs.every(name);
    let (ev_plant, ev_control, ev_stepper, ev_sensors) = (
        every("plant"),
        every("control"),
        every("stepper"),
        every("sensors"),
    );
    let mut ch = Channels {
        plant: ev_plant.map(|_| Vec::new()),
        control: ev_control.map(|_| Vec::new()),
        stepper: ev_stepper.map(|_| Vec::new()),
        sensors: ev_sensors.map(|_| Vec::new()),
        plot: (!scene.outputs.plots.is_empty()).then(Vec::new),
    };
    let duration = scene.duration_s;
    let omega0 = units::rpm_to_rad_s(scene.controller.omega0_rpm as f32) as f64;
    let plot_every = {
        let est_pulses = duration * omega0 / dtheta;
        ((est_pulses / 4000.0).ceil() as u64).max(1)
    };
    let m = &scene.metrics;
    let mut met = Metrics {
        from: m.from_s,
        band: m.band,
        static_from: (duration - m.static_window_s).max(m.from_s),
        omega0,
        dtheta,
        final_omega_a: f64::NAN,
        ..Metrics::default()
    };

    let mut r = match &r_schedule {
        Some(s) if backend.is_none() => s.at(0.0),
        _ => stepper.r(),
    };
    let mut target = stepper.position;
    let mut t_stepper = 0.0;
    let mut k_pulse = (integ.theta() / dtheta).floor() as i64 + 1;
    let ring_len = enc.ppr + 1;
    let mut ring = vec![f64::NAN; ring_len];
    let mut n_pulse: u64 = 0;
    let mut next_sensor = 0.0;
    let mut n_sensor: u64 = 0;
    let mut last_pulse_t = 0.0;
    let mut r_cmd_prev = r;
    let mut last_progress = 0.0;

    loop {
        if integ.t >= next_sensor {
            let (v, tu) = drive.at_time(integ.t);
            let (rv, rt) = (v_read.read(v, &mut rng), t_read.read(tu, &mut rng));
            if let Some(b) = backend.as_mut() {
                b.update_inputs(rv as f32, rt as f32)?;
            }
            if let (Some(buf), Some(e)) = (ch.sensors.as_mut(), ev_sensors) {
                if n_sensor.is_multiple_of(e as u64) {
                    let s = SensorSample {
                        t: integ.t,
                        v_m: rv,
                        t_u: rt,
                    };
                    buf.push(s);
                    sink(Sample::Sensors(s));
                }
            }
            n_sensor += 1;
            next_sensor += scene.sensors.period_s;
        }
        if integ.t >= duration {
            break;
        }
        let theta_k = k_pulse as f64 * dtheta;
        let reached = integ.advance(&drive, r, theta_k, next_sensor.min(duration))?;
        // the stepper moved towards its target meanwhile
        if backend.is_some() {
            stepper.advance(target, integ.t - t_stepper, &mut rng);
            t_stepper = integ.t;
            r = stepper.r();
        }
        if reached == Reached::Time {
            continue;
        }
        // an encoder pulse
        let t = integ.t;
        let slot = (n_pulse as usize) % ring_len;
        let oldest = ring[(n_pulse as usize + 1) % ring_len];
        ring[slot] = t;
        let omega_a = if n_pulse as usize >= enc.ppr {
            std::f64::consts::TAU / (t - oldest)
        } else {
            f64::NAN
        };
        let ticks = enc.capture(t, &mut rng);
        let (r_cmd, sat, fault) = if let Some(b) = backend.as_mut() {
            let out = b.on_pulse(ticks)?;
            target = i64::from(out.stepper_target);
            if let (Some(buf), Some(e)) = (ch.control.as_mut(), ev_control) {
                if n_pulse.is_multiple_of(e as u64) {
                    let s = ControlSample {
                        t,
                        ticks,
                        omega: out.omega,
                        omega_a: out.omega_a,
                        omega_t: out.omega_t,
                        r_ol: out.r_ol,
                        r_d: out.r_d,
                        r: out.r,
                        stepper_target: out.stepper_target,
                        saturated: out.saturated,
                        fault: out.fault.code(),
                    };
                    buf.push(s);
                    sink(Sample::Control(s));
                }
            }
            (f64::from(out.r), out.saturated, out.fault.code() != 0)
        } else {
            let rs = r_schedule.as_ref().map_or(r, |s| s.at(t));
            r = rs;
            (rs, false, false)
        };
        met.pulse(t, omega_a, r_cmd - r_cmd_prev, t - last_pulse_t, sat, fault);
        r_cmd_prev = r_cmd;
        last_pulse_t = t;
        if let (Some(buf), Some(e)) = (ch.plant.as_mut(), ev_plant) {
            if n_pulse.is_multiple_of(e as u64) {
                let (v, tu) = drive.at_time(t);
                let s = PlantSample {
                    t,
                    theta: integ.theta(),
                    omega: integ.omega(),
                    omega_a,
                    r,
                    v_m: v,
                    t_u: tu,
                    i_a: integ.y[2],
                };
                buf.push(s);
                sink(Sample::Plant(s));
            }
        }
        if let (Some(buf), Some(e)) = (ch.stepper.as_mut(), ev_stepper) {
            if n_pulse.is_multiple_of(e as u64) {
                let s = StepperSample {
                    t,
                    target,
                    commanded: stepper.commanded,
                    position: stepper.position,
                    missed: stepper.missed,
                };
                buf.push(s);
                sink(Sample::Stepper(s));
            }
        }
        if let Some(buf) = ch.plot.as_mut() {
            if n_pulse.is_multiple_of(plot_every) {
                let (v, tu) = drive.at_time(t);
                buf.push([t, integ.omega(), omega_a, r, v, tu]);
            }
        }
        n_pulse += 1;
        k_pulse += 1;
        if t - last_progress > 0.01 * duration {
            last_progress = t;
            progress(t / duration);
        }
    }
    progress(1.0);
    let wall_s = wall.elapsed().as_secs_f64();
    let n_rate = met.n_rate.max(1) as f64;
    let summary = Summary {
        scene: scene.name.clone(),
        law: scene.controller.law.clone(),
        ppr: enc.ppr,
        duration_s: duration,
        omega0_rad_s: omega0,
        pulses: met.pulses,
        settling_time_s: if !met.seen {
            None
        } else {
            match met.last_out {
                None => Some(0.0),
                Some(t) if t >= last_pulse_t => None,
                Some(t) => Some(t - met.from),
            }
        },
        overshoot_pct: 100.0 * met.max_dev / omega0,
        undershoot_pct: -100.0 * met.min_dev / omega0,
        static_error_rad_s: if met.static_n > 0 {
            met.static_sum / met.static_n as f64
        } else {
            f64::NAN
        },
        final_omega_a_rad_s: met.final_omega_a,
        rms_control_effort_m_per_rad: (met.drdth_sq / n_rate).sqrt(),
        rms_dr_dt_m_per_s: (met.drdt_sq / n_rate).sqrt(),
        max_abs_dr_dt_m_per_s: met.max_drdt,
        saturated_fraction: met.saturated as f64 / n_rate,
        fault_pulses: met.faults,
        missed_steps: stepper.missed,
        integrator_steps: [
            integ.stats.time_steps,
            integ.stats.angle_steps,
            integ.stats.rejected,
        ],
        wall_time_s: wall_s,
        realtime_factor: duration / wall_s.max(1e-9),
    };
    Ok(RunResult {
        summary,
        channels: ch,
    })
}

impl Drive {
    /// `(V_m, T_U)` at `t` (inherent shortcut for [`crate::integrate::InputProfile::at`]).
    pub fn at_time(&self, t: f64) -> (f64, f64) {
        (self.v_m.at(t), self.t_u.at(t))
    }
}
