//! The commissioning recording walked record by record from its file, every
//! length checked against a budget before anything is allocated: the file
//! is never read whole, a record (a chunk compressed or decompressed) is at
//! most [`MAX_RECORD_BYTES`], the chunks' declared uncompressed sizes add up
//! to at most [`MAX_DECOMPRESSED_BYTES`] (checked before a chunk is
//! decompressed, and the decompression stops at the declared size), and the
//! JSON arrays of the messages are parsed straight into the recording's
//! arrays, at most [`MAX_EDGES`] edges and [`MAX_MESSAGES`] messages per
//! channel (no JSON value tree).
//!
//! The framing, the magic at both ends and the data-section and summary
//! CRCs are mcap's [`LinearReader`] (with its record-length limit); the few
//! records read (channel, message, metadata, chunk) are parsed here with
//! every string length checked against its record, since mcap's own parser
//! reserves a string's declared length before reading it.

use ivt_design::identify::Stage;
use mcap::records::op;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;
use serde::de::{DeserializeSeed, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::io::Read;

/// Longest record \[bytes\]: a chunk compressed or decompressed, a message.
/// A recording's chunks are ~1 MiB (mcap's writer) and its messages a few
/// kB.
pub const MAX_RECORD_BYTES: usize = 64 << 20;
/// Longest record other than a chunk or a message \[bytes\] (channels,
/// schemas, metadata: a few hundred bytes in a recording).
pub const MAX_SMALL_RECORD_BYTES: usize = 1 << 20;
/// Sum of the chunks' uncompressed sizes \[bytes\]: 1 GiB, about 7× a full
/// commissioning plan (measured: 23 MB compressed, 150 MB decompressed).
pub const MAX_DECOMPRESSED_BYTES: u64 = 1 << 30;
/// Most encoder edges in `/pulses`: 43× a full plan's 93 363 edges (SIL,
/// PPR 1200).
pub const MAX_EDGES: usize = 4_000_000;
/// Most messages of `/sensors` or `/stepper`: 16× a full plan's 245 833
/// stepper samples (SIL), 11 h of rig telemetry at 100 Hz.
pub const MAX_MESSAGES: usize = 4_000_000;
/// Most `/sequence` stage starts (a plan has 27).
pub const MAX_STAGES: usize = 100_000;
/// Longest stage name (`sweep`, `hold`, `step`, `drive`) \[bytes\].
const MAX_STAGE_NAME: usize = 64;

/// The channels a commissioning recording's arrays come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Topic {
    Pulses,
    Sensors,
    Stepper,
    Sequence,
}

impl Topic {
    fn of(name: &[u8]) -> Option<Self> {
        match name {
            b"/pulses" => Some(Self::Pulses),
            b"/sensors" => Some(Self::Sensors),
            b"/stepper" => Some(Self::Stepper),
            b"/sequence" => Some(Self::Sequence),
            _ => None,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Pulses => "/pulses",
            Self::Sensors => "/sensors",
            Self::Stepper => "/stepper",
            Self::Sequence => "/sequence",
        }
    }
}

/// The channels and metadata collected while walking the file.
#[derive(Default)]
pub struct Collected {
    /// Channel id → the known channel it carries (other channels are skipped).
    topics: BTreeMap<u16, Topic>,
    /// `/pulses` edge times \[s\].
    pub pulse_t: Vec<f64>,
    /// `/pulses` timer captures (empty or one per edge).
    pub pulse_ticks: Vec<u64>,
    /// `/sensors` (t, V_m, T_U).
    pub sensors: Vec<[f64; 3]>,
    /// `/stepper` (t, position).
    pub stepper: Vec<(f64, i64)>,
    /// `/sequence` stage starts.
    pub stages: Vec<Stage>,
    /// The metadata record `ivt`.
    pub meta: Option<BTreeMap<String, String>>,
    /// Uncompressed bytes of the chunks so far.
    decompressed: u64,
}

