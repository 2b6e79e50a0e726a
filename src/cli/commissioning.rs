//! The commissioning recording (rig or simulated rig) as arrays for
//! `ivt_design::identify`: an MCAP file with JSON channels `/pulses`
//! (`{"t": [...], "ticks": [...]}` batches of encoder edges), `/sensors`
//! (`t`, `v_m`, `t_u`), `/stepper` (`t`, `position`), `/sequence` (`t`,
//! `name`, `stage`, `theta_ct_deg`, `hold`, at each stage start) and the
//! metadata record `ivt` (`frame_version`, `ppr`, `f_timer_hz`, `plant`,
//! optional `steps_per_rev`, `theta0`). Other channels (`/control`) are
//! skipped.
//!
//! The file is walked record by record so that a truncated or corrupt one
//! fails with the byte offset of the record at fault — never a partial
//! estimate: a recording without its footer and closing magic is refused.

use ivt_design::identify::{Recording, Stage};
use ivt_kin::plant::PlantParams;
use ivt_sim::scene::PlantSection;
use mcap::records::Record;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

/// The MCAP magic, at both ends of a file.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

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

/// The channels and metadata collected while walking the file.
#[derive(Default)]
struct Collected {
    topics: BTreeMap<u16, String>,
    pulse_t: Vec<f64>,
    pulse_ticks: Vec<u64>,
    sensors: Vec<[f64; 3]>,
    stepper: Vec<(f64, i64)>,
    stages: Vec<Stage>,
    meta: Option<BTreeMap<String, String>>,
}

/// Largest commissioning recording read \[bytes\]: 512 MiB, a third of the
/// 1.5 GB a hostile input may cost (the recording is read whole).
const MAX_RECORDING_BYTES: u64 = 512 << 20;

/// Read a commissioning recording.
///
/// # Errors
/// [`ReadError::Corrupt`] (truncated, bad magic, bad record or chunk CRC,
/// unparsable message: each with its byte offset), [`ReadError::Content`]
/// (missing channel or metadata), [`ReadError::Io`].
pub fn read(path: &Path) -> Result<Commissioning, ReadError> {
    let bytes = ivt_sim::input::read_bounded(path, MAX_RECORDING_BYTES)
        .map_err(|e| ReadError::Io(format!("{}: {e}", path.display())))?;
    let name = path.display().to_string();
    let corrupt = |why: String| ReadError::Corrupt {
        path: name.clone(),
        why,
    };
    let content = |why: String| ReadError::Content {
        path: name.clone(),
        why,
    };
    let mut c = Collected::default();
    walk(&bytes, &mut c).map_err(corrupt)?;
    assemble(c).map_err(content)
}

/// Every record from the leading magic to the footer and closing magic.
fn walk(bytes: &[u8], c: &mut Collected) -> Result<(), String> {
    let len = bytes.len();
    if bytes.get(..8) != Some(MAGIC.as_slice()) {
        return Err("not an MCAP file: no magic at byte offset 0".into());
    }
    let mut at = 8usize;
    loop {
        let Some(head) = bytes.get(at..at + 9) else {
            return Err(format!(
                "truncated at byte offset {at}: the file ends ({len} bytes) before the footer"
            ));
        };
        let (op, body_len) = match head.split_first() {
            Some((&op, len)) => (op, <[u8; 8]>::try_from(len).map(u64::from_le_bytes)),
            None => (0, Ok(u64::MAX)),
        };
        let body_len = body_len.unwrap_or(u64::MAX);
        let end = usize::try_from(body_len)
            .ok()
            .and_then(|b| (at + 9).checked_add(b))
            .filter(|&e| e <= len)
            .ok_or_else(|| {
                format!(
                    "truncated at byte offset {at}: record 0x{op:02x} of {body_len} bytes runs past the end of the file ({len} bytes)"
                )
            })?;
        let body = bytes.get(at + 9..end).unwrap_or_default();
        let record = mcap::read::parse_record(op, body)
            .map_err(|e| format!("corrupt record 0x{op:02x} at byte offset {at}: {e}"))?;
        match record {
            Record::DataEnd(d) => {
                // The data section's CRC covers every byte before this record
                // (messages, chunks and their indexes alike).
                let crc = crc32fast::hash(bytes.get(..at).unwrap_or_default());
                if d.data_section_crc != 0 && d.data_section_crc != crc {
                    return Err(format!(
                        "corrupt data section (bytes 0 to {at}): its CRC 0x{crc:08x} is not the recorded 0x{:08x} (data end record at byte offset {at})",
                        d.data_section_crc
                    ));
                }
            }
            Record::Footer(f) => {
                let start = usize::try_from(f.summary_start).unwrap_or(usize::MAX);
                // The summary CRC covers the summary section up to the footer's summary_crc field.
                let covered = bytes.get(start..at + 9 + 16);
                if f.summary_start != 0 && f.summary_crc != 0 {
                    match covered.map(crc32fast::hash) {
                        Some(crc) if crc == f.summary_crc => {}
                        _ => {
                            return Err(format!(
                                "corrupt summary section (from byte offset {start}): CRC mismatch (footer at byte offset {at})"
                            ))
                        }
                    }
                }
                return if bytes.get(end..) == Some(MAGIC.as_slice()) {
                    Ok(())
                } else {
                    Err(format!(
                        "corrupt or truncated at byte offset {end}: no closing magic after the footer"
                    ))
                };
            }
            Record::Chunk { header, data } => {
                let records = mcap::read::ChunkReader::new(header, &data)
                    .map_err(|e| format!("corrupt chunk at byte offset {at}: {e}"))?;
                for r in records {
                    let r = r.map_err(|e| format!("corrupt chunk at byte offset {at}: {e}"))?;
                    take(r, c).map_err(|e| format!("in the chunk at byte offset {at}: {e}"))?;
                }
            }
            other => take(other, c).map_err(|e| format!("at byte offset {at}: {e}"))?,
        }
        at = end;
    }
}

