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
//! `|ω_a − ω̄|/ω̄ ≤ 1/(N−1) + 3·2⁻²⁴` (the second term: u32→f32 rounding
//! of N, of the constant 2π·f_timer, and of the division).
//!
//! The laws do not use these f32 speeds for the error against ω0: see
//! [`SpeedError`] for why and how that error is formed without bias.

/// Speeds after one pulse. `None` until enough history has been seen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Speeds {
    /// ω over the last pulse interval \[rad/s\] (needs 2 pulses).
    pub omega: Option<f32>,
    /// ω_a, mean over the last revolution \[rad/s\] (needs PPR+1 pulses).
    pub omega_a: Option<f32>,
    /// ω_T, ω one revolution earlier \[rad/s\] (needs PPR+2 pulses).
    pub omega_t: Option<f32>,
    /// Ticks of the last pulse interval (0 if unknown).
    pub interval_ticks: u32,
    /// Ticks of the last revolution, t_k − t_{k−PPR} (0 if unknown).
    pub revolution_ticks: u32,
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

/// A tick count held as an integer part and an f32 fraction (≈ 2⁻²⁴ tick
/// resolution at any size): the number of ticks one pulse or one revolution
/// takes at exactly ω0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TargetTicks {
    int: u32,
    frac: f32,
    omega0: f32,
}

/// 2π − TAU_f32 (TAU_f32 = 6.2831854820251465).
const TAU_LO: f32 = -1.748_455_6e-7;

/// Veltkamp split of an f32 into two halves of ≤ 12 significant bits.
fn split(a: f32) -> (f32, f32) {
    let c = 4097.0 * a; // 2¹² + 1
    let hi = c - (c - a);
    (hi, a - hi)
}

/// Dekker's exact product: `a·b = p + e` with `p = fl(a·b)` (no FMA, f32 only).
fn two_prod(a: f32, b: f32) -> (f32, f32) {
    let p = a * b;
    let (a_hi, a_lo) = split(a);
    let (b_hi, b_lo) = split(b);
    let e = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo;
    (p, e)
}

impl TargetTicks {
    /// Ticks of angle `(angle_hi + angle_lo)` at speed ω0 on a timer of f:
    /// `D0 = angle·f/ω0`, formed with exact products (Dekker) so that D0 is good
    /// to ~1e-6 tick (an f32 quotient would be off by up to 2⁻²⁴·D0, i.e.
    /// 0.04 tick at 6e5 ticks, and that offset would be a permanent bias).
    /// Runs once, at construction.
    fn new(angle_hi: f32, angle_lo: f32, f_timer_hz: f32, omega0: f32) -> Self {
        // (angle_hi + angle_lo)·f as hi + lo.
        let (p_hi, p_err) = two_prod(angle_hi, f_timer_hz);
        let p_lo = p_err + angle_lo * f_timer_hz;
        // Divide by ω0; the remainder p_hi − q·ω0 is exact (q·ω0 = m + e
        // exactly, and p_hi − m is exact by Sterbenz since m ≈ p_hi).
        let q = p_hi / omega0;
        let (m, e) = two_prod(q, omega0);
        let rem = ((p_hi - m) - e) + p_lo;
        let q_lo = rem / omega0;
        let int = q as u32; // truncation; saturates, NaN → 0 (invalid configs)
                            // q − trunc(q) is exact (Sterbenz) for q ≥ 1 and trivially for q < 1.
        let frac = (q - int as f32) + q_lo;
        Self { int, frac, omega0 }
    }

    /// The speed error for a measured count of `ticks`, see [`SpeedError`].
    #[inline]
    fn error(self, ticks: u32) -> SpeedError {
        SpeedError {
            target: self,
            ticks,
        }
    }
}

/// A speed error `ω_meas − ω0` for a measured tick count D over an angle
/// whose count at ω0 is D0, evaluated on demand by [`SpeedError::get`] (a
/// law pays only for the error it uses).
///
/// Why not `ω_meas − ω0` in f32: in steady state D takes the same few values
/// again and again, so the f32 rounding of `ω_meas = angle·f/D` (up to half
/// an ulp, 4.8e-7 rad/s at 100 rpm) and of the constant `2π·f` are *fixed*
/// biases, and the integral law integrates them forever (measured: 1e-7 m of
/// r per 10⁶ pulses against the f64 reference). Instead
/// `ω_meas − ω0 = ω0·(D0 − D)/D`, where `D0 − D` is an exact integer
/// difference plus the fraction of D0: the result is good to a few 2⁻²⁴ of
/// *itself*, so there is no bias when the error is near zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedError {
    target: TargetTicks,
    ticks: u32,
}

impl SpeedError {
    /// A known error value (for tests and host tools).
    #[must_use]
    pub fn from_value(err: f32) -> Self {
        // ω0·(D0 − D)/D with ω0 = err, D = 1, D0 = 2 gives err.
        Self {
            target: TargetTicks {
                int: 2,
                frac: 0.0,
                omega0: err,
            },
            ticks: 1,
        }
    }

    /// The error \[rad/s\]; 0 for a zero tick count.
    #[inline]
    #[must_use]
    pub fn get(&self) -> f32 {
        let d = self.ticks;
        if d == 0 {
            return 0.0;
        }
        let d0 = self.target.int;
        // Exact in i32 when both fit (always, for the controller's limits).
        let diff = if d <= 0x7FFF_FFFF && d0 <= 0x7FFF_FFFF {
            (d0 as i32 - d as i32) as f32
        } else {
            d0 as f32 - d as f32
        };
        self.target.omega0 * (diff + self.target.frac) / d as f32
    }
}