/// Walks the recording `src` (`len` bytes) from its magic to its closing
/// magic into `c`.
///
/// # Errors
/// [`WalkError::Corrupt`]: what is wrong, with the byte offset of the record
/// at fault; [`WalkError::Io`]: reading `src` failed.
pub fn walk(src: &mut impl Read, len: u64, c: &mut Collected) -> Result<(), WalkError> {
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_emit_chunks(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(MAX_RECORD_BYTES),
    );
    // Offset of the record being read: after the magic, then after each
    // record (opcode, length, body).
    let mut at: u64 = 8;
    let mut records = 0u64;
    while let Some(event) = reader.next_event() {
        let event = event.map_err(|e| WalkError::Corrupt(framing(&e, at, records, len)))?;
        match event {
            LinearReadEvent::ReadRequest(n) => {
                let got = src.read(reader.insert(n)).map_err(WalkError::Io)?;
                reader.notify_read(got);
            }
            LinearReadEvent::Record { opcode, data } => {
                let body_len = data.len() as u64;
                record(opcode, data, c, false)
                    .map_err(|e| WalkError::Corrupt(format!("at byte offset {at}: {e}")))?;
                at += 9 + body_len;
                records += 1;
            }
        }
    }
    Ok(())
}

/// Why a walk stopped.
#[derive(Debug)]
pub enum WalkError {
    /// The file could not be read (its error).
    Io(std::io::Error),
    /// The bytes are not a complete, valid recording (with the byte offset).
    Corrupt(String),
}

/// A framing error of mcap's reader, at the record starting at `at`.
fn framing(e: &McapError, at: u64, records: u64, len: u64) -> String {
    match e {
        McapError::BadMagic if records == 0 => "not an MCAP file: no magic at byte offset 0".into(),
        McapError::BadMagic => {
            format!("corrupt or truncated at byte offset {at}: no closing magic after the footer")
        }
        McapError::UnexpectedEof => format!(
            "truncated at byte offset {at}: the file ends ({len} bytes) before the footer and its closing magic"
        ),
        McapError::BadDataCrc { saved, calculated } => format!(
            "corrupt data section (bytes 0 to {at}): its CRC 0x{calculated:08x} is not the recorded 0x{saved:08x} (data end record at byte offset {at})"
        ),
        McapError::BadSummaryCrc { .. } => {
            format!("corrupt summary section: CRC mismatch (footer at byte offset {at})")
        }
        McapError::RecordTooLarge { opcode, len } => format!(
            "record 0x{opcode:02x} at byte offset {at} claims {len} bytes, more than the {MAX_RECORD_BYTES} a record may have"
        ),
        McapError::BytesAfterEndMagic => {
            format!("bytes after the closing magic (footer before byte offset {at})")
        }
        other => format!("corrupt record at byte offset {at}: {other}"),
    }
}

/// One record's content (`in_chunk`: read from a chunk's records).
fn record(opcode: u8, body: &[u8], c: &mut Collected, in_chunk: bool) -> Result<(), String> {
    let small = || {
        if body.len() > MAX_SMALL_RECORD_BYTES {
            Err(format!(
                "record 0x{opcode:02x} of {} bytes: more than the {MAX_SMALL_RECORD_BYTES} it may have",
                body.len()
            ))
        } else {
            Ok(())
        }
    };
    match opcode {
        op::CHANNEL => {
            small()?;
            let mut r = Fields(body);
            let id = r.u16()?;
            let _schema = r.u16()?;
            match Topic::of(r.bytes("topic")?) {
                Some(t) => c.topics.insert(id, t),
                None => c.topics.remove(&id),
            };
        }
        op::METADATA => {
            small()?;
            let mut r = Fields(body);
            if r.bytes("name")? == b"ivt" {
                c.meta = Some(r.string_map()?);
            }
        }
        op::MESSAGE => {
            let mut r = Fields(body);
            let channel = r.u16()?;
            let sequence = r.u32()?;
            let _log_time = r.u64()?;
            let _publish_time = r.u64()?;
            if let Some(&topic) = c.topics.get(&channel) {
                message(topic, r.0, c)
                    .map_err(|e| format!("message {sequence} on {}: {e}", topic.name()))?;
            }
        }
        op::CHUNK if in_chunk => return Err("a chunk inside a chunk".into()),
        op::CHUNK => chunk(body, c)?,
        _ => {}
    }
    Ok(())
}

