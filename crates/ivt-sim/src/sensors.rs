//! Sensors and actuators between the plant and the controller: the encoder
//! (PPR, timer frequency, timestamp jitter), the V_m and T_U readings (noise,
//! quantization) and the stepper (rate/acceleration limits, missed steps).
//! All randomness comes from one seeded generator, so runs are reproducible.

/// SplitMix64: small, fast, seeded, good enough for sensor noise.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// Generator with `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform(); // (0, 1]
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// Encoder timestamping: a free-running timer of `f_timer_hz` captured at
/// each pulse, with optional Gaussian jitter of the edge time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Encoder {
    /// Pulses per revolution of θ.
    pub ppr: usize,
    /// Timer frequency \[Hz\].
    pub f_timer_hz: f64,
    /// Standard deviation of the edge-time jitter \[s\].
    pub jitter_s: f64,
}

impl Encoder {
    /// Angle between pulses \[rad\].
    pub fn dtheta(&self) -> f64 {
        std::f64::consts::TAU / self.ppr as f64
    }

    /// The 32-bit timer value captured for an edge at time `t` (wraps like
    /// the hardware counter).
    pub fn capture(&self, t: f64, rng: &mut Rng) -> u32 {
        let t = if self.jitter_s > 0.0 {
            t + self.jitter_s * rng.normal()
        } else {
            t
        };
        let ticks = (t.max(0.0) * self.f_timer_hz).floor();
        (ticks.rem_euclid(4_294_967_296.0)) as u32
    }
}

/// A slow analogue reading: value + Gaussian noise, then rounded to the ADC
/// quantum (0 = no quantization).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Reading {
    /// Noise standard deviation (same unit as the value).
    pub noise: f64,
    /// Quantization step (same unit as the value).
    pub quantum: f64,
}

impl Reading {
    /// What the controller reads for a true `value`.
    pub fn read(&self, value: f64, rng: &mut Rng) -> f64 {
        let v = if self.noise > 0.0 {
            value + self.noise * rng.normal()
        } else {
            value
        };
        if self.quantum > 0.0 {
            (v / self.quantum).round() * self.quantum
        } else {
            v
        }
    }
}

/// The stepper motor that sets the eccentricity: follows the controller's
/// target position with a speed limit and a constant acceleration
/// (trapezoidal profile), and loses each step with probability `miss_prob`
/// (a lost step moves the commanded but not the real position).
///
/// The model is advanced at pulse instants: between two pulses r is held,
/// i.e. r changes at most one encoder pulse late (≤ 0.5 ms at PPR 1200 and
/// 100 rpm).
#[derive(Clone, Debug, PartialEq)]
pub struct Stepper {
    /// Largest step rate \[steps/s\].
    pub max_speed: f64,
    /// Acceleration \[steps/s²\].
    pub accel: f64,
    /// Probability that a step is lost.
    pub miss_prob: f64,
    /// Eccentricity per step \[m/step\] (the actuator map, Eq. 185).
    pub r_per_step: f64,
    /// Steps counted by the driver (what the controller believes).
    pub commanded: i64,
    /// Real position of the mechanism \[steps\].
    pub position: i64,
    /// Signed speed \[steps/s\].
    pub speed: f64,
    frac: f64,
    /// Steps lost so far.
    pub missed: u64,
}

impl Stepper {
    /// A stepper at rest at `position`.
    pub fn new(max_speed: f64, accel: f64, miss_prob: f64, r_per_step: f64, position: i64) -> Self {
        Self {
            max_speed,
            accel,
            miss_prob,
            r_per_step,
            commanded: position,
            position,
            speed: 0.0,
            frac: 0.0,
            missed: 0,
        }
    }

    /// Eccentricity of the real position \[m\].
    pub fn r(&self) -> f64 {
        self.position as f64 * self.r_per_step
    }

