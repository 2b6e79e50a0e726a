//! Commissioning sequences of the rig (§4.4.2–4.4.3), as a state machine the
//! firmware runs without a host and the simulator runs against its plant.
//!
//! A [`Plan`] lists four sequences; a [`Selection`] picks some of them, run
//! in the order below. Each is a list of [`Stage`]s of fixed duration:
//!
//! | sequence | stages | thesis |
//! |---|---|---|
//! | [`SequenceName::Sweep`] | stepper angle θ_CT = 0, step, 2·step, … ≤ `to_deg` (and ≤ the θ_CT of r_max), each held | Fig. 47, Eq. 185 (average ratio ∝ θ_CT) |
//! | [`SequenceName::Hold`] | θ_CT held at one angle, every encoder edge logged | Fig. 48 (instantaneous ratio) |
//! | [`SequenceName::Step`] | `points` θ_CT holds at constant V_m, T_U (the ω_m–θ_CT line of Eq. 187, slope K₂T_out), then the proportional law Eq. 189 from the last angle, then a T_U step under the law | Fig. 50, Eq. 186–190 |
//! | [`SequenceName::Drive`] | six stages of V_m, T_U set-points; law off (θ_CT = 0) in the first and the last | Fig. 51 |
//!
//! Every edge is logged (the pulse log) in the holds of the sweep, the hold
//! and the step test: the encoder edge times at constant θ_CT are what
//! identification fits Eq. 151 to (`ivt rig identify`); a recording whose
//! edges come from the one hold at constant inputs and r leaves Eq. 151's
//! regressors collinear. The law stages and the drive cycle log none.
//!
//! A held stage commands `r = θ_CT · SGIVT_M_PER_DEG` (Eq. 185) through
//! [`Controller::set_hold`]; a law stage releases the hold, and the law
//! continues from the held r (bumpless: r_d starts at r − u_ol). V_m and T_U
//! of a stage are *set-points for the bench* (the supplies of the DC motor
//! and the brake): the firmware only reads them; the simulator applies them
//! as its input profiles ([`Plan::stage`] gives them to both).
//!
//! Stages advance on the encoder's timestamps: stage k starts at the first
//! pulse at or after `t0 + Σ_{j<k} duration_j` (t0 = the first pulse), so
//! the schedule does not drift with the pulse spacing. f32, no heap, no panic
//! path.

use crate::controller::{ControlOutput, Controller};
use crate::units::SGIVT_M_PER_DEG;

coded_enum! {
    /// The four commissioning sequences (wire codes in brackets).
    pub enum SequenceName {
        /// Stepper-angle sweep with holds, Fig. 47.
        #[default]
        Sweep = 0,
        /// Hold at one θ_CT with the pulse log, Fig. 48.
        Hold = 1,
        /// θ_CT holds and a proportional-law step test, Fig. 50, Eq. 186–190.
        Step = 2,
        /// The drive cycle, Fig. 51.
        Drive = 3,
    }
}

impl SequenceName {
    /// All four, in run order.
    pub const ALL: [Self; 4] = [Self::Sweep, Self::Hold, Self::Step, Self::Drive];

    /// The name used on the command line and in recordings.
    #[must_use]
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Sweep => "sweep",
            Self::Hold => "hold",
            Self::Step => "step",
            Self::Drive => "drive",
        }
    }

    /// The sequence called `name` (see [`SequenceName::as_str`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.as_str() == name)
    }
}

/// Which sequences run: bit `code` set for each selected [`SequenceName`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Selection(pub u8);

impl Selection {
    /// Every sequence, in order.
    pub const ALL: Self = Self(0b1111);

    /// One sequence alone.
    #[must_use]
    pub fn only(s: SequenceName) -> Self {
        Self(1 << s.code())
    }

    /// True if `s` is selected.
    #[must_use]
    pub fn contains(self, s: SequenceName) -> bool {
        self.0 & (1 << s.code()) != 0
    }
}