/// A chunk: its declared uncompressed size checked against the budgets, then
/// decompressed (no further than that size), CRC-checked and walked.
fn chunk(body: &[u8], c: &mut Collected) -> Result<(), String> {
    let mut r = Fields(body);
    let _start = r.u64()?;
    let _end = r.u64()?;
    let size = r.u64()?;
    let crc = r.u32()?;
    let compression = r.bytes("compression")?;
    let compressed_size = r.u64()?;
    let data = usize::try_from(compressed_size)
        .ok()
        .and_then(|n| r.0.get(..n))
        .ok_or_else(|| {
            format!(
                "chunk claims {compressed_size} compressed bytes, its record holds {}",
                r.0.len()
            )
        })?;
    let total = c.decompressed.saturating_add(size);
    if size > MAX_RECORD_BYTES as u64 || total > MAX_DECOMPRESSED_BYTES {
        return Err(format!(
            "chunk claims {size} uncompressed bytes ({total} in the chunks so far): more than the {MAX_RECORD_BYTES} a chunk or the {MAX_DECOMPRESSED_BYTES} a recording may have"
        ));
    }
    c.decompressed = total;
    let size = size as usize; // ≤ MAX_RECORD_BYTES
    let records = match compression {
        b"" if data.len() == size => std::borrow::Cow::Borrowed(data),
        b"" => {
            return Err(format!(
                "uncompressed chunk of {} bytes claims {size}",
                data.len()
            ))
        }
        b"zstd" => {
            let out = zstd::bulk::decompress(data, size)
                .map_err(|e| format!("chunk does not decompress within its {size} bytes: {e}"))?;
            if out.len() != size {
                return Err(format!(
                    "chunk decompresses to {} bytes, it claims {size}",
                    out.len()
                ));
            }
            std::borrow::Cow::Owned(out)
        }
        other => {
            return Err(format!(
                "chunk compression {:?} is not supported (zstd or none)",
                String::from_utf8_lossy(other)
            ))
        }
    };
    if crc != 0 && crc32fast::hash(&records) != crc {
        return Err("chunk CRC mismatch".into());
    }
    let mut at = 0usize;
    while at < records.len() {
        let head = records
            .get(at..at + 9)
            .ok_or_else(|| format!("chunk ends inside the head of its record at {at}"))?;
        let (opcode, len) = match head.split_first() {
            Some((&o, l)) => (
                o,
                <[u8; 8]>::try_from(l).map_or(u64::MAX, u64::from_le_bytes),
            ),
            None => (0, u64::MAX),
        };
        let body = usize::try_from(len)
            .ok()
            .and_then(|n| (at + 9).checked_add(n))
            .and_then(|end| records.get(at + 9..end))
            .ok_or_else(|| {
                format!(
                    "in its chunk, record 0x{opcode:02x} at {at} claims {len} bytes, more than the chunk holds ({})",
                    records.len()
                )
            })?;
        record(opcode, body, c, true).map_err(|e| format!("in its chunk, record at {at}: {e}"))?;
        at += 9 + body.len();
    }
    Ok(())
}

/// Little-endian fields of a record, each length checked against what is
/// left of it.
struct Fields<'a>(&'a [u8]);

impl<'a> Fields<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        if n > self.0.len() {
            return Err(format!(
                "{what} of {n} bytes runs past the end of its record ({} left)",
                self.0.len()
            ));
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let b = self.take(N, "a field")?;
        <[u8; N]>::try_from(b).map_err(|e| e.to_string())
    }

    fn u16(&mut self) -> Result<u16, String> {
        self.array().map(u16::from_le_bytes)
    }

    fn u32(&mut self) -> Result<u32, String> {
        self.array().map(u32::from_le_bytes)
    }

    fn u64(&mut self) -> Result<u64, String> {
        self.array().map(u64::from_le_bytes)
    }

    /// A u32-prefixed byte string.
    fn bytes(&mut self, what: &str) -> Result<&'a [u8], String> {
        let n = self.u32()? as usize;
        self.take(n, what)
    }

    /// A u32-prefixed map of u32-prefixed UTF-8 strings.
    fn string_map(&mut self) -> Result<BTreeMap<String, String>, String> {
        let n = self.u32()? as usize;
        let mut entries = Fields(self.take(n, "the metadata map")?);
        let mut map = BTreeMap::new();
        let text = |b: &[u8]| {
            std::str::from_utf8(b)
                .map(str::to_string)
                .map_err(|e| format!("metadata is not UTF-8: {e}"))
        };
        while !entries.0.is_empty() {
            let k = text(entries.bytes("a metadata key")?)?;
            let v = text(entries.bytes("a metadata value")?)?;
            map.insert(k, v);
        }
        Ok(map)
    }
}

