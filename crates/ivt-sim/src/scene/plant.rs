//! `[plant]`: the preset (SPEC §6) and per-parameter overrides.

use super::Invalid;
use ivt_kin::plant::{GravityModel, PlantParams, PlantPreset};
use serde::Deserialize;

/// `[plant] preset`: the parameter set the overrides start from.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
pub enum PresetName {
    /// Table 1 as printed ([`PlantParams::printed`]).
    #[default]
    #[serde(rename = "printed")]
    Printed,
    /// Table 1 with k_t, k_e / 10 ([`PlantParams::thesis_ch4`], SPEC §5).
    #[serde(rename = "thesis-ch4")]
    ThesisCh4,
}

impl From<PresetName> for PlantPreset {
    fn from(p: PresetName) -> Self {
        match p {
            PresetName::Printed => Self::Printed,
            PresetName::ThesisCh4 => Self::ThesisCh4,
        }
    }
}

/// `[plant] gravity`: the gravity term of Eq. 151 (SPEC §5).
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum Gravity {
    /// G = g(sin θ + cos θ) as printed.
    #[default]
    Printed,
    /// m_r g.
    RollerMass,
}

impl From<Gravity> for GravityModel {
    fn from(g: Gravity) -> Self {
        match g {
            Gravity::Printed => Self::Printed,
            Gravity::RollerMass => Self::RollerMass,
        }
    }
}

/// `[plant]`: `preset = "printed" | "thesis-ch4"` and any parameter of
/// [`PlantParams`] as an override.
#[derive(Clone, Debug, Deserialize, PartialEq, Default)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct PlantSection {
    /// Parameter set (default `"printed"`, Table 1).
    #[serde(default)]
    pub preset: PresetName,
    /// Gravity term (default `"printed"`).
    #[serde(default)]
    pub gravity: Gravity,
    pub r_a: Option<f64>,
    pub k_e: Option<f64>,
    pub k_t: Option<f64>,
    pub l_a: Option<f64>,
    pub j_n1: Option<f64>,
    pub j_n2: Option<f64>,
    pub j_inshaft: Option<f64>,
    pub j_carrier: Option<f64>,
    pub j_ring: Option<f64>,
    pub j_crk: Option<f64>,
    pub m_r: Option<f64>,
    pub m_dr: Option<f64>,
    pub j_u: Option<f64>,
    pub r_u: Option<f64>,
    pub g: Option<f64>,
    pub sun_to_planet: Option<f64>,
    pub r_max: Option<f64>,
}

impl PlantSection {
    /// Plant parameters: preset plus overrides, validated.
    ///
    /// # Errors
    /// An invalid parameter (named `plant.<name>`), or an inductance too
    /// stiff for the explicit integrators.
    pub fn params(&self) -> Result<PlantParams, Invalid> {
        let p = self;
        let mut params = PlantPreset::from(p.preset).params();
        params.gravity = p.gravity.into();
        let overrides: [(Option<f64>, &mut f64); 17] = [
            (p.r_a, &mut params.r_a),
            (p.k_e, &mut params.k_e),
            (p.k_t, &mut params.k_t),
            (p.l_a, &mut params.l_a),
            (p.j_n1, &mut params.j_n1),
            (p.j_n2, &mut params.j_n2),
            (p.j_inshaft, &mut params.j_inshaft),
            (p.j_carrier, &mut params.j_carrier),
            (p.j_ring, &mut params.j_ring),
            (p.j_crk, &mut params.j_crk),
            (p.m_r, &mut params.m_r),
            (p.m_dr, &mut params.m_dr),
            (p.j_u, &mut params.j_u),
            (p.r_u, &mut params.r_u),
            (p.g, &mut params.g),
            (p.sun_to_planet, &mut params.sun_to_planet),
            (p.r_max, &mut params.r_max),
        ];
        for (v, slot) in overrides {
            if let Some(v) = v {
                *slot = v;
            }
        }
        params.validate().map_err(|e| {
            Invalid::new(
                format!("plant.{}", e.name),
                format!("= {} must be {}", e.value, e.requirement),
            )
        })?;
        Invalid::check(params.l_a == 0.0 || params.l_a >= 1e-7, "plant.l_a", || {
            format!(
                "= {} H: below 1e-7 H the current mode (R_a/L_a > 2e6 /s) is too stiff for the explicit integrators; use 0 (Eq. 138)",
                params.l_a
            )
        })?;
        Ok(params)
    }
}