/// Stepper-angle sweep (Fig. 47).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepPlan {
    /// Last angle \[deg\] (the thesis: 3600°); also limited by r_max.
    pub to_deg: f32,
    /// Angle step \[deg\] (the thesis: 100°).
    pub step_deg: f32,
    /// Hold time per angle \[s\].
    pub hold_s: f32,
    /// Bench set-points V_m \[V\], T_U \[N·m\].
    pub inputs: [f32; 2],
}

/// Hold with the pulse log (Fig. 48).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoldPlan {
    /// Held angle \[deg\] (the thesis: 3600°), limited by r_max.
    pub theta_ct_deg: f32,
    /// Duration \[s\] (the thesis: 75 revolutions of θ_in).
    pub hold_s: f32,
    /// Bench set-points V_m \[V\], T_U \[N·m\].
    pub inputs: [f32; 2],
}

/// θ_CT holds and the proportional-law step test (Fig. 50, Eq. 186–190).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepPlan {
    /// First and last held angle \[deg\].
    pub range_deg: [f32; 2],
    /// Number of held angles (≥ 2 for a slope).
    pub points: u8,
    /// Hold time per angle \[s\].
    pub hold_s: f32,
    /// Duration of each of the two law stages \[s\].
    pub law_s: f32,
    /// Bench set-points V_m \[V\], T_U \[N·m\] of the holds and the first law stage.
    pub inputs: [f32; 2],
    /// T_U of the second law stage \[N·m\] (the step).
    pub t_u_step: f32,
}

/// Number of stages of the drive cycle (Fig. 51).
pub const DRIVE_STAGES: usize = 6;

/// The drive cycle (Fig. 51): per stage the duration \[s\] and the bench
/// set-points V_m \[V\], T_U \[N·m\]; the law runs in stages 2–5, θ_CT = 0
/// is held in stages 1 (idle) and 6 (controller shut down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrivePlan {
    /// `[duration_s, v_m, t_u]` per stage.
    pub stages: [[f32; 3]; DRIVE_STAGES],
}

/// The four sequences' parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    /// Fig. 47.
    pub sweep: SweepPlan,
    /// Fig. 48.
    pub hold: HoldPlan,
    /// Fig. 50.
    pub step: StepPlan,
    /// Fig. 51.
    pub drive: DrivePlan,
}

impl Default for Plan {
    /// Angles of the thesis (0…3600° by 100°, the hold at 3600°), limited
    /// by r_max when run; set-points inside the feasible band of the printed
    /// plant at 100 rpm (V_m ∈ [7.869, 7.869 + 0.1537·T_U], scenes/drive.toml),
    /// the drive cycle's values those of `scenes/drive.toml`.
    fn default() -> Self {
        Self {
            sweep: SweepPlan {
                to_deg: 3600.0,
                step_deg: 100.0,
                hold_s: 2.0,
                // T_U = 7.35 N·m: the load at which Fig. 50's slope K₂T_out
                // is 0.0128 rpm/deg (§4.4.3) on the printed plant.
                inputs: [8.6, 7.35],
            },
            hold: HoldPlan {
                theta_ct_deg: 3600.0,
                hold_s: 10.0,
                inputs: [8.6, 6.0],
            },
            step: StepPlan {
                range_deg: [300.0, 800.0],
                points: 6,
                hold_s: 2.0,
                law_s: 8.0,
                inputs: [8.6, 6.0],
                t_u_step: 8.0,
            },
            drive: DrivePlan {
                stages: [
                    [5.0, 7.938, 1.5],
                    [7.0, 8.622, 7.0],
                    [12.0, 8.176, 4.0],
                    [14.0, 8.914, 8.5],
                    [12.0, 7.946, 2.0],
                    [10.0, 7.961, 1.5],
                ],
            },
        }
    }
}

/// One stage of a sequence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stage {
    /// The sequence it belongs to.
    pub sequence: SequenceName,
    /// Its index inside the sequence (from 0).
    pub index: u16,
    /// Held stepper angle \[deg\] (after the r_max limit); NaN when the law runs.
    pub theta_ct_deg: f32,
    /// True if θ_CT is held (the law does not act).
    pub hold: bool,
    /// Duration \[s\].
    pub duration_s: f32,
    /// Bench set-points V_m \[V\], T_U \[N·m\].
    pub inputs: [f32; 2],
    /// True if every encoder edge is logged (Fig. 48; the holds that
    /// identification fits Eq. 151 to).
    pub pulse_log: bool,
}

