//! `[inputs]` (piecewise-linear V_m(t), T_U(t)) and `[initial]`.

use super::Invalid;
use serde::Deserialize;

/// `[inputs]`: piecewise-linear profiles as `[[t, value], ...]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct InputsSection {
    /// Motor voltage V_m(t) \[V\].
    pub v_m: Vec<[f64; 2]>,
    /// Brake torque T_U(t) \[N·m\].
    pub t_u: Vec<[f64; 2]>,
}

impl InputsSection {
    pub(super) fn validate(&self) -> Result<(), Invalid> {
        profile_ok(&self.v_m, "inputs.v_m", f64::NEG_INFINITY, f64::INFINITY)?;
        profile_ok(&self.t_u, "inputs.t_u", 0.0, f64::INFINITY)
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
        Invalid::check(self.theta.is_finite(), "initial.theta", || {
            format!("must be finite, got {}", self.theta)
        })?;
        Invalid::non_negative(self.omega, "initial.omega", "")?;
        Invalid::check((0.0..=r_max).contains(&self.r), "initial.r", || {
            format!("must be in [0, r_max = {r_max}] m, got {}", self.r)
        })
    }
}

/// A profile `[[t, value], ...]`: at least one knot, finite times ≥ 0
/// increasing strictly, values in `[lo, hi]`.
pub(super) fn profile_ok(p: &[[f64; 2]], key: &str, lo: f64, hi: f64) -> Result<(), Invalid> {
    if p.is_empty() {
        return Err(Invalid::new(key, "needs at least one [t, value] knot"));
    }
    for (k, &[t, v]) in p.iter().enumerate() {
        let at = format!("{key}[{k}]");
        if !(t.is_finite() && t >= 0.0) {
            return Err(Invalid::new(
                at,
                format!("knot {k}: time must be finite and ≥ 0, got {t}"),
            ));
        }
        if !(v.is_finite() && v >= lo && v <= hi) {
            return Err(Invalid::new(
                at,
                format!("knot {k}: value {v} outside [{lo}, {hi}]"),
            ));
        }
        if let Some(prev) = k.checked_sub(1).and_then(|j| p.get(j)) {
            if t <= prev[0] {
                return Err(Invalid::new(
                    at,
                    format!(
                        "knot {k}: times must increase strictly ({} then {t})",
                        prev[0]
                    ),
                ));
            }
        }
    }
    Ok(())
}
