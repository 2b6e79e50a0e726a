//! Every number a scene sets, described once: its key, unit, physical range
//! and whether the controller holds it as an `f32` ([`KEYS`]). Each section's
//! `validate` checks its numbers here, so a range and its message are never
//! written twice; errors name the key and show the value as typed ([`typed`]:
//! `1e300`, `3600.0000001`, never 300 digits or a converted unit).
//!
//! The ranges are physical bounds on the bench of the thesis (§4.4: a 12 V
//! motor, a brake of a few N·m, ω0 of 100 rpm) widened by orders of magnitude;
//! they refuse what no rig can mean (`t_u = 1e300`) and what the integrator
//! cannot honour (`rtol = 1e-300`: below ~1e-14 DP5's error estimate is
//! round-off, Hairer–Nørsett–Wanner §II.4), not unusual but valid studies.
//! How much work a valid scene asks for is [`Scene::estimated_events`](super::Scene::estimated_events)'s job.

use super::Invalid;

/// One bound of a [`Key`]'s range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    /// The value may equal the bound.
    Closed(f64),
    /// The value must differ from the bound.
    Open(f64),
}

impl Bound {
    fn value(self) -> f64 {
        match self {
            Self::Closed(v) | Self::Open(v) => v,
        }
    }
}

/// A scene number: where it lives, what it measures, what it may be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key {
    /// Dotted key path (`controller.k_mm_per_rad`; `inputs.v_m[]` for a
    /// profile's values).
    pub name: &'static str,
    /// Unit as printed in messages (empty for a pure number).
    pub unit: &'static str,
    /// Lower bound.
    pub min: Bound,
    /// Upper bound.
    pub max: Bound,
    /// The controller (ivt-ctrl, firmware) holds it as an `f32`: it must be
    /// finite there too, and not flush a non-zero value to 0.
    pub f32: bool,
}

const fn key(name: &'static str, unit: &'static str, min: Bound, max: Bound, f32: bool) -> Key {
    Key {
        name,
        unit,
        min,
        max,
        f32,
    }
}

use Bound::{Closed, Open};

/// Longest simulated time \[s\] ([`super::MAX_DURATION_S`]).
const T_MAX: f64 = super::MAX_DURATION_S;

/// Every number of a scene except the plant's parameters (those are
/// `ivt_kin::plant::PlantParams::validate`'s, the one description of the
/// plant) and the integers `encoder.ppr` (a list) and `outputs.channels[].every`.
#[rustfmt::skip]
pub const KEYS: &[Key] = &[
    key("duration_s", "s", Open(0.0), Closed(T_MAX), false),
    key("inputs.v_m[].t", "s", Closed(0.0), Closed(T_MAX), false),
    key("inputs.v_m[]", "V", Closed(-1e3), Closed(1e3), true),
    key("inputs.t_u[].t", "s", Closed(0.0), Closed(T_MAX), false),
    key("inputs.t_u[]", "N·m", Closed(0.0), Closed(1e3), true),
    key("initial.theta", "rad", Closed(-1e6), Closed(1e6), false),
    key("initial.omega", "rad/s", Closed(0.0), Closed(1e4), false),
    key("integrator.rtol", "", Closed(1e-14), Open(1.0), false),
    key("integrator.atol", "", Closed(1e-14), Open(1.0), false),
    key("integrator.dtheta", "rad", Closed(1e-9), Closed(1.0), false),
    key("integrator.omega_handover", "rad/s", Open(0.0), Closed(1e4), false),
    key("encoder.f_timer_hz", "Hz", Open(0.0), Closed(1e9), true),
    key("encoder.jitter_s", "s", Closed(0.0), Closed(1.0), false),
    key("sensors.period_s", "s", Closed(1e-7), Closed(T_MAX), false),
    key("sensors.v_m_noise", "V", Closed(0.0), Closed(1e3), false),
    key("sensors.v_m_quantum", "V", Closed(0.0), Closed(1e3), false),
    key("sensors.t_u_noise", "N·m", Closed(0.0), Closed(1e3), false),
    key("sensors.t_u_quantum", "N·m", Closed(0.0), Closed(1e3), false),
    key("stepper.steps_per_rev", "", Open(0.0), Closed(1e6), true),
    key("stepper.max_speed", "steps/s", Open(0.0), Closed(1e7), true),
    key("stepper.accel", "steps/s²", Open(0.0), Closed(1e9), true),
    key("stepper.miss_prob", "", Closed(0.0), Closed(1.0), false),
    key("controller.omega0_rpm", "rpm", Open(0.0), Open(1e4), true),
    key("controller.k_mm_per_rad", "mm/rad", Closed(-1e6), Closed(1e6), true),
    key("controller.k2_mm_per_rad", "mm/rad", Closed(-1e6), Closed(1e6), true),
    key("controller.k_prop_deg_per_rpm", "deg/rpm", Closed(-1e6), Closed(1e6), true),
    key("controller.prop_period_s", "s", Open(0.0), Closed(1e3), true),
    key("controller.r_schedule[].t", "s", Closed(0.0), Closed(T_MAX), false),
    key("metrics.from_s", "s", Closed(0.0), Closed(T_MAX), false),
    key("metrics.band", "", Open(0.0), Open(1.0), false),
    key("metrics.static_window_s", "s", Open(0.0), Closed(T_MAX), false),
    key("outputs.max_bytes", "bytes", Open(0.0), Closed(1e15), false),
];

