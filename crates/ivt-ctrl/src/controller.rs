//! The top-level controller: the three calls the firmware, the simulator and
//! the Python bindings drive (BRIEF controller contract).
//!
//! ```text
//! on_pulse(ticks)        encoder pulse → ω, ω_a, ω_T → law → r = u_ol + r_d → stepper target
//! update_inputs(V_m,T_U) slow readings → u_ol (Eq. 158–160), evaluated here, not per pulse
//! step_tick(now)         step/dir generator; also detects a stalled encoder
//! ```
//!
//! # Saturation and anti-windup
//! `r = clamp(u_ol + r_d, 0, r_max)`. After each increment the integrator
//! state itself is clamped to `[−u_ol, r_max − u_ol]`, so r_d never winds up
//! beyond the bound: r leaves a bound at the first pulse whose increment
//! points back inside. r_d is a Kahan-compensated sum, so 10⁶ tiny
//! increments do not drift against an f64 reference.
//!
//! # Faults and safe state
//! | code | [`Fault`] | cause | output |
//! |---|---|---|---|
//! | 0 | `None` | — | normal |
//! | 1 | `Stall` | no encoder pulse for `stall_timeout_s` (seen by `step_tick`, or a pulse arriving after that long) | r = `safe_r` (default 0: geared neutral, the motor is unloaded); averager, law and r_d reset; normal control resumes after a full revolution of fresh pulses (open loop r = u_ol until then) |
//! | 2 | `IntervalTooShort` | zero tick difference or faster than `omega_max` (double edge, noise) | pulse ignored, outputs held |
//! | 3 | `InputInvalid` | V_m or T_U NaN/∞ or outside the plausible sensor range `v_m_valid`/`t_u_valid` | reading ignored, last valid inputs held; code reported until a valid reading arrives |
//! | 4 | `Config` | invalid [`Config`] (non-finite or non-positive f_timer, ω0, r_max, limits; PPR = 0; …) | permanent safe state r = clamp(`safe_r`), no steps emitted |
//!
//! Readings that are plausible but outside the working region of the
//! open-loop fit are clamped, not faults: `ControlOutput::inputs_clamped`.
//! Before a full revolution has been seen (`ready == false`) the output is
//! the open-loop value and ω_a, ω_T read 0.

use crate::actuator::{ActuatorMap, StepGenerator};
use crate::averager::{AngleAverager, Targets};
pub use crate::config::{Config, Gains, LawKind};
use crate::law::{DelayLaw, FeedbackLaw, LawState, NoDelayLaw, NoFeedback, PropLaw, PulseSample};
use crate::open_loop::{clamp_f32, OlRegion, OpenLoopCoeffs, REFIT};

coded_enum! {
    /// Fault codes (see the module doc for the safe state of each).
    pub enum Fault {
        /// No fault.
        #[default]
        None = 0,
        /// Encoder stalled (no pulse within the timeout).
        Stall = 1,
        /// Zero or implausibly short pulse interval; the pulse was ignored.
        IntervalTooShort = 2,
        /// NaN/∞ or implausible V_m/T_U reading; it was ignored.
        InputInvalid = 3,
        /// Invalid configuration; permanent safe state.
        Config = 4,
    }
}

/// What one pulse produces (the parts of the law, as the simulator logs them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlOutput {
    /// ω over the last pulse \[rad/s\] (0 before two pulses).
    pub omega: f32,
    /// ω_a, mean over the last revolution \[rad/s\] (0 until `ready`).
    pub omega_a: f32,
    /// ω_T, ω one revolution earlier \[rad/s\] (0 until `ready`).
    pub omega_t: f32,
    /// Open-loop part u_ol \[m\] (0 if `feedforward` is off).
    pub r_ol: f32,
    /// Feedback part r_d \[m\].
    pub r_d: f32,
    /// Commanded eccentricity r ∈ \[0, r_max\] \[m\].
    pub r: f32,
    /// Stepper position for r \[steps\].
    pub stepper_target: i32,
    /// True if r is at a bound (anti-windup active).
    pub saturated: bool,
    /// Fault code of this call.
    pub fault: Fault,
    /// True once a full revolution of pulses has been seen and the law runs.
    pub ready: bool,
    /// True if the open-loop inputs were clamped to the working region.
    pub inputs_clamped: bool,
    /// Branch of Eq. 160 for the current inputs.
    pub ol_region: OlRegion,
}

impl ControlOutput {
    /// The output before any pulse: everything zero, no fault, not ready
    /// (what a firmware shows before its first encoder edge).
    pub const IDLE: Self = Self {
        omega: 0.0,
        omega_a: 0.0,
        omega_t: 0.0,
        r_ol: 0.0,
        r_d: 0.0,
        r: 0.0,
        stepper_target: 0,
        saturated: false,
        fault: Fault::None,
        ready: false,
        inputs_clamped: false,
        ol_region: OlRegion::Normal,
    };
}

