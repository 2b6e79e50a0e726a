//! Feedback laws behind one trait (§4.3 Eq. 180, 181; §4.4.3 Eq. 189).
//!
//! Each law returns the **increment** of the feedback part `r_d` for one
//! (decimated) encoder pulse; the controller adds it to a compensated sum,
//! forms `r = u_ol + r_d`, saturates to `[0, r_max]` and applies anti-windup
//! (see [`crate::controller`]). Laws are only called once the averager has a
//! full revolution of history. Gains are SI (`m·s/rad²`); the conversion from
//! the thesis's printed "mm·rad⁻¹" lives in [`crate::units`] only.
//!
//! Integration per pulse uses the exact angle step `Δθ = 2π/PPR` (the
//! independent variable of Eq. 171 is θ, not t), so no time measurement and
//! no trigonometry enter the pulse path.

use crate::averager::SpeedError;

/// What a law sees at one pulse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PulseSample {
    /// Timer timestamp of the pulse \[ticks\].
    pub ticks: u32,
    /// ω over the last pulse \[rad/s\].
    pub omega: f32,
    /// ω at the previous (decimated) pulse \[rad/s\].
    pub omega_prev: f32,
    /// ω_T, ω one revolution earlier \[rad/s\].
    pub omega_t: f32,
    /// ω_a − ω0 \[rad/s\], formed without the f32 bias of ω_a
    /// ([`crate::Targets::omega_a_error`]); `.get()` evaluates it.
    pub omega_a_err: SpeedError,
    /// ω − ω0 \[rad/s\], likewise ([`crate::Targets::omega_error`]).
    pub omega_err: SpeedError,
    /// Angle step of one (decimated) pulse, 2π/PPR \[rad\].
    pub dtheta: f32,
}

/// A feedback law: the increment of r_d at one pulse.
pub trait FeedbackLaw {
    /// Increment of r_d \[m\] for this pulse.
    fn increment(&mut self, s: &PulseSample) -> f32;
    /// Forget internal state (after a stall or restart); `ticks` is "now".
    fn reset(&mut self, ticks: u32);
}

/// Integral time-delay law Eq. 180: `dr_d/dθ = k(ω_a − ω0) + k2(ω − ω_T)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelayLaw {
    /// Integral gain k \[m·s/rad²\].
    pub k: f32,
    /// Damping gain k2 \[m·s/rad²\].
    pub k2: f32,
}

impl FeedbackLaw for DelayLaw {
    #[inline]
    fn increment(&mut self, s: &PulseSample) -> f32 {
        (self.k * s.omega_a_err.get() + self.k2 * (s.omega - s.omega_t)) * s.dtheta
    }
    fn reset(&mut self, _ticks: u32) {}
}

/// No-delay law Eq. 181: `dr_d/dθ = k(ω − ω0) + k2·dω/dθ`; the derivative is
/// the backward difference over one pulse, so `k2·(ω_k − ω_{k−1})` needs no
/// division by Δθ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoDelayLaw {
    /// Gain on the speed error k \[m·s/rad²\].
    pub k: f32,
    /// Gain on dω/dθ, k2 \[m·s/rad\].
    pub k2: f32,
}

impl FeedbackLaw for NoDelayLaw {
    #[inline]
    fn increment(&mut self, s: &PulseSample) -> f32 {
        self.k * s.omega_err.get() * s.dtheta + self.k2 * (s.omega - s.omega_prev)
    }
    fn reset(&mut self, _ticks: u32) {}
}

/// Proportional-increment law of the driving test, Eq. 189:
/// `θ_CT,k+1 = θ_CT,k + K(ω_m − ω_r)` at a fixed sample period. Here in
/// eccentricity: `r_d += K_r (ω_a − ω0)` once per period, with ω_a standing
/// for the thesis's revolution-averaged motor speed (simplification 3 of
/// §4.4.3). Sampling happens at the first pulse at or after each period
/// boundary (the law is pulse-driven like the others).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PropLaw {
    /// K_r \[m per rad/s\] (see [`crate::units::prop_gain_from_deg_per_rpm`]).
    pub k_r: f32,
    /// Sample period \[ticks\] (≥ 1).
    pub period_ticks: u32,
    next_sample: u32,
    primed: bool,
}