    /// Move towards `target` for `dt` seconds.
    pub fn advance(&mut self, target: i64, dt: f64, rng: &mut Rng) {
        if dt.is_nan() || dt <= 0.0 {
            return;
        }
        // sub-steps so that the acceleration profile is resolved
        let n = ((dt * self.max_speed / 4.0).ceil() as usize).clamp(1, 64);
        let h = dt / n as f64;
        for _ in 0..n {
            let dist = (target - self.commanded) as f64 - self.frac;
            // fastest speed from which we can still stop at the target
            let v_stop = (2.0 * self.accel * dist.abs()).sqrt().min(self.max_speed);
            let v_want = dist.signum() * v_stop;
            let dv = (v_want - self.speed).clamp(-self.accel * h, self.accel * h);
            self.speed += dv;
            self.frac += self.speed * h;
            while self.frac >= 1.0 {
                self.frac -= 1.0;
                self.step(1, rng);
            }
            while self.frac <= -1.0 {
                self.frac += 1.0;
                self.step(-1, rng);
            }
            if self.commanded == target && self.speed.abs() < self.accel * h {
                self.speed = 0.0;
                self.frac = 0.0;
            }
        }
    }

    fn step(&mut self, dir: i64, rng: &mut Rng) {
        self.commanded += dir;
        if self.miss_prob > 0.0 && rng.uniform() < self.miss_prob {
            self.missed += 1;
        } else {
            self.position += dir;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stepper_respects_limits_and_reaches_target() {
        let mut rng = Rng::new(1);
        let mut s = Stepper::new(1000.0, 10_000.0, 0.0, 1e-6, 0);
        let mut last = 0;
        for _ in 0..2000 {
            s.advance(500, 1e-3, &mut rng);
            assert!(
                (s.position - last).abs() <= 2,
                "rate limit: {} per ms",
                s.position - last
            );
            assert!(s.speed.abs() <= 1000.0 + 1e-9);
            last = s.position;
        }
        assert_eq!(s.position, 500);
        // trapezoid: 500 steps at 1000/s with 10^4/s² takes ≥ 0.55 s
        let mut s = Stepper::new(1000.0, 10_000.0, 0.0, 1e-6, 0);
        for _ in 0..540 {
            s.advance(500, 1e-3, &mut rng);
        }
        assert!(s.position < 500);
    }

    #[test]
    fn missed_steps_are_lost_at_the_given_rate() {
        let mut rng = Rng::new(7);
        let mut s = Stepper::new(1e5, 1e7, 0.1, 1e-6, 0);
        for _ in 0..1000 {
            s.advance(10_000, 1e-2, &mut rng);
        }
        assert_eq!(s.commanded, 10_000);
        let rate = s.missed as f64 / 10_000.0;
        assert!((rate - 0.1).abs() < 0.015, "{rate}"); // 5σ of a binomial(10⁴, 0.1)
        assert_eq!(s.position + s.missed as i64, 10_000);
    }

    #[test]
    fn readings_and_encoder() {
        let mut rng = Rng::new(3);
        let q = Reading {
            noise: 0.0,
            quantum: 0.01,
        };
        assert!((q.read(1.234, &mut rng) - 1.23).abs() < 1e-12);
        let n = Reading {
            noise: 0.1,
            quantum: 0.0,
        };
        let xs: Vec<f64> = (0..20_000).map(|_| n.read(5.0, &mut rng)).collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let sd = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / xs.len() as f64).sqrt();
        assert!(
            (mean - 5.0).abs() < 0.005 && (sd - 0.1).abs() < 0.005,
            "{mean} {sd}"
        );
        let e = Encoder {
            ppr: 1200,
            f_timer_hz: 1e6,
            jitter_s: 0.0,
        };
        assert_eq!(e.capture(1.5e-3, &mut rng), 1500);
        assert_eq!(e.capture(4294.967296 + 1e-3, &mut rng), 1000); // wraps
    }
}
