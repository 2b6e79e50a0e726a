//! The commissioning recording (rig or simulated rig) as arrays for
//! `ivt_design::identify`: an MCAP file with JSON channels `/pulses`
//! (`{"t": [...], "ticks": [...]}` batches of encoder edges), `/sensors`
//! (`t`, `v_m`, `t_u`), `/stepper` (`t`, `position`), `/sequence` (`t`,
//! `name`, `stage`, `theta_ct_deg`, `hold`, at each stage start) and the
//! metadata record `ivt` (`frame_version`, `ppr`, `f_timer_hz`, `plant`,
//! optional `steps_per_rev`, `theta0`). Other channels (`/control`) are
//! skipped.
//!
//! The file is walked record by record (`walk.rs`, within its budgets) so
//! that a truncated or corrupt one fails with the byte offset of the record
//! at fault — never a partial estimate: a recording without its footer and
//! closing magic is refused.

mod walk;

use ivt_design::identify::{Recording, Stage};
use ivt_kin::plant::PlantParams;
use ivt_sim::scene::PlantSection;
use serde_json::Value;
use std::path::Path;
use walk::Collected;

/// A recording as read, with its metadata.
#[derive(Debug)]
pub struct Commissioning {
    /// The arrays.
    pub recording: Recording,
    /// The plant the rig was built to (metadata `plant`; `printed` if absent).
    pub nominal: PlantSection,
    /// Metadata `frame_version` (None if absent).
    pub frame_version: Option<u64>,
    /// Timer rate of the edge times \[Hz\].
    pub f_timer_hz: Option<f64>,
    /// Stepper (micro)steps per revolution of θ_CT.
    pub steps_per_rev: f64,
}

/// Why a recording cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be read.
    #[error("{0}")]
    Io(String),
    /// The bytes are not a complete, valid MCAP recording (names the byte offset).
    #[error("{path}: {why}")]
    Corrupt {
        /// The file.
        path: String,
        /// What is wrong, with the byte offset.
        why: String,
    },
    /// Valid MCAP, but not a commissioning recording (a channel or key is missing or malformed).
    #[error("{path}: {why}")]
    Content {
        /// The file.
        path: String,
        /// What is missing or malformed.
        why: String,
    },
}

/// Largest commissioning recording read \[bytes\]: 512 MiB (23 MB for a
/// full simulated plan). The file is walked record by record within the
/// budgets of its walk (`walk`), never read whole.
pub const MAX_RECORDING_BYTES: u64 = 512 << 20;

/// Read a commissioning recording.
///
/// # Errors
/// [`ReadError::Corrupt`] (truncated, bad magic, bad record or chunk CRC,
/// unparsable message, a length beyond its budget: each with its byte
/// offset), [`ReadError::Content`] (missing channel or metadata),
/// [`ReadError::Io`] (the file cannot be opened or read: missing, not a
/// regular file, over [`MAX_RECORDING_BYTES`]).
pub fn read(path: &Path) -> Result<Commissioning, ReadError> {
    let io = |e: std::io::Error| ReadError::Io(format!("{}: {e}", path.display()));
    let mut input = ivt_sim::input::open(path, MAX_RECORDING_BYTES).map_err(io)?;
    let len = input.len();
    read_from(&mut input, len, &path.display().to_string()).map_err(|e| match e {
        ReadError::Io(m) => ReadError::Io(format!("{}: {m}", path.display())),
        other => other,
    })
}

/// A commissioning recording from `src` (`len` bytes), named `name` in
/// errors: what [`read`] does after opening the file (and the fuzz target
/// of the reader, `fuzz/fuzz_targets/recording_mcap.rs`).
///
/// # Errors
/// As [`read`]; [`ReadError::Io`] carries the read error alone.
pub fn read_from(
    src: &mut impl std::io::Read,
    len: u64,
    name: &str,
) -> Result<Commissioning, ReadError> {
    let mut c = Collected::default();
    walk::walk(src, len, &mut c).map_err(|e| match e {
        walk::WalkError::Io(e) => ReadError::Io(e.to_string()),
        walk::WalkError::Corrupt(why) => ReadError::Corrupt {
            path: name.to_string(),
            why,
        },
    })?;
    assemble(c).map_err(|why| ReadError::Content {
        path: name.to_string(),
        why,
    })
}