/// What one step-generator tick produces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepTick {
    /// Emit a step pulse now.
    pub step: bool,
    /// Direction line: true = towards larger positions (larger r for a positive map).
    pub forward: bool,
    /// Stepper position after this tick \[steps\].
    pub position: i32,
    /// Timer tick at which the next step is due (while `moving`).
    pub next_step_at: u32,
    /// True while a move is in progress.
    pub moving: bool,
    /// `Fault::Stall` if the encoder has stalled, else the last pulse's fault.
    pub fault: Fault,
}

/// The rig controller for an encoder sampled `PPR` times per revolution of θ.
#[derive(Clone, Debug)]
pub struct Controller<const PPR: usize> {
    averager: AngleAverager<PPR>,
    law: LawState,
    stepper: StepGenerator,
    open_loop: OpenLoopCoeffs,
    actuator: ActuatorMap,
    /// r_d and its Kahan compensation.
    r_d: f32,
    r_d_comp: f32,
    targets: Targets,
    dtheta: f32,
    safe_r: f32,
    v_m_valid: [f32; 2],
    t_u_valid: [f32; 2],
    min_interval: u32,
    max_interval: u32,
    decimation: u16,
    skip: u16,
    feedforward: bool,
    config_ok: bool,
    running: bool,
    stalled: bool,
    input_fault: bool,
    last_raw: u32,
    omega_prev: f32,
    /// Commissioning hold: r commanded as given, the law does not act.
    hold: Option<f32>,
    out: ControlOutput,
}

impl<const PPR: usize> Controller<PPR> {
    /// A controller for `config`. An invalid config gives a controller in the
    /// permanent `Fault::Config` safe state (never a panic).
    ///
    /// This returns the ~5 KiB controller by value; firmware that keeps it in
    /// a `static` should use [`Controller::unconfigured`] as the static's
    /// initializer and [`Controller::reset`] at boot (no stack copy).
    #[must_use]
    pub fn new(config: Config) -> Self {
        let mut c = Self::unconfigured();
        c.reset(config);
        c
    }

    /// A controller with no configuration yet, usable as a `static`
    /// initializer: it is in the `Fault::Config` safe state (r = 0, no steps)
    /// until [`Controller::reset`] gives it a valid [`Config`].
    #[must_use]
    pub const fn unconfigured() -> Self {
        Self {
            averager: AngleAverager::unconfigured(),
            law: LawState::Open(NoFeedback),
            stepper: StepGenerator::unconfigured(),
            open_loop: REFIT,
            actuator: ActuatorMap {
                steps_per_metre: 0.0,
                offset_steps: 0,
            },
            r_d: 0.0,
            r_d_comp: 0.0,
            targets: Targets::NONE,
            dtheta: 0.0,
            safe_r: 0.0,
            v_m_valid: [0.0; 2],
            t_u_valid: [0.0; 2],
            min_interval: 1,
            max_interval: 1,
            decimation: 1,
            skip: 0,
            feedforward: false,
            config_ok: false,
            running: false,
            stalled: false,
            input_fault: false,
            last_raw: 0,
            omega_prev: 0.0,
            hold: None,
            out: ControlOutput {
                fault: Fault::Config,
                ..ControlOutput::IDLE
            },
        }
    }

    /// (Re)configure in place: forget the pulse history, the law state and
    /// r_d, and start over as [`Controller::new`] would — without building a
    /// second controller (the timestamp ring is not touched, only marked
    /// empty). The stepper keeps its physical position but stops its ramp
    /// (the next move starts from rest).
    pub fn reset(&mut self, config: Config) {
        let config_ok = config.is_valid(PPR);
        let f = config.f_timer_hz;
        let decimation = config.decimation.max(1);
        let samples = PPR as f32 * f32::from(decimation);
        let dtheta_enc = core::f32::consts::TAU / samples;
        // Shortest accepted interval: a pulse at omega_max. Longest: the stall
        // timeout, and at most u32::MAX/(PPR+1)·decimation so one revolution
        // always spans fewer than 2³² ticks (wrapping differences stay exact).
        let min_interval = ((f * dtheta_enc / config.omega_max) as u32).max(1);
        let rev_cap = u32::MAX
            / (PPR as u32)
                .saturating_add(1)
                .saturating_mul(u32::from(decimation));
        let stall = (config.stall_timeout_s * f) as u32;
        let period = (config.gains.prop_period_s * f) as u32;
        let (k, k2) = (config.gains.k, config.gains.k2);
        self.law = match config.law {
            LawKind::Delay => LawState::Delay(DelayLaw { k, k2 }),
            LawKind::NoDelay => LawState::NoDelay(NoDelayLaw { k, k2 }),
            LawKind::Prop => LawState::Prop(PropLaw::new(config.gains.k_prop, period)),
            LawKind::Open => LawState::Open(NoFeedback),
        };
        self.averager.configure(f);
        self.stepper.configure(config.stepper, f);
        self.open_loop = config.open_loop;
        self.actuator = config.actuator;
        self.r_d = 0.0;
        self.r_d_comp = 0.0;
        self.targets = AngleAverager::<PPR>::targets(f, config.omega0);
        self.dtheta = core::f32::consts::TAU / (PPR.max(1) as f32);
        self.safe_r = config.safe_r;
        self.v_m_valid = config.v_m_valid;
        self.t_u_valid = config.t_u_valid;
        self.min_interval = min_interval;
        self.max_interval = stall.min(rev_cap).min(0x7FFF_FFFF).max(min_interval);
        self.decimation = decimation;
        self.skip = 0;
        self.feedforward = config.feedforward;
        self.config_ok = config_ok;
        self.running = false;
        self.stalled = false;
        self.input_fault = false;
        self.last_raw = 0;
        self.omega_prev = 0.0;
        self.hold = None;
        self.out = Self::unconfigured().out;
        let [v, t] = config.initial_inputs;
        self.set_inputs(v, t);
        if config_ok {
            self.command(Fault::None);
        } else {
            self.enter_safe(Fault::Config);
        }
    }

