//! The closed loop in named stages: plant ⟶ encoder pulses ⟶ controller
//! backend ⟶ stepper ⟶ r.
//!
//! [`ClosedLoop::new`] sets up the plant, encoder, sensors, stepper and the
//! channel buffers the scene asks for. Then, one iteration per encoder pulse:
//! 1. [`ClosedLoop::read_sensors`]: every `sensors.period_s` the true V_m, T_U
//!    are read (noise, quantization) and given to `update_inputs`;
//! 2. [`ClosedLoop::advance_plant`]: integrate to the next pulse angle
//!    θ_k = k·2π/PPR (exactly, in the angle domain once ω > 0; stopping for
//!    sensor samples in between) while the stepper moves towards its target;
//! 3. [`ClosedLoop::encoder_pulse`]: timestamp the pulse with the encoder's
//!    timer (and jitter), ω_a from the exact pulse times of one revolution;
//! 4. [`ClosedLoop::control`]: hand the pulse to the backend (`on_pulse`,
//!    the call the firmware makes) or follow the r schedule;
//! 5. [`ClosedLoop::record`]: update the metrics and the channels.
//!
//! [`ClosedLoop::finish`] forms the summary.

use super::metrics::Metrics;
use super::{Channels, ControlSample, PlantSample, RunResult, SensorSample, StepperSample};
use crate::backend::ControllerBackend;
use crate::error::SimError;
use crate::integrate::{Method, PlantIntegrator, Reached, Tolerance};
use crate::plant::Plant;
use crate::profile::{Drive, Pwl};
use crate::record::{Channel, Sample};
use crate::scene::{IntegratorMethod, Scene};
use crate::sensors::{Encoder, Reading, Rng, Stepper};
use ivt_ctrl::ActuatorMap;

fn pwl(knots: &[[f64; 2]]) -> Pwl {
    Pwl::new(knots.iter().map(|&[t, v]| (t, v)).collect())
}

/// Channel decimations (None: not recorded).
struct Every {
    plant: Option<usize>,
    control: Option<usize>,
    stepper: Option<usize>,
    sensors: Option<usize>,
    plot: u64,
}

/// One encoder pulse as the loop sees it.
struct Pulse {
    t: f64,
    omega_a: f64,
    ticks: u32,
}

/// The state of one closed-loop run.
pub(super) struct ClosedLoop<'s> {
    scene: &'s Scene,
    backend: Option<Box<dyn ControllerBackend>>,
    integ: PlantIntegrator,
    drive: Drive,
    r_schedule: Option<Pwl>,
    rng: Rng,
    enc: Encoder,
    dtheta: f64,
    v_read: Reading,
    t_read: Reading,
    stepper: Stepper,
    every: Every,
    ch: Channels,
    met: Metrics,
    r: f64,
    target: i64,
    t_stepper: f64,
    k_pulse: i64,
    ring: Vec<f64>,
    n_pulse: u64,
    next_sensor: f64,
    n_sensor: u64,
    last_pulse_t: f64,
    r_cmd_prev: f64,
}

