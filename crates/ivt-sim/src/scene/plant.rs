//! `[plant]`: the preset (SPEC §6) and per-parameter overrides, in a scene
//! or in a plant file of its own (`[plant] file = "P.toml"`, `--plant-file`,
//! the output of `ivt rig identify`).

use super::locate::Doc;
use super::{Invalid, SceneError};
use ivt_kin::plant::{GravityModel, PlantParams, PlantPreset};
use serde::Deserialize;
use std::path::{Path, PathBuf};

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

impl From<PlantPreset> for PresetName {
    fn from(p: PlantPreset) -> Self {
        match p {
            PlantPreset::Printed => Self::Printed,
            PlantPreset::ThesisCh4 => Self::ThesisCh4,
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
    /// A plant file whose `[plant]` table is the base of this one (scenes
    /// only; relative to the scene's directory). The keys given beside it
    /// override the file's; `preset` and `gravity` come from the file.
    #[serde(default)]
    pub file: Option<PathBuf>,
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

/// A plant file: its `[plant]` table and nothing else (a key above the table
/// or another table is refused by name, as an unknown key inside it is).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlantFile {
    plant: PlantSection,
}

/// The overridable parameters, listed once: their names
/// (`OVERRIDE_NAMES`), the section's values and slots
/// (`PlantSection::overrides`, `overrides_mut`) and the matching
/// [`PlantParams`] fields (`param_slots`), all in this order.
macro_rules! overridable {
    ($($f:ident),+ $(,)?) => {
        const OVERRIDE_NAMES: [&str; 17] = [$(stringify!($f)),+];

        impl PlantSection {
            /// The override values, in `OVERRIDE_NAMES` order.
            fn overrides(&self) -> [Option<f64>; 17] {
                [$(self.$f),+]
            }

            /// The override slots, in `OVERRIDE_NAMES` order.
            fn overrides_mut(&mut self) -> [&mut Option<f64>; 17] {
                [$(&mut self.$f),+]
            }
        }

        /// The parameters of `p` that a section overrides, in `OVERRIDE_NAMES` order.
        fn param_slots(p: &mut PlantParams) -> [&mut f64; 17] {
            [$(&mut p.$f),+]
        }
    };
}

overridable!(
    r_a,
    k_e,
    k_t,
    l_a,
    j_n1,
    j_n2,
    j_inshaft,
    j_carrier,
    j_ring,
    j_crk,
    m_r,
    m_dr,
    j_u,
    r_u,
    g,
    sun_to_planet,
    r_max
);

impl PlantSection {
    /// The `[plant]` table of a plant file (preset + overrides), validated.
    ///
    /// # Errors
    /// One line `path:line:column: `plant.key` message` for I/O, TOML,
    /// unknown keys, a missing `[plant]` table, a nested `file` or an
    /// invalid parameter.
    pub fn from_file(path: &Path) -> Result<Self, SceneError> {
        let origin = path.display().to_string();
        let src = crate::input::read_text_bounded(path, crate::input::MAX_SCENE_BYTES)
            .map_err(|e| SceneError::reading(path, &e))?;
        Self::parse_file(&src, &origin)
    }

    /// As [`Self::from_file`] from the file's text; `origin` names it in errors.
    ///
    /// # Errors
    /// As [`Self::from_file`].
    pub fn parse_file(src: &str, origin: &str) -> Result<Self, SceneError> {
        let doc = Doc::new(src);
        let at = |span: Option<std::ops::Range<usize>>| doc.at(origin, span);
        let file: PlantFile =
            toml::from_str(src).map_err(|e| SceneError::invalid(doc.serde_error(origin, &e)))?;
        let plant = file.plant;
        let check = || {
            Invalid::check(plant.file.is_none(), "plant.file", || {
                "is not allowed in a plant file (no chains of plant files)".into()
            })?;
            plant.params().map(|_| ())
        };
        check().map_err(|e| SceneError::invalid(format!("{}: {e}", at(doc.span_of(&e.key)))))?;
        Ok(plant)
    }

    /// This section with its `file` (if any) read and merged: the file's
    /// preset, gravity and overrides, then the overrides given here. A
    /// relative `file` is taken from `base`.
    ///
    /// # Errors
    /// The plant file's own errors ([`Self::from_file`]).
    pub fn resolve(&self, base: &Path) -> Result<Self, SceneError> {
        let Some(file) = &self.file else {
            return Ok(self.clone());
        };
        let path = if file.is_absolute() {
            file.clone()
        } else {
            base.join(file)
        };
        let mut merged = Self::from_file(&path)?;
        for (mine, theirs) in self.overrides().into_iter().zip(merged.overrides_mut()) {
            if mine.is_some() {
                *theirs = mine;
            }
        }
        Ok(merged)
    }

    /// The section that describes `params` exactly: `preset` plus an
    /// override for every parameter that differs from it (what `ivt rig
    /// identify` writes).
    #[must_use]
    pub fn from_params(preset: PresetName, params: &PlantParams) -> Self {
        let mut s = Self {
            preset,
            gravity: match params.gravity {
                GravityModel::Printed => Gravity::Printed,
                GravityModel::RollerMass => Gravity::RollerMass,
            },
            ..Self::default()
        };
        let (mut want, mut have) = (*params, PlantPreset::from(preset).params());
        let pairs = param_slots(&mut want)
            .into_iter()
            .zip(param_slots(&mut have));
        for ((w, h), slot) in pairs.zip(s.overrides_mut()) {
            if w.to_bits() != h.to_bits() {
                *slot = Some(*w);
            }
        }
        s
    }

    /// The section as a plant file (`[plant]` table, preset first, then the
    /// overrides in Table 1 order; floats in shortest round-trip form).
    #[must_use]
    pub fn to_toml(&self) -> String {
        let preset = PlantPreset::from(self.preset).name();
        let gravity = match self.gravity {
            Gravity::Printed => "printed",
            Gravity::RollerMass => "roller_mass",
        };
        let mut out = format!("[plant]\npreset = \"{preset}\"\ngravity = \"{gravity}\"\n");
        for (name, v) in OVERRIDE_NAMES.iter().zip(self.overrides()) {
            if let Some(v) = v {
                out.push_str(&format!("{name} = {v:?}\n"));
            }
        }
        out
    }

    /// Plant parameters: preset plus overrides, validated.
    ///
    /// # Errors
    /// An invalid parameter (named `plant.<name>`), or an inductance too
    /// stiff for the explicit integrators.
    pub fn params(&self) -> Result<PlantParams, Invalid> {
        let mut params = PlantPreset::from(self.preset).params();
        params.gravity = self.gravity.into();
        for (v, slot) in self.overrides().into_iter().zip(param_slots(&mut params)) {
            if let Some(v) = v {
                *slot = v;
            }
        }
        params
            .validate()
            .map_err(|e| Invalid::new(format!("plant.{}", e.name), e.refused.to_string()))?;
        Invalid::check(params.l_a == 0.0 || params.l_a >= 1e-7, "plant.l_a", || {
            format!(
                "= {} H: below 1e-7 H the current mode (R_a/L_a > 2e6 /s) is too stiff for the explicit integrators; use 0 (Eq. 138)",
                super::keys::typed(params.l_a)
            )
        })?;
        Ok(params)
    }
}

#[cfg(test)]
#[path = "plant_file_tests.rs"]
mod tests;