impl Plan {
    /// Number of stages of `seq` when r is limited to `r_max` \[m\].
    #[must_use]
    pub fn stages_of(&self, seq: SequenceName, r_max: f32) -> u16 {
        match seq {
            SequenceName::Sweep => {
                let s = &self.sweep;
                let top = min_f32(s.to_deg, max_angle_deg(r_max));
                if !(s.step_deg > 0.0 && top >= 0.0) {
                    return 0;
                }
                // `as` saturates (NaN → 0): no panic path.
                ((top / s.step_deg) as u16).saturating_add(1)
            }
            SequenceName::Hold => 1,
            SequenceName::Step => u16::from(self.step.points).saturating_add(2),
            SequenceName::Drive => DRIVE_STAGES as u16,
        }
    }

    /// Stage `k` (counted over the selected sequences in order) when r is
    /// limited to `r_max` \[m\]; None past the last one.
    #[must_use]
    pub fn stage(&self, sel: Selection, k: u32, r_max: f32) -> Option<Stage> {
        let mut k = k;
        for seq in SequenceName::ALL {
            if !sel.contains(seq) {
                continue;
            }
            let n = u32::from(self.stages_of(seq, r_max));
            if k < n {
                return Some(self.stage_of(seq, k as u16, r_max));
            }
            k -= n;
        }
        None
    }

    /// Total duration of the selected sequences \[s\].
    #[must_use]
    pub fn duration_s(&self, sel: Selection, r_max: f32) -> f32 {
        let mut total = 0.0;
        let mut k = 0;
        while let Some(s) = self.stage(sel, k, r_max) {
            total += s.duration_s;
            k += 1;
        }
        total
    }

    fn stage_of(&self, sequence: SequenceName, index: u16, r_max: f32) -> Stage {
        let top = max_angle_deg(r_max);
        let held = |deg: f32, duration_s: f32, inputs: [f32; 2], pulse_log: bool| Stage {
            sequence,
            index,
            theta_ct_deg: clamp_angle(deg, top),
            hold: true,
            duration_s,
            inputs,
            pulse_log,
        };
        let law = |duration_s: f32, inputs: [f32; 2]| Stage {
            sequence,
            index,
            theta_ct_deg: f32::NAN,
            hold: false,
            duration_s,
            inputs,
            pulse_log: false,
        };
        match sequence {
            SequenceName::Sweep => {
                let s = &self.sweep;
                held(f32::from(index) * s.step_deg, s.hold_s, s.inputs, true)
            }
            SequenceName::Hold => {
                let h = &self.hold;
                held(h.theta_ct_deg, h.hold_s, h.inputs, true)
            }
            SequenceName::Step => {
                let s = &self.step;
                let n = u16::from(s.points);
                if index < n {
                    let [a, b] = s.range_deg;
                    let frac = if n > 1 {
                        f32::from(index) / f32::from(n - 1)
                    } else {
                        0.0
                    };
                    held(a + (b - a) * frac, s.hold_s, s.inputs, true)
                } else if index == n {
                    law(s.law_s, s.inputs)
                } else {
                    law(s.law_s, [s.inputs[0], s.t_u_step])
                }
            }
            SequenceName::Drive => {
                let last = DRIVE_STAGES - 1;
                let i = usize::from(index).min(last);
                let [d, v, t] = self.drive.stages.get(i).copied().unwrap_or([0.0; 3]);
                if i == 0 || i == last {
                    held(0.0, d, [v, t], false)
                } else {
                    law(d, [v, t])
                }
            }
        }
    }
}

/// The stepper angle of eccentricity `r_max` \[deg\] (Eq. 185).
#[must_use]
pub fn max_angle_deg(r_max: f32) -> f32 {
    r_max / SGIVT_M_PER_DEG
}

/// Eccentricity of a stepper angle \[m\] (Eq. 185).
#[must_use]
pub fn r_of_angle(theta_ct_deg: f32) -> f32 {
    theta_ct_deg * SGIVT_M_PER_DEG
}