/// The range of every numeric metadata value (key, lowest, highest, the
/// range as printed): a value outside is refused by name, never clamped or
/// wrapped.
const META_RANGES: [(&str, f64, f64, &str); 5] = [
    ("frame_version", 0.0, 65_535.0, "[0, 65535]"),
    ("ppr", 1.0, 1e6, "[1, 1e6] pulses"),
    ("f_timer_hz", 1e3, 1e10, "[1e3, 1e10] Hz"),
    ("steps_per_rev", 1.0, 1e7, "[1, 1e7] steps"),
    (
        "theta0",
        ivt_design::identify::THETA0_RANGE[0],
        ivt_design::identify::THETA0_RANGE[1],
        "[−2π, 2π] rad",
    ),
];

/// `value` of metadata `key` inside its [`META_RANGES`] row.
fn in_range(key: &str, text: &str, value: f64) -> Result<f64, String> {
    match META_RANGES.iter().find(|r| r.0 == key) {
        Some(&(_, lo, hi, range)) if !(lo..=hi).contains(&value) => {
            Err(format!("metadata `{key}` = {text} is outside {range}"))
        }
        _ => Ok(value),
    }
}

/// The arrays from the collected channels and metadata.
fn assemble(c: Collected) -> Result<Commissioning, String> {
    let meta = c
        .meta
        .ok_or("no metadata record `ivt` (frame_version, ppr, f_timer_hz, plant)")?;
    let field = |k: &str| meta.get(k).map(|s| s.trim().trim_matches('"').to_string());
    let number = |k: &str| -> Result<Option<f64>, String> {
        field(k)
            .map(|s| {
                s.parse::<f64>()
                    .map_err(|e| format!("metadata `{k}` = {s:?}: {e}"))
                    .and_then(|v| in_range(k, &s, v))
            })
            .transpose()
    };
    let ppr = number("ppr")?.ok_or("metadata `ppr` is missing")?;
    if ppr.fract() != 0.0 {
        return Err(format!("metadata `ppr` = {ppr} is not a pulse count"));
    }
    let f_timer_hz = number("f_timer_hz")?;
    let nominal = match field("plant") {
        None => PlantSection::default(),
        Some(p) if p.starts_with('{') => plant_from_json(&p)?,
        Some(p) if p.contains('[') => {
            PlantSection::parse_file(&p, "metadata `plant`").map_err(|e| e.message)?
        }
        Some(p) => PlantSection {
            preset: ivt_kin::plant::PlantPreset::from_name(&p)
                .ok_or_else(|| {
                    format!(
                        "metadata `plant` = {}: not a preset (printed, thesis-ch4), a JSON object or a `[plant]` table",
                        ivt_sim::input::excerpt(&p)
                    )
                })?
                .into(),
            ..PlantSection::default()
        },
    };
    if c.pulse_t.len() < 2 {
        return Err("channel /pulses is missing or holds fewer than 2 edges".into());
    }
    if c.sensors.len() < 2 {
        return Err("channel /sensors is missing or holds fewer than 2 samples".into());
    }
    if c.stepper.is_empty() {
        return Err("channel /stepper is missing".into());
    }
    let steps_per_rev = match number("steps_per_rev")? {
        Some(s) => s,
        None => steps_per_rev_from_stages(&c.stages, &c.stepper)
            .ok_or("metadata `steps_per_rev` is missing and /sequence gives no stage at θ_CT > 0 to infer it")?,
    };
    let steps_per_rev = in_range("steps_per_rev", &steps_per_rev.to_string(), steps_per_rev)?;
    let pulse_t = match f_timer_hz {
        Some(f) if c.pulse_ticks.len() == c.pulse_t.len() => {
            edge_times(&c.pulse_t, &c.pulse_ticks, f)
        }
        _ => c.pulse_t,
    };
    let ppr = ppr as usize;
    let r_per_step = 360.0 / steps_per_rev * crank_m_per_deg();
    let theta0 = number("theta0")?.unwrap_or(std::f64::consts::TAU / ppr as f64);
    Ok(Commissioning {
        recording: Recording {
            ppr,
            theta0,
            pulse_t,
            sensors: c.sensors,
            eccentricity: c
                .stepper
                .iter()
                .map(|&(t, p)| (t, p as f64 * r_per_step))
                .collect(),
            stages: c.stages,
        },
        nominal,
        frame_version: number("frame_version")?.map(|v| v as u64),
        f_timer_hz,
        steps_per_rev,
    })
}

