//! Actuator output (§4.4.2, SPEC §3): eccentricity → stepper position
//! ([`ActuatorMap`], Eq. 185 for the SGIVT prototype), and a step/dir
//! generator with speed and acceleration limits ([`StepGenerator`]).

use crate::units::SGIVT_M_PER_DEG;

/// Linear map from eccentricity r \[m\] to a stepper position \[steps\]:
/// `steps = offset_steps + round(r · steps_per_metre)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActuatorMap {
    /// Stepper steps per metre of eccentricity.
    pub steps_per_metre: f32,
    /// Position \[steps\] at r = 0.
    pub offset_steps: i32,
}

impl ActuatorMap {
    /// The SGIVT prototype, Eq. 185: `e = 7π/51840·θ_CT` (inch, degree), for a
    /// stepper with `steps_per_rev` (micro)steps per revolution of θ_CT.
    /// Example: 200 full steps × 16 microsteps = 3200.
    #[must_use]
    pub fn sgivt(steps_per_rev: f32) -> Self {
        Self {
            steps_per_metre: steps_per_rev / 360.0 / SGIVT_M_PER_DEG,
            offset_steps: 0,
        }
    }

    /// Stepper position for eccentricity `r`. Saturates at the i32 range;
    /// NaN maps to `offset_steps`.
    #[must_use]
    pub fn steps(&self, r: f32) -> i32 {
        let x = r * self.steps_per_metre;
        let rounded = if x >= 0.0 { x + 0.5 } else { x - 0.5 };
        // `as` saturates and maps NaN to 0: no panic path.
        self.offset_steps.saturating_add(rounded as i32)
    }

    /// True if the map is usable (finite, non-zero gain).
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.steps_per_metre.is_finite() && self.steps_per_metre != 0.0
    }
}

/// Speed and acceleration limits of the stepper.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepperLimits {
    /// Largest step rate \[steps/s\].
    pub max_speed: f32,
    /// Acceleration \[steps/s²\].
    pub accel: f32,
}

impl StepperLimits {
    /// True if both limits are finite and positive.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.max_speed.is_finite()
            && self.max_speed > 0.0
            && self.accel.is_finite()
            && self.accel > 0.0
    }
}

/// One decision of the step generator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepDecision {
    /// Emit a step pulse now.
    pub step: bool,
    /// Direction line: true = towards larger positions.
    pub forward: bool,
    /// Position after this decision \[steps\].
    pub position: i32,
    /// Timer tick at which the next step is due (meaningful while moving).
    pub next_step_at: u32,
    /// True while a move is in progress.
    pub moving: bool,
}

/// Trapezoidal step/dir generator in timer ticks (D. Austin, "Generate
/// stepper-motor speed profiles in real time", 2005): the delay between
/// steps follows `c_n = c_{n−1}(4n−1)/(4n+1)` while accelerating (exact
/// constant-acceleration profile up to O(1/n²), no square root per step),
/// the inverse while decelerating, and `c_min = f_timer/max_speed` when
/// cruising. `n` is the ramp index, equal to the number of steps needed to
/// stop, so deceleration starts when the remaining distance is ≤ n. A target
/// behind the direction of motion makes it decelerate to rest, then reverse.
#[derive(Clone, Debug)]
pub struct StepGenerator {
    position: i32,
    target: i32,
    n: u32,
    delay: f32,
    last_step: u32,
    dir: i8,
    stepped: bool,
    c0: f32,
    c_min: f32,
}

impl StepGenerator {
    /// A generator at position 0 for a timer at `f_timer_hz`. Invalid limits
    /// give a generator that never steps (the controller reports the config fault).
    #[must_use]
    pub fn new(limits: StepperLimits, f_timer_hz: f32) -> Self {
        let mut g = Self::unconfigured();
        g.configure(limits, f_timer_hz);
        g
    }

    /// A generator at position 0 that never steps until [`Self::configure`].
    #[must_use]
    pub const fn unconfigured() -> Self {
        Self {
            position: 0,
            target: 0,
            n: 0,
            delay: f32::INFINITY,
            last_step: 0,
            dir: 0,
            stepped: false,
            c0: f32::INFINITY,
            c_min: f32::INFINITY,
        }
    }

    /// Set limits and timer in place; keeps the position and target, drops
    /// any ramp in progress (the next step starts from rest).
    pub fn configure(&mut self, limits: StepperLimits, f_timer_hz: f32) {
        let (c0, c_min) = if limits.is_valid() && f_timer_hz.is_finite() && f_timer_hz > 0.0 {
            let c_min = f_timer_hz / limits.max_speed;
            // First delay from rest: 0.676·f·sqrt(2/a) (Austin's correction).
            let c0 = 0.676 * f_timer_hz * libm::sqrtf(2.0 / limits.accel);
            (c0.max(c_min), c_min)
        } else {
            (f32::INFINITY, f32::INFINITY)
        };
        self.c0 = c0;
        self.c_min = c_min;
        self.delay = c0;
        self.n = 0;
        self.dir = 0;
        self.stepped = false;
    }