    /// Commissioning hold (`crate::commission`): while `Some(r)`, every call
    /// commands r (limited to \[0, r_max\]) and the law's increments are
    /// discarded; averaging, faults and the stepper run as usual. `None`
    /// releases it: the law goes on from the held r (r_d = r − u_ol). Takes
    /// effect at the next pulse or input update.
    pub fn set_hold(&mut self, r: Option<f32>) {
        self.hold = r;
    }

    /// r_max of the open-loop coefficient set \[m\].
    #[must_use]
    pub fn r_max(&self) -> f32 {
        self.open_loop.r_max
    }

    /// The output of the most recent call (pulse, input update or stall).
    #[must_use]
    pub fn output(&self) -> ControlOutput {
        self.out
    }

    /// Clamp without the `f32::clamp` assertion; NaN → lo.
    #[inline]
    fn clamp_r(&self, r: f32) -> f32 {
        if r.is_nan() {
            0.0
        } else {
            clamp_f32(r, 0.0, self.open_loop.r_max)
        }
    }

    /// Evaluate u_ol for (already validated) inputs.
    fn set_inputs(&mut self, v_m: f32, t_u: f32) {
        let ol = self.open_loop.evaluate(v_m, t_u);
        self.out.r_ol = if self.feedforward { ol.r_ol } else { 0.0 };
        self.out.inputs_clamped = ol.inputs_clamped;
        self.out.ol_region = ol.region;
    }

    /// Form r from r_ol and r_d with saturation and anti-windup, and set the
    /// stepper target.
    fn command(&mut self, fault: Fault) {
        let r_ol = self.out.r_ol;
        if let Some(r) = self.hold {
            // The held r is reached through r_d, so the law resumes from it
            // (bumpless) when the hold is released.
            self.r_d = r - r_ol;
            self.r_d_comp = 0.0;
        }
        let lo = -r_ol;
        let hi = self.open_loop.r_max - r_ol;
        let mut saturated = false;
        if self.r_d < lo {
            self.r_d = lo;
            self.r_d_comp = 0.0;
            saturated = true;
        } else if self.r_d > hi {
            self.r_d = hi;
            self.r_d_comp = 0.0;
            saturated = true;
        }
        let r = self.clamp_r(r_ol + self.r_d);
        saturated |= r <= 0.0 || r >= self.open_loop.r_max;
        self.out.r_d = self.r_d;
        self.out.r = r;
        self.out.saturated = saturated;
        self.set_target(r);
        self.out.fault = self.reported_fault(fault, self.held_input_fault());
    }

    /// Fault precedence, the one rule every call reports by: the call's own
    /// event (a stall seen by this pulse, a too-short interval, an invalid
    /// reading just given, a bad config) first; else a held stall; else
    /// `held`, what the call carries over (a pulse or an input update: a held
    /// invalid reading, [`Self::held_input_fault`]; a step tick: the last
    /// call's fault).
    fn reported_fault(&self, event: Fault, held: Fault) -> Fault {
        if event != Fault::None {
            event
        } else if self.stalled {
            Fault::Stall
        } else {
            held
        }
    }

    /// `Fault::InputInvalid` while the last V_m/T_U reading was invalid.
    fn held_input_fault(&self) -> Fault {
        if self.input_fault {
            Fault::InputInvalid
        } else {
            Fault::None
        }
    }

    fn set_target(&mut self, r: f32) {
        let target = self.actuator.steps(r);
        self.out.stepper_target = target;
        self.stepper.set_target(target);
    }