/// Tick counts at ω0 for one pulse and one revolution; computed once by
/// [`AngleAverager::targets`] and kept by the controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Targets {
    /// Ticks of one pulse (Δθ = 2π/PPR) at ω0.
    pub pulse: TargetTicks,
    /// Ticks of one revolution at ω0.
    pub revolution: TargetTicks,
}

impl Targets {
    /// Placeholder of an unconfigured controller (errors read 0 for any count).
    pub const NONE: Self = Self {
        pulse: TargetTicks {
            int: 0,
            frac: 0.0,
            omega0: 0.0,
        },
        revolution: TargetTicks {
            int: 0,
            frac: 0.0,
            omega0: 0.0,
        },
    };

    /// `ω_a − ω0` for a revolution of `revolution_ticks`.
    #[inline]
    #[must_use]
    pub fn omega_a_error(&self, revolution_ticks: u32) -> SpeedError {
        self.revolution.error(revolution_ticks)
    }

    /// `ω − ω0` for a pulse interval of `interval_ticks`.
    #[inline]
    #[must_use]
    pub fn omega_error(&self, interval_ticks: u32) -> SpeedError {
        self.pulse.error(interval_ticks)
    }
}

impl<const PPR: usize> AngleAverager<PPR> {
    /// An empty averager for a timer of `f_timer_hz`.
    #[must_use]
    pub fn new(f_timer_hz: f32) -> Self {
        let mut a = Self::unconfigured();
        a.configure(f_timer_hz);
        a
    }

    /// An empty averager with no timer yet (speeds read 0 until
    /// [`Self::configure`]); `const` so that it can initialize a `static`.
    #[must_use]
    pub const fn unconfigured() -> Self {
        Self {
            ring: [0; PPR],
            head: 0,
            last: 0,
            older: 0,
            seen: 0,
            two_pi_f: 0.0,
            dtheta_f: 0.0,
        }
    }

    /// Set the timer frequency and forget all history, in place.
    pub fn configure(&mut self, f_timer_hz: f32) {
        self.two_pi_f = core::f32::consts::TAU * f_timer_hz;
        self.dtheta_f = self.two_pi_f / Self::ppr_f32();
        self.reset();
    }

    fn ppr_f32() -> f32 {
        if PPR == 0 {
            1.0
        } else {
            PPR as f32
        }
    }

    /// Tick counts of a pulse and of a revolution at the target speed ω0,
    /// for [`Targets::omega_a_error`] and [`Targets::omega_error`].
    #[must_use]
    pub fn targets(f_timer_hz: f32, omega0: f32) -> Targets {
        let n = Self::ppr_f32();
        let revolution = TargetTicks::new(core::f32::consts::TAU, TAU_LO, f_timer_hz, omega0);
        // 2π/PPR as hi + lo.
        let a_hi = core::f32::consts::TAU / n;
        let (m, e) = two_prod(a_hi, n);
        let a_lo = (((core::f32::consts::TAU - m) - e) + TAU_LO) / n;
        Targets {
            pulse: TargetTicks::new(a_hi, a_lo, f_timer_hz, omega0),
            revolution,
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
        let interval_ticks = if seen >= 1 {
            ticks.wrapping_sub(self.last)
        } else {
            0
        };
        let omega = if seen >= 1 {
            Self::rate(self.dtheta_f, interval_ticks)
        } else {
            None
        };
        // The slot under `head` holds t_{k−PPR} once the ring is full.
        let mut omega_a = None;
        let mut omega_t = None;
        let mut revolution_ticks = 0;
        if let Some(slot) = self.ring.get_mut(self.head as usize) {
            let oldest = *slot;
            if seen >= PPR {
                revolution_ticks = ticks.wrapping_sub(oldest);
                omega_a = Self::rate(self.two_pi_f, revolution_ticks);
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
            interval_ticks,
            revolution_ticks,
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

    #[test]
    fn speed_error_is_unbiased_near_the_target() {
        // f64 truth 2πf/D − ω0 (ω0 taken as its f32 value) vs SpeedError for
        // D around D0 at 1 MHz and 84 MHz: |error| ≤ 4·2⁻²⁴·|truth| + 1e-9 rad/s.
        // The plain f32 difference ω_a − ω0 misses this by up to ~5e-7 rad/s.
        for f in [1.0e6f32, 84.0e6] {
            let omega0 = 100.0 * core::f32::consts::TAU / 60.0;
            let t = AngleAverager::<1200>::targets(f, omega0);
            let d0 = core::f64::consts::TAU * f64::from(f) / f64::from(omega0);
            for off in -300i64..=300 {
                let d = (d0.round() as i64 + off * (1 + d0 as i64 / 100_000)) as u32;
                let truth =
                    core::f64::consts::TAU * f64::from(f) / f64::from(d) - f64::from(omega0);
                let got = f64::from(t.omega_a_error(d).get());
                let tol = 4.0 * f64::from(f32::EPSILON) / 2.0 * truth.abs() + 1e-9;
                assert!(
                    (got - truth).abs() <= tol,
                    "f={f} D={d}: {got:e} vs {truth:e}"
                );
                let dp = d / 1200;
                let truth_p = core::f64::consts::TAU / 1200.0 * f64::from(f) / f64::from(dp)
                    - f64::from(omega0);
                let got_p = f64::from(t.omega_error(dp).get());
                let tol_p = 4.0 * f64::from(f32::EPSILON) / 2.0 * truth_p.abs() + 1e-9;
                assert!(
                    (got_p - truth_p).abs() <= tol_p,
                    "f={f} d={dp}: {got_p:e} vs {truth_p:e}"
                );
            }
        }
        assert_eq!(SpeedError::from_value(-0.25).get(), -0.25);
    }
}