impl<'s> ClosedLoop<'s> {
    /// Set-up stage.
    pub(super) fn new(
        scene: &'s Scene,
        backend: Option<Box<dyn ControllerBackend>>,
    ) -> Result<Self, SimError> {
        let params = scene
            .plant_params()
            .map_err(|e| SimError::Scene(e.to_string()))?;
        let plant = Plant::new(params);
        let g = &scene.integrator;
        let tol = Tolerance {
            rtol: g.rtol,
            atol: g.atol,
        };
        let method = match g.method {
            IntegratorMethod::Rk4 => Method::Rk4 {
                dtheta: g.dtheta,
                startup: tol,
            },
            IntegratorMethod::Dp5 => Method::Dp5(tol),
        };
        let drive = Drive {
            v_m: pwl(&scene.inputs.v_m),
            t_u: pwl(&scene.inputs.t_u),
        };
        let r_schedule =
            (!scene.controller.r_schedule.is_empty()).then(|| pwl(&scene.controller.r_schedule));
        let enc = Encoder {
            ppr: scene.encoder.ppr,
            f_timer_hz: scene.encoder.f_timer_hz,
            jitter_s: scene.encoder.jitter_s,
        };
        let dtheta = enc.dtheta();
        let s = &scene.sensors;
        let map = ActuatorMap::sgivt(scene.stepper.steps_per_rev as f32);
        let r_per_step = 1.0 / f64::from(map.steps_per_metre);
        let st = &scene.stepper;
        let stepper = Stepper::new(
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

        let o = &scene.outputs;
        let omega0 = scene.omega0_rad_s();
        let est_pulses = scene.duration_s * omega0 / dtheta;
        let every = Every {
            plant: o.every(Channel::Plant),
            control: o.every(Channel::Control),
            stepper: o.every(Channel::Stepper),
            sensors: o.every(Channel::Sensors),
            plot: ((est_pulses / 4000.0).ceil() as u64).max(1),
        };
        let ch = Channels::recording(|c| o.every(c).is_some(), !o.plots.is_empty());
        let met = Metrics::new(scene, omega0, dtheta);
        let r = match &r_schedule {
            Some(s) if backend.is_none() => s.at(0.0),
            _ => stepper.r(),
        };
        let target = stepper.position;
        let k_pulse = (integ.theta() / dtheta).floor() as i64 + 1;
        let ring = vec![f64::NAN; enc.ppr + 1];
        Ok(Self {
            scene,
            backend,
            integ,
            drive,
            r_schedule,
            rng: Rng::new(scene.seed),
            enc,
            dtheta,
            v_read: Reading {
                noise: s.v_m_noise,
                quantum: s.v_m_quantum,
            },
            t_read: Reading {
                noise: s.t_u_noise,
                quantum: s.t_u_quantum,
            },
            stepper,
            every,
            ch,
            met,
            r,
            target,
            t_stepper: 0.0,
            k_pulse,
            ring,
            n_pulse: 0,
            next_sensor: 0.0,
            n_sensor: 0,
            last_pulse_t: 0.0,
            r_cmd_prev: r,
        })
    }

    /// Simulated time \[s\].
    pub(super) fn t(&self) -> f64 {
        self.integ.t
    }

    /// Stage 1: the slow readings, when one is due. Inlined into the loop
    /// of [`super::Simulation::run`], its one caller, like
    /// [`Self::on_pulse`]: a call per pulse is measurable in a scene.
    #[inline]
    pub(super) fn read_sensors(&mut self, sink: &mut dyn FnMut(Sample)) -> Result<(), SimError> {
        if self.integ.t < self.next_sensor {
            return Ok(());
        }
        let (v, tu) = self.drive.at_time(self.integ.t);
        let rv = self.v_read.read(v, &mut self.rng);
        let rt = self.t_read.read(tu, &mut self.rng);
        if let Some(b) = self.backend.as_mut() {
            b.update_inputs(rv as f32, rt as f32)?;
        }
        if let (Some(buf), Some(e)) = (self.ch.sensors.as_mut(), self.every.sensors) {
            if self.n_sensor.is_multiple_of(e as u64) {
                let s = SensorSample {
                    t: self.integ.t,
                    v_m: rv,
                    t_u: rt,
                };
                buf.push(s);
                sink(Sample::Sensors(s));
            }
        }
        self.n_sensor += 1;
        self.next_sensor += self.scene.sensors.period_s;
        Ok(())
    }

    /// Stage 2: integrate to the next pulse angle (or sensor time, or the
    /// end); the stepper moves towards its target meanwhile.
    pub(super) fn advance_plant(&mut self) -> Result<Reached, SimError> {
        let theta_k = self.k_pulse as f64 * self.dtheta;
        let until = self.next_sensor.min(self.scene.duration_s);
        let reached = self.integ.advance(&self.drive, self.r, theta_k, until)?;
        if self.backend.is_some() {
            self.stepper
                .advance(self.target, self.integ.t - self.t_stepper, &mut self.rng);
            self.t_stepper = self.integ.t;
            self.r = self.stepper.r();
        }
        Ok(reached)
    }

    /// Stage 3: the pulse's timestamp and ω_a over the last revolution of
    /// exact pulse times (NaN for the first revolution).
    fn encoder_pulse(&mut self) -> Pulse {
        let t = self.integ.t;
        let len = self.ring.len().max(1);
        let n = self.n_pulse as usize;
        let oldest = self.ring.get((n + 1) % len).copied().unwrap_or(f64::NAN);
        if let Some(slot) = self.ring.get_mut(n % len) {
            *slot = t;
        }
        let omega_a = if n >= self.enc.ppr {
            std::f64::consts::TAU / (t - oldest)
        } else {
            f64::NAN
        };
        Pulse {
            t,
            omega_a,
            ticks: self.enc.capture(t, &mut self.rng),
        }
    }

    /// Stage 4: the controller's answer (or the r schedule): the commanded
    /// r, whether it saturated, whether a fault was reported.
    fn control(
        &mut self,
        p: &Pulse,
        sink: &mut dyn FnMut(Sample),
    ) -> Result<(f64, bool, bool), SimError> {
        let Some(b) = self.backend.as_mut() else {
            let rs = self.r_schedule.as_ref().map_or(self.r, |s| s.at(p.t));
            self.r = rs;
            return Ok((rs, false, false));
        };
        let out = b.on_pulse(p.ticks)?;
        self.target = i64::from(out.stepper_target);
        if let (Some(buf), Some(e)) = (self.ch.control.as_mut(), self.every.control) {
            if self.n_pulse.is_multiple_of(e as u64) {
                let s = ControlSample {
                    t: p.t,
                    ticks: p.ticks,
                    out,
                };
                buf.push(s);
                sink(Sample::Control(s));
            }
        }
        Ok((f64::from(out.r), out.saturated, out.fault.code() != 0))
    }

    /// Stage 5: metrics and the plant, stepper and plot channels.
    fn record(&mut self, p: &Pulse, commanded: (f64, bool, bool), sink: &mut dyn FnMut(Sample)) {
        let (r_cmd, sat, fault) = commanded;
        let t = p.t;
        self.met.pulse(
            t,
            p.omega_a,
            r_cmd - self.r_cmd_prev,
            t - self.last_pulse_t,
            sat,
            fault,
        );
        self.r_cmd_prev = r_cmd;
        self.last_pulse_t = t;
        let n = self.n_pulse;
        if self.every.plant.is_some_and(|e| n.is_multiple_of(e as u64)) {
            let s = self.plant_sample(p);
            if let Some(buf) = self.ch.plant.as_mut() {
                buf.push(s);
            }
            sink(Sample::Plant(s));
        }
        if let (Some(buf), Some(e)) = (self.ch.stepper.as_mut(), self.every.stepper) {
            if n.is_multiple_of(e as u64) {
                let s = StepperSample {
                    t,
                    target: self.target,
                    commanded: self.stepper.commanded,
                    position: self.stepper.position,
                    missed: self.stepper.missed,
                };
                buf.push(s);
                sink(Sample::Stepper(s));
            }
        }
        if self.ch.plot.is_some() && n.is_multiple_of(self.every.plot) {
            let s = self.plant_sample(p);
            if let Some(buf) = self.ch.plot.as_mut() {
                buf.push(s);
            }
        }
    }

    /// The plant's state at the pulse `p`, as the `plant` channel logs it.
    fn plant_sample(&self, p: &Pulse) -> PlantSample {
        let (v, tu) = self.drive.at_time(p.t);
        PlantSample {
            t: p.t,
            theta: self.integ.theta(),
            omega: self.integ.omega(),
            omega_a: p.omega_a,
            r: self.r,
            v_m: v,
            t_u: tu,
            i_a: armature_current(&self.integ, v),
        }
    }

    /// Stages 3–5 for the pulse the plant just reached.
    #[inline]
    pub(super) fn on_pulse(&mut self, sink: &mut dyn FnMut(Sample)) -> Result<(), SimError> {
        let p = self.encoder_pulse();
        let commanded = self.control(&p, sink)?;
        self.record(&p, commanded, sink);
        self.n_pulse += 1;
        self.k_pulse += 1;
        Ok(())
    }

    /// The summary and the recorded channels.
    pub(super) fn finish(self, wall_s: f64) -> RunResult {
        let integ = &self.integ;
        let summary = self.met.summary(
            self.scene,
            self.last_pulse_t,
            self.stepper.missed,
            [
                integ.stats.time_steps,
                integ.stats.angle_steps,
                integ.stats.rejected,
            ],
            wall_s,
        );
        RunResult {
            summary,
            channels: self.ch,
        }
    }
}

/// Armature current \[A\]: the state i_a with an inductance (Eq. 137), the
/// algebraic (V_m − k_e f(θ) ω)/R_a of the quasi-static armature with
/// L_a = 0 (Eq. 138), where the state is not integrated.
fn armature_current(integ: &PlantIntegrator, v_m: f64) -> f64 {
    if integ.plant.params.l_a > 0.0 {
        integ.y[2]
    } else {
        integ
            .plant
            .quasi_static_current(integ.theta(), integ.omega(), v_m)
    }
}