    /// Safe state: r = safe_r, history and integrator forgotten.
    fn enter_safe(&mut self, fault: Fault) {
        self.averager.reset();
        self.law.reset(self.last_raw);
        self.r_d = 0.0;
        self.r_d_comp = 0.0;
        self.skip = 0;
        let r = self.clamp_r(self.safe_r);
        self.out.omega = 0.0;
        self.out.omega_a = 0.0;
        self.out.omega_t = 0.0;
        self.out.r_d = 0.0;
        self.out.r = r;
        self.out.saturated = false;
        self.out.ready = false;
        self.out.fault = fault;
        self.set_target(r);
    }

    /// One encoder pulse with its timer timestamp \[ticks\]. O(1), no trig,
    /// no heap; see the module doc for faults.
    pub fn on_pulse(&mut self, ticks: u32) -> ControlOutput {
        if !self.config_ok {
            return self.out;
        }
        let mut event = Fault::None;
        if self.running {
            let dt = ticks.wrapping_sub(self.last_raw);
            if dt < self.min_interval {
                // Double edge or noise: ignore the pulse, hold the outputs.
                self.out.fault = Fault::IntervalTooShort;
                return self.out;
            }
            if dt > self.max_interval {
                // Restart after a stall: this pulse is the first of a new history.
                self.enter_safe(Fault::Stall);
                event = Fault::Stall;
            }
        }
        self.running = true;
        self.stalled = false;
        self.last_raw = ticks;
        if self.skip > 0 {
            self.skip -= 1;
            self.out.fault = self.reported_fault(event, self.held_input_fault());
            return self.out;
        }
        self.skip = self.decimation - 1;

        let s = self.averager.push(ticks);
        let omega = s.omega.unwrap_or(0.0);
        self.out.omega = omega;
        match (s.omega_a, s.omega_t) {
            (Some(omega_a), Some(omega_t)) => {
                self.out.omega_a = omega_a;
                self.out.omega_t = omega_t;
                self.out.ready = true;
                let sample = PulseSample {
                    ticks,
                    omega,
                    omega_prev: self.omega_prev,
                    omega_t,
                    omega_a_err: self.targets.omega_a_error(s.revolution_ticks),
                    omega_err: self.targets.omega_error(s.interval_ticks),
                    dtheta: self.dtheta,
                };
                let inc = self.law.increment(&sample);
                if inc.is_finite() {
                    // Kahan-compensated r_d += inc.
                    let y = inc - self.r_d_comp;
                    let t = self.r_d + y;
                    self.r_d_comp = (t - self.r_d) - y;
                    self.r_d = t;
                }
            }
            (omega_a, _) => {
                self.out.omega_a = omega_a.unwrap_or(0.0);
                self.out.omega_t = 0.0;
                self.out.ready = false;
            }
        }
        self.omega_prev = omega;
        self.command(event);
        self.out
    }

    /// Slow readings: motor voltage V_m \[V\] and brake torque T_U \[N·m\].
    /// Invalid readings are ignored and flagged (`Fault::InputInvalid`).
    pub fn update_inputs(&mut self, v_m: f32, t_u: f32) {
        if !self.config_ok {
            return;
        }
        let inside = |x: f32, r: [f32; 2]| x.is_finite() && x >= r[0] && x <= r[1];
        let event = if inside(v_m, self.v_m_valid) && inside(t_u, self.t_u_valid) {
            self.input_fault = false;
            self.set_inputs(v_m, t_u);
            Fault::None
        } else {
            self.input_fault = true;
            Fault::InputInvalid
        };
        if self.stalled {
            self.out.fault = self.reported_fault(event, self.held_input_fault());
        } else {
            self.command(event);
        }
    }

    /// Step-generator tick at `now` \[ticks\]: whether to emit a step now and
    /// in which direction. Also declares a stall if no pulse arrived within
    /// the timeout.
    pub fn step_tick(&mut self, now: u32) -> StepTick {
        if self.config_ok && self.running && !self.stalled {
            let since = now.wrapping_sub(self.last_raw);
            if since > self.max_interval && since < 0x8000_0000 {
                self.stalled = true;
                self.enter_safe(Fault::Stall);
            }
        }
        let d = self.stepper.tick(now);
        StepTick {
            step: d.step,
            forward: d.forward,
            position: d.position,
            next_step_at: d.next_step_at,
            moving: d.moving,
            // A stall detected here or held outranks the last call's fault.
            fault: self.reported_fault(Fault::None, self.out.fault),
        }
    }
}

// Issue 5: the controller for the thesis's 1200-line encoder fits in 5 KiB
// (4800 bytes of timestamps + state). Checked at compile time on every target.
const _: () = assert!(core::mem::size_of::<Controller<1200>>() <= 5 * 1024);