/// A simulated rig's metadata `plant`: a flat JSON object of `[plant]` keys
/// (`ivt_sim::commission`), read by the scene's `[plant]` parser.
fn plant_from_json(text: &str) -> Result<PlantSection, String> {
    let bad = |why: String| {
        format!(
            "metadata `plant` = {}: {why}",
            ivt_sim::input::excerpt(text)
        )
    };
    let obj: serde_json::Map<String, Value> =
        serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
    let mut toml = String::from("[plant]\n");
    for (k, v) in &obj {
        // Keys go into the TOML text as they are: only a parameter's name
        // (letters, digits, `_`), so that a key cannot write other lines.
        if k.is_empty() || !k.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
            return Err(bad(format!(
                "{} is not a plant parameter",
                ivt_sim::input::excerpt(k)
            )));
        }
        match v {
            Value::Number(n) => toml.push_str(&format!("{k} = {n}\n")),
            Value::String(s) => toml.push_str(&format!("{k} = {s:?}\n")),
            _ => return Err(bad(format!("`{k}` is neither a number nor a string"))),
        }
    }
    PlantSection::parse_file(&toml, "metadata `plant`").map_err(|e| bad(e.message))
}

/// Eq. 185 in SI: e \[m\] per degree of θ_CT, 7π/51840 inch.
pub fn crank_m_per_deg() -> f64 {
    ivt_kin::units::inch_to_m(ivt_kin::sgivt::CRANK_PER_STEPPER_INCH_PER_DEG)
}

/// Steps per revolution from the stages: the stepper position at the end
/// of each stage with θ_CT > 0 over its θ_CT (median).
fn steps_per_rev_from_stages(stages: &[Stage], stepper: &[(f64, i64)]) -> Option<f64> {
    let mut ratios: Vec<f64> = stages
        .iter()
        .enumerate()
        .filter(|(_, s)| s.theta_ct_deg > 0.0)
        .filter_map(|(k, s)| {
            let end = stages.get(k + 1).map_or(f64::INFINITY, |n| n.t);
            let i = stepper.partition_point(|p| p.0 < end).checked_sub(1)?;
            let pos = stepper.get(i)?.1 as f64;
            Some(pos / s.theta_ct_deg * 360.0)
        })
        .collect();
    ratios.sort_by(f64::total_cmp);
    ratios.get(ratios.len() / 2).copied()
}

/// Edge times from the timer captures: the first edge's `t`, then the
/// wrapping 32-bit tick differences over the timer rate (finer than `t`
/// when that was rounded).
fn edge_times(t: &[f64], ticks: &[u64], f_timer_hz: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(t.len());
    let mut now = t.first().copied().unwrap_or(0.0);
    let mut prev: Option<u64> = None;
    for &k in ticks {
        if let Some(p) = prev {
            let d = (k as u32).wrapping_sub(p as u32);
            now += f64::from(d) / f_timer_hz;
        }
        out.push(now);
        prev = Some(k);
    }
    out
}

/// The nominal plant's parameters.
///
/// # Errors
/// An invalid `plant` table in the metadata.
pub fn nominal_params(c: &Commissioning) -> Result<PlantParams, String> {
    c.nominal
        .params()
        .map_err(|e| format!("metadata `plant`: {e}"))
}