/// The description of `name` (None for a key not in [`KEYS`]).
#[must_use]
pub fn find(name: &str) -> Option<&'static Key> {
    KEYS.iter().find(|k| k.name == name)
}

impl Key {
    /// `value` is finite, fits the controller's f32 where it must, and lies
    /// in the range; the error is reported at `at` (the key itself, or one
    /// knot of a profile: `inputs.v_m[2]`).
    ///
    /// # Errors
    /// [`Invalid`] naming `at`, the value as typed and the range.
    pub fn check_at(&self, at: &str, value: f64) -> Result<(), Invalid> {
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        let shown = typed(value);
        if self.f32 && !fits_f32(value) {
            return Err(Invalid::new(at, format!("= {shown}{unit} {NOT_F32}")));
        }
        let (lo, above) = match self.min {
            Closed(m) => ('[', value >= m),
            Open(m) => ('(', value > m),
        };
        let (hi, below) = match self.max {
            Closed(m) => (']', value <= m),
            Open(m) => (')', value < m),
        };
        if value.is_finite() && above && below {
            return Ok(());
        }
        let (min, max) = (typed(self.min.value()), typed(self.max.value()));
        let range = format!("{lo}{min}, {max}{hi}{unit}");
        Err(Invalid::new(
            at,
            format!("= {shown}{unit} is outside {range}"),
        ))
    }

    /// [`Self::check_at`] at the key itself.
    ///
    /// # Errors
    /// As [`Self::check_at`].
    pub fn check(&self, value: f64) -> Result<(), Invalid> {
        self.check_at(self.name, value)
    }
}

/// Check scene number `name` (one of [`KEYS`]).
///
/// # Errors
/// [`Invalid`] for a value out of range, or for a `name` that [`KEYS`] does
/// not describe (a bug the unit tests rule out).
pub fn check(name: &str, value: f64) -> Result<(), Invalid> {
    find(name)
        .ok_or_else(|| Invalid::new(name, "has no description in scene::keys::KEYS"))?
        .check(value)
}

/// `value` spelled as a person types it: the shorter of the plain and the
/// exponent form (both round-trip exactly), the plain one unless the
/// exponent saves more than two characters: `0.01`, `3600.0000001`, `1e300`,
/// `1e-300`, `1e6` — never 300 digits.
#[must_use]
pub fn typed(value: f64) -> String {
    let plain = format!("{value}");
    let exp = format!("{value:e}");
    if plain.len() <= exp.len() + 2 {
        plain
    } else {
        exp
    }
}

/// What is wrong with a value [`fits_f32`] refuses.
pub const NOT_F32: &str =
    "does not fit the controller's f32 (finite, |v| in [1.1754944e-38, 3.4028235e38] or 0)";

/// `value` as an `f32` is finite, and not flushed to 0 unless it is 0.
#[must_use]
pub fn fits_f32(value: f64) -> bool {
    let single = value as f32;
    single.is_finite() && (value == 0.0 || single != 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_once_with_an_ordered_range() {
        for (i, k) in KEYS.iter().enumerate() {
            assert!(
                KEYS.iter().skip(i + 1).all(|o| o.name != k.name),
                "{} twice",
                k.name
            );
            assert!(k.min.value() < k.max.value(), "{}", k.name);
        }
    }

    #[test]
    fn values_as_typed_and_f32_overflow() {
        let e = check("controller.k_mm_per_rad", 1e300)
            .unwrap_err()
            .to_string();
        assert!(e.contains("= 1e300 mm/rad") && e.contains("f32"), "{e}");
        let e = check("integrator.rtol", 1e-300).unwrap_err().to_string();
        assert!(e.contains("= 1e-300 is outside [1e-14, 1)"), "{e}");
        let e = check("duration_s", 1e7).unwrap_err().to_string();
        assert!(e.contains("= 1e7 s is outside (0, 1e6] s"), "{e}");
        assert_eq!(typed(3600.0000001), "3600.0000001");
        assert_eq!(typed(0.01), "0.01");
        assert_eq!(typed(-2.5), "-2.5");
        assert!(check("inputs.t_u[]", f64::NAN).is_err());
        assert!(check("controller.omega0_rpm", 100.0).is_ok());
        // 1e-50 is representable as f64 but flushes to 0 in f32
        assert!(!fits_f32(1e-50) && fits_f32(0.0) && fits_f32(-3.0e38));
        // the bounds NOT_F32 states are f32's own
        assert!(NOT_F32.contains(&format!("[{:e}, {:e}]", f32::MIN_POSITIVE, f32::MAX)));
        assert!(check("no.such.key", 1.0).is_err());
    }
}