/// File one record's content away.
fn take(r: Record<'_>, c: &mut Collected) -> Result<(), String> {
    match r {
        Record::Channel(ch) => {
            c.topics.insert(ch.id, ch.topic);
        }
        Record::Metadata(m) if m.name == "ivt" => c.meta = Some(m.metadata),
        Record::Message { header, data } => {
            let topic = c
                .topics
                .get(&header.channel_id)
                .cloned()
                .unwrap_or_default();
            if !matches!(
                topic.as_str(),
                "/pulses" | "/sensors" | "/stepper" | "/sequence"
            ) {
                return Ok(());
            }
            let v: Value = serde_json::from_slice(&data)
                .map_err(|e| format!("message {} on {topic} is not JSON: {e}", header.sequence))?;
            message(&topic, &v, c).ok_or_else(|| {
                format!("message {} on {topic} lacks a field: {v}", header.sequence)
            })?;
        }
        _ => {}
    }
    Ok(())
}

/// One JSON message of a known channel (None: a field is missing or of the wrong type).
fn message(topic: &str, v: &Value, c: &mut Collected) -> Option<()> {
    let num = |k: &str| v.get(k).and_then(Value::as_f64);
    match topic {
        "/pulses" => {
            let t = v.get("t")?.as_array()?;
            let ticks = v.get("ticks").and_then(Value::as_array);
            if ticks.is_some_and(|k| k.len() != t.len()) {
                return None;
            }
            for x in t {
                c.pulse_t.push(x.as_f64()?);
            }
            for x in ticks.into_iter().flatten() {
                c.pulse_ticks.push(x.as_u64()?);
            }
        }
        "/sensors" => c.sensors.push([num("t")?, num("v_m")?, num("t_u")?]),
        "/stepper" => c.stepper.push((num("t")?, v.get("position")?.as_i64()?)),
        _ => c.stages.push(Stage {
            t: num("t")?,
            name: v.get("name")?.as_str()?.to_string(),
            // null while the law runs (the drive cycle, the step test's law stages).
            theta_ct_deg: match v.get("theta_ct_deg")? {
                Value::Null => f64::NAN,
                x => x.as_f64()?,
            },
        }),
    }
    Some(())
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
            PlantSection::parse_file(&p, "metadata `plant`").map_err(|e| e.0)?
        }
        Some(p) => {
            let text = format!("[plant]\npreset = \"{p}\"\n");
            PlantSection::parse_file(&text, "metadata `plant`").map_err(|e| e.0)?
        }
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
    let bad = |why: String| format!("metadata `plant` = {text}: {why}");
    let obj: serde_json::Map<String, Value> =
        serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
    let mut toml = String::from("[plant]\n");
    for (k, v) in &obj {
        match v {
            Value::Number(n) => toml.push_str(&format!("{k} = {n}\n")),
            Value::String(s) => toml.push_str(&format!("{k} = {s:?}\n")),
            _ => return Err(bad(format!("`{k}` is neither a number nor a string"))),
        }
    }
    PlantSection::parse_file(&toml, "metadata `plant`").map_err(|e| bad(e.0))
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
