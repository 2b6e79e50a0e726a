//! `[inputs]` (piecewise-linear V_m(t), T_U(t)) and `[initial]`.

use super::keys;
use super::Invalid;
use serde::{Deserialize, Deserializer};

/// `[inputs]`: piecewise-linear profiles as `[[t, value], ...]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct InputsSection {
    /// Motor voltage V_m(t) \[V\].
    #[serde(deserialize_with = "knots")]
    pub v_m: Vec<[f64; 2]>,
    /// Brake torque T_U(t) \[N·m\].
    #[serde(deserialize_with = "knots")]
    pub t_u: Vec<[f64; 2]>,
}

impl InputsSection {
    pub(super) fn validate(&self) -> Result<(), Invalid> {
        for (p, key) in [(&self.v_m, "inputs.v_m"), (&self.t_u, "inputs.t_u")] {
            let values = keys::described(&format!("{key}[]"))?;
            profile_ok(p, key, |v| values.check(v).map_err(|e| e.to_string()))?;
        }
        Ok(())
    }
}

/// `[initial]`.
#[derive(Clone, Debug, Deserialize, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct InitialSection {
    /// θ(0) \[rad\].
    #[serde(default)]
    pub theta: f64,
    /// ω(0) \[rad/s\] (0 = start from rest).
    #[serde(default)]
    pub omega: f64,
    /// Eccentricity at t = 0 \[m\] (stepper position).
    #[serde(default)]
    pub r: f64,
}

impl InitialSection {
    pub(super) fn validate(&self, r_max: f64) -> Result<(), Invalid> {
        keys::check_fields!(self, "initial", theta, omega)?;
        within_r_max(self.r, r_max).map_err(|why| Invalid::new("initial.r", why))
    }
}

/// An eccentricity in `[0, r_max]` (the plant's own bound, so not one of
/// [`keys::KEYS`]), else why not, as typed.
pub(super) fn within_r_max(r: f64, r_max: f64) -> Result<(), String> {
    if (0.0..=r_max).contains(&r) {
        Ok(())
    } else {
        Err(format!(
            "= {} m is outside [0, r_max = {}] m",
            keys::typed(r),
            keys::typed(r_max)
        ))
    }
}

/// A profile `[[t, value], ...]`: at least one knot, times in the range of
/// `{key}[].t` ([`keys::KEYS`]) increasing strictly, each value accepted by
/// `value_ok` (which says why not, as typed).
pub(super) fn profile_ok(
    p: &[[f64; 2]],
    key: &str,
    value_ok: impl Fn(f64) -> Result<(), String>,
) -> Result<(), Invalid> {
    if p.is_empty() {
        return Err(Invalid::new(key, "needs at least one [t, value] knot"));
    }
    let times = keys::described(&format!("{key}[].t"))?;
    for (k, &[t, v]) in p.iter().enumerate() {
        let at = format!("{key}[{k}]");
        times
            .check(t)
            .map_err(|e| Invalid::new(at.clone(), format!("knot {k}: time {e}")))?;
        value_ok(v).map_err(|e| Invalid::new(at.clone(), format!("knot {k}: value {e}")))?;
        if let Some(prev) = k.checked_sub(1).and_then(|j| p.get(j)) {
            if t <= prev[0] {
                return Err(Invalid::new(
                    at,
                    format!(
                        "knot {k}: times must increase strictly ({} then {})",
                        keys::typed(prev[0]),
                        keys::typed(t)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Deserialize `[[t, value], ...]`, refusing a knot with fewer or more than
/// two numbers (serde's `[f64; 2]` would drop a third value silently).
pub(super) fn knots<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
    let raw = Vec::<Vec<f64>>::deserialize(d)?;
    raw.into_iter()
        .enumerate()
        .map(|(k, knot)| match knot.as_slice() {
            &[t, v] => Ok([t, v]),
            other => Err(serde::de::Error::custom(format!(
                "knot {k} has {} numbers; each knot is exactly [t, value]",
                other.len()
            ))),
        })
        .collect()
}
