//! Angle-sampled speed averaging (§4.3, SPEC §3).
//!
//! The encoder on the driven noncircular gear gives one pulse every
//! `Δθ = 2π/PPR` with a free-running timer timestamp (u32 ticks at
//! `f_timer`). From the last PPR+1 timestamps:
//!
//! ```text
//! ω   = Δθ·f_timer / (t_k − t_{k−1})              speed over the last pulse
//! ω_a = 2π·f_timer / (t_k − t_{k−PPR})            = 2π / ∫_{θ−2π}^{θ} dσ/ω  (§4.3)
//! ω_T = Δθ·f_timer / (t_{k−PPR} − t_{k−PPR−1})    ω one revolution earlier (Eq. 172)
//! ```
//!
//! Storage: PPR timestamps in a ring plus the one that was last overwritten
//! (`older`) and the latest (`last`) — PPR+1 slots of history in all
//! (const generics cannot size an array `PPR+1` on stable Rust). O(1) per
//! pulse: no sums are kept, so nothing accumulates or drifts; differences
//! of u32 timestamps use wrapping arithmetic, exact across a timer overflow
//! as long as one revolution lasts fewer than 2³² ticks (the controller
//! guarantees that by its interval limits).
//!
//! Quantization: a timestamp is the timer count at the edge, so a tick
//! difference is within ±1 tick of `f_timer·Δt` (both ends truncate
//! the same way). With N = f_timer·T_rev ticks per revolution,
//! `|ω_a − ω̄|/ω̄ ≤ 1/(N−1) + 3·2⁻²⁴` (the second term: u32→f32 rounding,
//! the rounded constant 2π·f_timer, and the division).

/// Speeds after one pulse. `None` until enough history has been seen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Speeds {
    /// ω over the last pulse interval \[rad/s\] (needs 2 pulses).
    pub omega: Option<f32>,
    /// ω_a, mean over the last revolution \[rad/s\] (needs PPR+1 pulses).
    pub omega_a: Option<f32>,
    /// ω_T, ω one revolution earlier \[rad/s\] (needs PPR+2 pulses).
    pub omega_t: Option<f32>,
}

/// Ring buffer of encoder timestamps giving ω, ω_a and ω_T per pulse.
#[derive(Clone, Debug)]
pub struct AngleAverager<const PPR: usize> {
    ring: [u32; PPR],
    head: u32,
    last: u32,
    older: u32,
    seen: u32,
    two_pi_f: f32,
    dtheta_f: f32,
}

impl<const PPR: usize> AngleAverager<PPR> {
    /// An empty averager for a timer of `f_timer_hz`.
    #[must_use]
    pub fn new(f_timer_hz: f32) -> Self {
        let two_pi_f = core::f32::consts::TAU * f_timer_hz;
        let ppr = if PPR == 0 { 1.0 } else { PPR as f32 };
        Self {
            ring: [0; PPR],
            head: 0,
            last: 0,
            older: 0,
            seen: 0,
            two_pi_f,
            dtheta_f: two_pi_f / ppr,
        }
    }

    /// Forget all history (after a stall or a restart).
    pub fn reset(&mut self) {
        self.head = 0;
        self.seen = 0;
    }

    /// Number of timestamps seen since the last reset (saturates at PPR+2).
    #[must_use]
    pub fn seen(&self) -> u32 {
        self.seen
    }

    /// True once ω_a and ω_T are both available (PPR+2 pulses seen).
    #[must_use]
    pub fn is_ready(&self) -> bool {
        (self.seen as usize) >= PPR.saturating_add(2)
    }

    /// `f(ticks)` = `scale/ticks`, with a zero difference mapped to `None`.
    #[inline]
    fn rate(scale: f32, dt: u32) -> Option<f32> {
        if dt == 0 {
            None
        } else {
            Some(scale / dt as f32)
        }
    }

    /// Record the timestamp of a pulse and return the speeds at it.
    /// A zero tick difference yields `None` for that speed (the controller
    /// rejects such pulses before they get here).
    pub fn push(&mut self, ticks: u32) -> Speeds {
        let seen = self.seen as usize;
        let omega = if seen >= 1 {
            Self::rate(self.dtheta_f, ticks.wrapping_sub(self.last))
        } else {
            None
        };
        // The slot under `head` holds t_{k−PPR} once the ring is full.
        let mut omega_a = None;
        let mut omega_t = None;
        if let Some(slot) = self.ring.get_mut(self.head as usize) {
            let oldest = *slot;
            if seen >= PPR {
                omega_a = Self::rate(self.two_pi_f, ticks.wrapping_sub(oldest));
            }
            if seen > PPR {
                omega_t = Self::rate(self.dtheta_f, oldest.wrapping_sub(self.older));
            }
            self.older = oldest;
            *slot = ticks;
            let next = self.head.wrapping_add(1);
            self.head = if next as usize >= PPR { 0 } else { next };
        }
        self.last = ticks;
        if seen < PPR.saturating_add(2) {
            self.seen = self.seen.saturating_add(1);
        }
        Speeds {
            omega,
            omega_a,
            omega_t,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_speed_exact() {
        // 1000 ticks per pulse, PPR 4, f = 1 MHz: ω = (2π/4)·1e6/1000.
        let mut a = AngleAverager::<4>::new(1.0e6);
        let mut s = a.push(0);
        for k in 1..=6u32 {
            s = a.push(k * 1000);
            if k < 4 {
                assert!(s.omega_a.is_none());
            }
        }
        let w = core::f32::consts::TAU / 4.0 * 1e3;
        assert!((s.omega.unwrap_or(0.0) - w).abs() < 1e-3);
        assert!((s.omega_a.unwrap_or(0.0) - w).abs() < 1e-3);
        assert!((s.omega_t.unwrap_or(0.0) - w).abs() < 1e-3);
        assert!(a.is_ready());
    }

    #[test]
    fn omega_t_is_omega_one_revolution_earlier() {
        // Intervals 1,2,3,...: ω_T at pulse k must equal ω at pulse k − PPR.
        let mut a = AngleAverager::<3>::new(1.0);
        let mut t = 0u32;
        let mut omegas = [0.0f32; 20];
        for k in 0..omegas.len() {
            t = t.wrapping_add(k as u32 + 1);
            let s = a.push(t);
            omegas[k] = s.omega.unwrap_or(f32::NAN);
            if k >= 5 {
                assert_eq!(s.omega_t, Some(omegas[k - 3]), "k={k}");
            }
        }
    }
}