/// One JSON message of a known channel, parsed into the arrays.
fn message(topic: Topic, data: &[u8], c: &mut Collected) -> Result<(), String> {
    let mut de = serde_json::Deserializer::from_slice(data);
    let full = |what: &str, cap: usize| format!("more than the {cap} {what} a recording may have");
    match topic {
        Topic::Pulses => Pulses { c }
            .deserialize(&mut de)
            .map_err(|e| e.to_string())?,
        Topic::Sensors => {
            let s = SensorSample::deserialize(&mut de).map_err(|e| e.to_string())?;
            if c.sensors.len() >= MAX_MESSAGES {
                return Err(full("sensor samples", MAX_MESSAGES));
            }
            c.sensors.push([s.t, s.v_m, s.t_u]);
        }
        Topic::Stepper => {
            let s = StepperSample::deserialize(&mut de).map_err(|e| e.to_string())?;
            if c.stepper.len() >= MAX_MESSAGES {
                return Err(full("stepper samples", MAX_MESSAGES));
            }
            c.stepper.push((s.t, s.position));
        }
        Topic::Sequence => {
            let s = StageStart::deserialize(&mut de).map_err(|e| e.to_string())?;
            if c.stages.len() >= MAX_STAGES {
                return Err(full("stage starts", MAX_STAGES));
            }
            if s.name.len() > MAX_STAGE_NAME {
                return Err(format!(
                    "a stage name of {} bytes (at most {MAX_STAGE_NAME})",
                    s.name.len()
                ));
            }
            c.stages.push(Stage {
                t: s.t,
                name: s.name,
                theta_ct_deg: s.theta_ct_deg,
            });
        }
    }
    de.end().map_err(|e| e.to_string())
}

#[derive(Deserialize)]
struct SensorSample {
    t: f64,
    v_m: f64,
    t_u: f64,
}

#[derive(Deserialize)]
struct StepperSample {
    t: f64,
    position: i64,
}

#[derive(Deserialize)]
struct StageStart {
    t: f64,
    name: String,
    /// Null while the law runs (the drive cycle, the step test's law stages).
    #[serde(deserialize_with = "null_as_nan")]
    theta_ct_deg: f64,
}

/// A number, or NaN for `null` (the key itself is required).
fn null_as_nan<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Option::<f64>::deserialize(d).map(|v| v.unwrap_or(f64::NAN))
}

/// A `/pulses` batch `{"t": [...], "ticks": [...]}` (`ticks` optional, as
/// long as `t`), appended to the recording's arrays as it is parsed.
struct Pulses<'c> {
    c: &'c mut Collected,
}

impl<'de> DeserializeSeed<'de> for Pulses<'_> {
    type Value = ();

    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_map(self)
    }
}

impl<'de> Visitor<'de> for Pulses<'_> {
    type Value = ();

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("an object with the arrays `t` and `ticks`")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        use serde::de::Error as _;
        let c = self.c;
        let (mut t, mut ticks) = (None, None);
        while let Some(key) = map.next_key::<std::borrow::Cow<'_, str>>()? {
            match key.as_ref() {
                "t" if t.is_some() => return Err(A::Error::duplicate_field("t")),
                "ticks" if ticks.is_some() => return Err(A::Error::duplicate_field("ticks")),
                "t" => t = Some(map.next_value_seed(Append(&mut c.pulse_t))?),
                "ticks" => ticks = Some(map.next_value_seed(Append(&mut c.pulse_ticks))?),
                _ => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        let t = t.ok_or_else(|| A::Error::missing_field("t"))?;
        match ticks {
            Some(k) if k != t => Err(A::Error::custom(format!(
                "`ticks` has {k} entries, `t` {t}"
            ))),
            _ => Ok(()),
        }
    }
}

/// Appends a JSON array to a vector, at most [`MAX_EDGES`] in all; the
/// count appended.
struct Append<'v, T>(&'v mut Vec<T>);

impl<'de, T: Deserialize<'de>> DeserializeSeed<'de> for Append<'_, T> {
    type Value = usize;

    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<usize, D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de, T: Deserialize<'de>> Visitor<'de> for Append<'_, T> {
    type Value = usize;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("an array")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<usize, A::Error> {
        use serde::de::Error as _;
        let mut n = 0;
        while let Some(x) = seq.next_element()? {
            if self.0.len() >= MAX_EDGES {
                return Err(A::Error::custom(format!(
                    "more than the {MAX_EDGES} encoder edges a recording may have"
                )));
            }
            self.0.push(x);
            n += 1;
        }
        Ok(n)
    }
}