fn min_f32(a: f32, b: f32) -> f32 {
    if b < a {
        b
    } else {
        a
    }
}

/// `deg` limited to `[0, top]` (NaN → 0).
fn clamp_angle(deg: f32, top: f32) -> f32 {
    if deg.is_nan() || deg < 0.0 {
        0.0
    } else {
        min_f32(deg, top)
    }
}

/// What one pulse of a running sequence produced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SequenceStep {
    /// The controller's output.
    pub out: ControlOutput,
    /// The stage that started at this pulse, if one did.
    pub started: Option<Stage>,
    /// Global index of the current stage (over the selected sequences).
    pub stage: u32,
    /// True while the current stage logs every edge.
    pub pulse_log: bool,
    /// True once the last stage has ended (the controller runs its law on).
    pub done: bool,
}

/// The commissioning state machine: drives a [`Controller`] through the
/// stages of a [`Plan`] on the encoder's timestamps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sequencer {
    plan: Plan,
    sel: Selection,
    f_timer_hz: f32,
    /// Global index of the current stage.
    k: u32,
    current: Option<Stage>,
    /// Ticks since the first pulse (unwrapped) and the last raw timestamp.
    elapsed: u64,
    last: u32,
    /// Ticks since the first pulse at which the current stage ends.
    stage_end: u64,
    started: bool,
    done: bool,
}

impl Sequencer {
    /// A sequencer for `plan`'s selected sequences, on a timer at
    /// `f_timer_hz` (the controller's); nothing happens until the first pulse.
    #[must_use]
    pub const fn new(plan: Plan, sel: Selection, f_timer_hz: f32) -> Self {
        Self {
            plan,
            sel,
            f_timer_hz,
            k: 0,
            current: None,
            elapsed: 0,
            last: 0,
            stage_end: 0,
            started: false,
            done: false,
        }
    }

    /// The plan it runs.
    #[must_use]
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The selected sequences.
    #[must_use]
    pub fn selection(&self) -> Selection {
        self.sel
    }

    /// True once the last stage has ended.
    #[must_use]
    pub fn done(&self) -> bool {
        self.done
    }

    /// One encoder pulse: advance the stage if its time is up, apply its hold,
    /// and run the controller's pulse path.
    pub fn on_pulse<const PPR: usize>(
        &mut self,
        ctrl: &mut Controller<PPR>,
        ticks: u32,
    ) -> SequenceStep {
        let r_max = ctrl.r_max();
        let mut started = None;
        if self.started {
            self.elapsed += u64::from(ticks.wrapping_sub(self.last));
        } else {
            self.started = true;
            started = self.enter(0, r_max);
        }
        self.last = ticks;
        while !self.done && self.elapsed >= self.stage_end {
            started = self.enter(self.k + 1, r_max);
        }
        match self.current {
            Some(s) if s.hold && !self.done => ctrl.set_hold(Some(r_of_angle(s.theta_ct_deg))),
            _ => ctrl.set_hold(None),
        }
        let out = ctrl.on_pulse(ticks);
        SequenceStep {
            out,
            started,
            stage: self.k,
            pulse_log: !self.done && self.current.is_some_and(|s| s.pulse_log),
            done: self.done,
        }
    }