impl PropLaw {
    /// A law with gain `k_r` \[m per rad/s\] sampling every `period_ticks`.
    #[must_use]
    pub fn new(k_r: f32, period_ticks: u32) -> Self {
        Self {
            k_r,
            period_ticks: period_ticks.max(1),
            next_sample: 0,
            primed: false,
        }
    }
}

impl FeedbackLaw for PropLaw {
    #[inline]
    fn increment(&mut self, s: &PulseSample) -> f32 {
        if !self.primed {
            self.primed = true;
            self.next_sample = s.ticks.wrapping_add(self.period_ticks);
            return 0.0;
        }
        // Signed wrapping comparison: "ticks is at or after next_sample".
        let late = s.ticks.wrapping_sub(self.next_sample);
        if late >= 0x8000_0000 {
            return 0.0;
        }
        // Keep the fixed grid unless we fell a full period behind (then resync).
        self.next_sample = if late < self.period_ticks {
            self.next_sample.wrapping_add(self.period_ticks)
        } else {
            s.ticks.wrapping_add(self.period_ticks)
        };
        self.k_r * s.omega_a_err.get()
    }
    fn reset(&mut self, _ticks: u32) {
        self.primed = false;
    }
}

/// Open loop only: r_d stays 0.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct NoFeedback;

impl FeedbackLaw for NoFeedback {
    #[inline]
    fn increment(&mut self, _s: &PulseSample) -> f32 {
        0.0
    }
    fn reset(&mut self, _ticks: u32) {}
}

/// The law a controller runs (static dispatch over the four laws).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LawState {
    /// Eq. 180.
    Delay(DelayLaw),
    /// Eq. 181.
    NoDelay(NoDelayLaw),
    /// Eq. 189.
    Prop(PropLaw),
    /// Eq. 160 alone.
    Open(NoFeedback),
}

impl FeedbackLaw for LawState {
    #[inline]
    fn increment(&mut self, s: &PulseSample) -> f32 {
        match self {
            Self::Delay(l) => l.increment(s),
            Self::NoDelay(l) => l.increment(s),
            Self::Prop(l) => l.increment(s),
            Self::Open(l) => l.increment(s),
        }
    }
    fn reset(&mut self, ticks: u32) {
        match self {
            Self::Delay(l) => l.reset(ticks),
            Self::NoDelay(l) => l.reset(ticks),
            Self::Prop(l) => l.reset(ticks),
            Self::Open(l) => l.reset(ticks),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ω0 = 10 rad/s; ω_prev = ω_T = 10.
    fn sample(ticks: u32, omega: f32, omega_a: f32) -> PulseSample {
        PulseSample {
            ticks,
            omega,
            omega_prev: 10.0,
            omega_t: 10.0,
            omega_a_err: SpeedError::from_value(omega_a - 10.0),
            omega_err: SpeedError::from_value(omega - 10.0),
            dtheta: 0.5,
        }
    }

    #[test]
    fn delay_law_is_eq_180() {
        let mut l = DelayLaw { k: 2.0, k2: 3.0 };
        // (2·(12 − 10) + 3·(11 − 10))·0.5 = 3.5
        assert_eq!(l.increment(&sample(0, 11.0, 12.0)), 3.5);
    }

    #[test]
    fn no_delay_law_is_eq_181() {
        let mut l = NoDelayLaw { k: 2.0, k2: 3.0 };
        // 2·(11 − 10)·0.5 + 3·(11 − 10) = 4
        assert_eq!(l.increment(&sample(0, 11.0, 99.0)), 4.0);
    }

    #[test]
    fn prop_law_samples_on_a_fixed_grid() {
        let mut l = PropLaw::new(0.5, 100);
        assert_eq!(l.increment(&sample(u32::MAX - 10, 0.0, 12.0)), 0.0); // primes, next = 89
        assert_eq!(l.increment(&sample(50, 0.0, 12.0)), 0.0); // before the boundary
        assert_eq!(l.increment(&sample(95, 0.0, 12.0)), 1.0); // 0.5·(12 − 10), next = 189
        assert_eq!(l.increment(&sample(150, 0.0, 12.0)), 0.0);
        assert_eq!(l.increment(&sample(190, 0.0, 14.0)), 2.0);
    }
}