    /// Current position \[steps\].
    #[must_use]
    pub fn position(&self) -> i32 {
        self.position
    }

    /// Current target \[steps\].
    #[must_use]
    pub fn target(&self) -> i32 {
        self.target
    }

    /// Set a new target position \[steps\].
    pub fn set_target(&mut self, target: i32) {
        self.target = target;
    }

    /// Delay until the next step as whole ticks (saturating; ∞ → u32::MAX).
    fn delay_ticks(&self) -> u32 {
        self.delay as u32
    }

    fn decision(&self, step: bool) -> StepDecision {
        StepDecision {
            step,
            forward: self.dir >= 0,
            position: self.position,
            next_step_at: self.last_step.wrapping_add(self.delay_ticks()),
            moving: self.dir != 0,
        }
    }

    /// Advance to `now` \[ticks\]: emit at most one step. Call at least once per
    /// `c_min` ticks; calls more than 2³¹ ticks apart are misread as "early".
    pub fn tick(&mut self, now: u32) -> StepDecision {
        if !self.c0.is_finite() {
            return self.decision(false);
        }
        if self.dir == 0 {
            if self.position == self.target {
                return self.decision(false);
            }
            // From rest the last step must be at least c0 ago (the start-stop
            // rate), so a reversal never steps back at speed.
            if self.stepped && now.wrapping_sub(self.last_step) < self.delay_ticks() {
                return self.decision(false);
            }
            // Start from rest: first step now, then wait c0.
            self.stepped = true;
            self.dir = if self.target > self.position { 1 } else { -1 };
            self.n = 0;
            self.delay = self.c0;
            self.last_step = now;
            self.position = self.position.saturating_add(i32::from(self.dir));
            self.plan_next();
            return self.decision(true);
        }
        let elapsed = now.wrapping_sub(self.last_step);
        if elapsed >= 0x8000_0000 || elapsed < self.delay_ticks() {
            return self.decision(false);
        }
        self.last_step = now;
        self.position = self.position.saturating_add(i32::from(self.dir));
        self.plan_next();
        self.decision(true)
    }

    /// After a step: choose the delay to the next one (accelerate, cruise,
    /// decelerate or stop).
    fn plan_next(&mut self) {
        let ahead = (i64::from(self.target) - i64::from(self.position)) * i64::from(self.dir);
        let remaining = if ahead > 0 { ahead as u64 } else { 0 };
        if remaining == 0 && self.n == 0 {
            // At the target (or it is behind us) at the lowest speed: stop.
            self.dir = 0;
            self.delay = self.c0;
        } else if remaining <= u64::from(self.n) {
            // c_{n−1} = c_n (4n+1)/(4n−1)
            let n4 = 4.0 * self.n as f32;
            self.delay *= (n4 + 1.0) / (n4 - 1.0);
            self.n = self.n.saturating_sub(1);
        } else if self.delay > self.c_min {
            self.n = self.n.saturating_add(1);
            let n4 = 4.0 * self.n as f32;
            self.delay *= (n4 - 1.0) / (n4 + 1.0);
            if self.delay < self.c_min {
                self.delay = self.c_min;
            }
        } else {
            self.delay = self.c_min;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sgivt_map_full_stroke() {
        // Eq. 185: θ_CT = 3600° gives the maximum crank length 7π/51840·3600 inch.
        let m = ActuatorMap::sgivt(360.0); // one step per degree
        let e_max = 7.0 * core::f32::consts::PI / 51840.0 * 3600.0 * 0.0254;
        assert_eq!(m.steps(e_max), 3600);
        assert_eq!(m.steps(f32::NAN), 0);
        assert_eq!(m.steps(f32::INFINITY), i32::MAX);
    }

    /// Run to a target, recording step times; check limits and arrival.
    fn run(limits: StepperLimits, f: f32, target: i32) -> (i32, u32, f32) {
        let mut g = StepGenerator::new(limits, f);
        g.set_target(target);
        let mut steps = 0u32;
        let mut last: Option<u32> = None;
        let mut min_dt = u32::MAX;
        for now in 0..2_000_000u32 {
            let d = g.tick(now);
            if d.step {
                steps += 1;
                if let Some(l) = last {
                    min_dt = min_dt.min(now - l);
                }
                last = Some(now);
            }
            if !d.moving && d.position == target {
                break;
            }
        }
        (g.position(), steps, f / min_dt as f32)
    }

    #[test]
    fn trapezoid_reaches_target_within_speed_limit() {
        // 1 MHz timer, 2000 steps/s, 20000 steps/s²: the ramp takes
        // v²/(2a) = 100 steps, so a 1000-step move cruises.
        let lim = StepperLimits {
            max_speed: 2000.0,
            accel: 20_000.0,
        };
        let (pos, steps, vmax) = run(lim, 1.0e6, 1000);
        assert_eq!((pos, steps), (1000, 1000));
        // Integer-tick delays round down: allow one tick on a 500-tick period.
        assert!(vmax <= 2000.0 * 500.0 / 499.0, "{vmax}");
        let (pos, _, _) = run(lim, 1.0e6, -7);
        assert_eq!(pos, -7);
    }
}