    /// Makes stage `k` current (or ends the run); returns it.
    fn enter(&mut self, k: u32, r_max: f32) -> Option<Stage> {
        self.k = k;
        match self.plan.stage(self.sel, k, r_max) {
            Some(s) => {
                // `as` saturates, NaN → 0: a bad duration ends the stage at once.
                let ticks = (s.duration_s * self.f_timer_hz) as u64;
                self.stage_end = self.stage_end.saturating_add(ticks);
                self.current = Some(s);
                Some(s)
            }
            None => {
                self.done = true;
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controller::{Config, LawKind};

    #[test]
    fn sweep_is_limited_by_r_max_and_counts_stages() {
        let plan = Plan::default();
        // r_max = 12 mm ↔ 1113.6° (Eq. 185): 0, 100, …, 1100 → 12 stages.
        let top = max_angle_deg(0.012);
        assert!((top - 0.012 / (7.0 * core::f32::consts::PI / 51840.0 * 0.0254)).abs() < 1e-3);
        assert_eq!(plan.stages_of(SequenceName::Sweep, 0.012), 12);
        // With room for 3600° the thesis's 37 angles.
        assert_eq!(plan.stages_of(SequenceName::Sweep, 1.0), 37);
        let s = plan.stage(Selection::ALL, 11, 0.012).unwrap();
        assert_eq!(
            (s.sequence, s.index, s.theta_ct_deg),
            (SequenceName::Sweep, 11, 1100.0)
        );
        // The hold at 3600° is limited to r_max's angle.
        let h = plan.stage(Selection::ALL, 12, 0.012).unwrap();
        assert_eq!(h.sequence, SequenceName::Hold);
        assert_eq!(h.theta_ct_deg, top);
        assert!(h.pulse_log);
        // 12 + 1 + 8 + 6 stages, then nothing.
        assert!(plan.stage(Selection::ALL, 26, 0.012).is_some());
        assert!(plan.stage(Selection::ALL, 27, 0.012).is_none());
        let d = plan
            .stage(Selection::only(SequenceName::Drive), 3, 0.012)
            .unwrap();
        assert_eq!((d.hold, d.inputs), (false, [8.914, 8.5]));
        let total = plan.duration_s(Selection::ALL, 0.012);
        assert!(
            (total - (24.0 + 10.0 + 12.0 + 16.0 + 60.0)).abs() < 1e-3,
            "{total}"
        );
    }

    #[test]
    fn sequencer_holds_then_releases_on_schedule() {
        let mut cfg = Config {
            law: LawKind::Prop,
            feedforward: false,
            ..Config::default()
        };
        cfg.gains.k_prop = 1e-4; // m per rad/s: one increment stays far from the bounds
        let mut c = Controller::<16>::new(cfg);
        let mut plan = Plan::default();
        plan.step = StepPlan {
            range_deg: [100.0, 200.0],
            points: 2,
            hold_s: 1.0,
            law_s: 1.0,
            inputs: [8.0, 8.0],
            ..plan.step
        };
        let mut seq = Sequencer::new(plan, Selection::only(SequenceName::Step), 1.0e6);
        // 10 rad/s at 16 pulses/rev: a pulse every 39 269 µs.
        let dt = (core::f32::consts::TAU / 16.0 / 10.0 * 1.0e6) as u32;
        let mut starts = [0u32; 8];
        let mut n = 0;
        let mut r = [0f32; 120];
        let mut done = false;
        for i in 0..120u32 {
            let t = 0xFFF0_0000u32.wrapping_add(i * dt); // across the u32 wrap
            let st = seq.on_pulse(&mut c, t);
            if st.started.is_some() {
                starts[n] = i;
                n += 1;
            }
            r[i as usize] = st.out.r;
            done = st.done;
        }
        // Stages at 0, 1, 2, 3 s: the first pulse at or after each.
        assert_eq!(&starts[..n], &[0, 26, 51, 77]);
        assert!(done);
        // Holds: r = Eq. 185 of the angle, whatever the law computes.
        assert!(r[1..26].iter().all(|&x| x == r_of_angle(100.0)));
        assert!(r[26..51].iter().all(|&x| x == r_of_angle(200.0)));
        // Released at pulse 51: the law goes on from the held r (bumpless):
        // every change is one Eq. 189 increment K_r(ω_a − ω0), one per 0.1 s.
        let omega_a = f64::from(core::f32::consts::TAU) / (16.0 * f64::from(dt) * 1e-6);
        let inc = 1e-4 * (omega_a - 100.0 * core::f64::consts::PI / 30.0);
        let mut prev = f64::from(r_of_angle(200.0));
        let mut steps = 0;
        for &x in &r[51..77] {
            let d = f64::from(x) - prev;
            assert!(d == 0.0 || (d - inc).abs() < 1e-8, "{d} vs {inc}");
            steps += usize::from(d != 0.0);
            prev = f64::from(x);
        }
        // 26 pulses span 0.98–1.02 s of the 0.1 s sample grid.
        assert!((10..=11).contains(&steps), "{steps} samples");
    }
}
