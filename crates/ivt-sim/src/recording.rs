//! A commissioning recording: the MCAP file that `ivt rig record`, `ivt rig
//! commission` (rig, SIL, PIL) write and `ivt rig identify` reads. JSON
//! channels, `t` always in seconds from the start:
//!
//! | channel | fields | one message per |
//! |---|---|---|
//! | `/control` | `t`, `ticks`, `omega`, `omega_a`, `r`, `fault` (rig); the simulator's whole control sample (SIL/PIL) | telemetry frame / pulse |
//! | `/stepper` | `t`, `position` (+ `target`, `commanded`, `missed` in the simulator) | telemetry frame / pulse |
//! | `/sensors` | `t`, `v_m`, `t_u`: the inputs the controller read | telemetry frame / sensor reading |
//! | `/pulses` | `t: [s…]`, `ticks: [u32…]`: every encoder edge (pulse-log stages) | batch |
//! | `/sequence` | `t`, `name` (sweep, hold, step, drive), `stage`, `theta_ct_deg` (null when the law runs), `hold` | stage start |
//!
//! and a metadata record `ivt`: `frame_version`, `ppr`, `f_timer_hz` and,
//! for a simulated rig, `plant` (the plant's parameters as JSON, the keys of
//! a `[plant]` table) and `steps_per_rev`. Metadata
//! values are strings (MCAP), each a JSON value.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use crate::atomic::Staged;
use crate::error::{io_at, mcap_at, SimError};
use crate::output::{add_json_channel, add_schema_channel};
use crate::record::{Channel, Record};
use ivt_ctrl::commission::SequenceName;

/// A channel of a recording: one of the simulator's (the channel table of
/// [`crate::record`]) or one that only a commissioning run has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Topic {
    /// A simulator channel, with its samples' fields.
    Sim(Channel),
    /// `/pulses`: batches of encoder edge times.
    Pulses,
    /// `/sequence`: stage starts.
    Sequence,
}

/// The channels of a recording, in MCAP channel order.
pub const RECORDING_CHANNELS: [Topic; 5] = [
    Topic::Sim(Channel::Control),
    Topic::Sim(Channel::Stepper),
    Topic::Sim(Channel::Sensors),
    Topic::Pulses,
    Topic::Sequence,
];

/// JSON schemas of the rig-only channels (the simulator's come from their
/// field lists).
const PULSES_SCHEMA: &str = r#"{"title":"ivt.pulses","type":"object","properties":{"t":{"type":"array","items":{"type":"number"}},"ticks":{"type":"array","items":{"type":"integer"}}}}"#;
const SEQUENCE_SCHEMA: &str = r#"{"title":"ivt.sequence","type":"object","properties":{"t":{"type":"number"},"name":{"type":"string"},"stage":{"type":"integer"},"theta_ct_deg":{"type":["number","null"]},"hold":{"type":"boolean"}}}"#;

impl Topic {
    /// The topic's name (`/NAME`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Sim(c) => c.name(),
            Self::Pulses => "pulses",
            Self::Sequence => "sequence",
        }
    }
}

/// Position of the simulator channel named `name` in [`RECORDING_CHANNELS`].
fn sim_index(name: &str) -> Option<usize> {
    RECORDING_CHANNELS
        .iter()
        .position(|t| matches!(t, Topic::Sim(c) if c.name() == name))
}

/// What the metadata record `ivt` says.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordingMeta {
    /// Telemetry frame version of the source (2 for the simulator and v2
    /// firmware; a recorder sets what it read, [`Recording::set_frame_version`]).
    pub frame_version: u8,
    /// Encoder samples per revolution.
    pub ppr: u32,
    /// Timer rate of the `ticks` \[Hz\].
    pub f_timer_hz: f64,
    /// The simulated plant (None for a rig).
    pub plant: Option<serde_json::Value>,
    /// Stepper (micro)steps per revolution of θ_CT, when known (the
    /// simulator's; a rig's reader infers it from the held stages).
    pub steps_per_rev: Option<f64>,
    /// Free text: where the recording comes from.
    pub source: String,
}

/// An MCAP recording being written (under a temporary name until
/// [`Recording::finish`]).
pub struct Recording {
    out: PathBuf,
    staged: Staged,
    w: mcap::Writer<BufWriter<File>>,
    ids: [u16; 5],
    counts: [u64; 5],
    buf: Vec<u8>,
    meta: RecordingMeta,
}

impl Recording {
    /// Creates the recording `out` with its channels and metadata.
    ///
    /// # Errors
    /// File creation or MCAP writing.
    pub fn create(out: &Path, meta: &RecordingMeta) -> Result<Self, SimError> {
        let mcap_err = mcap_at(out);
        let mut staged = Staged::new();
        let (_, file) = staged.file(out).map_err(io_at(out))?;
        let mut w = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .profile("")
            .create(BufWriter::new(file))
            .map_err(&mcap_err)?;
        let mut channel_meta = BTreeMap::new();
        channel_meta.insert("source".to_string(), meta.source.clone());
        let mut ids = [0u16; 5];
        for (id, topic) in ids.iter_mut().zip(RECORDING_CHANNELS) {
            *id = match topic {
                Topic::Sim(c) => add_json_channel(&mut w, c, &channel_meta),
                Topic::Pulses => add_schema_channel(&mut w, "pulses", PULSES_SCHEMA, &channel_meta),
                Topic::Sequence => {
                    add_schema_channel(&mut w, "sequence", SEQUENCE_SCHEMA, &channel_meta)
                }
            }
            .map_err(&mcap_err)?;
        }
        Ok(Self {
            out: out.to_path_buf(),
            staged,
            w,
            ids,
            counts: [0; 5],
            buf: Vec::with_capacity(512),
            meta: meta.clone(),
        })
    }

    fn write(&mut self, channel: usize, t: f64) -> Result<(), SimError> {
        let (Some(&id), Some(count)) = (self.ids.get(channel), self.counts.get_mut(channel)) else {
            return Ok(());
        };
        let ns = (t.max(0.0) * 1e9).round() as u64;
        let header = mcap::records::MessageHeader {
            channel_id: id,
            sequence: *count as u32,
            log_time: ns,
            publish_time: ns,
        };
        *count += 1;
        self.w
            .write_to_known_channel(&header, &self.buf)
            .map_err(mcap_at(&self.out))
    }

    /// Writes a sample of one of the simulator's channels (`record::Record`):
    /// `/control`, `/stepper` or `/sensors`.
    ///
    /// # Errors
    /// MCAP writing.
    pub fn sample<R: Record>(&mut self, s: &R) -> Result<(), SimError> {
        let Some(channel) = sim_index(R::CHANNEL) else {
            return Ok(());
        };
        self.buf.clear();
        s.write_json(&mut self.buf);
        self.write(channel, s.time())
    }

    /// Writes a JSON message on `/control`, `/stepper` or `/sensors` (the rig's
    /// fields) at time `t`.
    ///
    /// # Errors
    /// MCAP writing.
    pub fn json(&mut self, channel: &str, t: f64, msg: &serde_json::Value) -> Result<(), SimError> {
        match sim_index(channel) {
            Some(k) => self.json_on(k, t, msg),
            None => Ok(()),
        }
    }

    /// A batch of encoder edges on `/pulses` (logged at the first edge's time).
    ///
    /// # Errors
    /// MCAP writing.
    pub fn pulses(&mut self, t: &[f64], ticks: &[u32]) -> Result<(), SimError> {
        let Some(&t0) = t.first() else {
            return Ok(());
        };
        let msg = serde_json::json!({ "t": t, "ticks": ticks });
        self.json_on(3, t0, &msg)
    }

    /// A stage start on `/sequence`.
    ///
    /// # Errors
    /// MCAP writing.
    pub fn stage(
        &mut self,
        t: f64,
        name: SequenceName,
        stage: u16,
        theta_ct_deg: f32,
        hold: bool,
    ) -> Result<(), SimError> {
        let theta = theta_ct_deg.is_finite().then_some(theta_ct_deg);
        let msg = serde_json::json!({
            "t": t, "name": name.as_str(), "stage": stage, "theta_ct_deg": theta, "hold": hold,
        });
        self.json_on(4, t, &msg)
    }

    fn json_on(&mut self, k: usize, t: f64, msg: &serde_json::Value) -> Result<(), SimError> {
        self.buf.clear();
        self.buf.extend_from_slice(msg.to_string().as_bytes());
        self.write(k, t)
    }

    /// The telemetry frame version the source turned out to send (the
    /// metadata is written at [`Recording::finish`]).
    pub fn set_frame_version(&mut self, v: u8) {
        self.meta.frame_version = v;
    }

    /// Writes the metadata and the summary, renames the file into place and returns the
    /// message count of each channel that got any (`/name` → count).
    ///
    /// # Errors
    /// MCAP writing or the rename.
    pub fn finish(mut self) -> Result<BTreeMap<String, u64>, SimError> {
        let meta = &self.meta;
        let mut m = BTreeMap::new();
        m.insert("frame_version".into(), meta.frame_version.to_string());
        m.insert("ppr".into(), meta.ppr.to_string());
        m.insert(
            "f_timer_hz".into(),
            serde_json::json!(meta.f_timer_hz).to_string(),
        );
        if let Some(p) = &meta.plant {
            m.insert("plant".into(), p.to_string());
        }
        if let Some(s) = meta.steps_per_rev {
            m.insert("steps_per_rev".into(), serde_json::json!(s).to_string());
        }
        self.w
            .write_metadata(&mcap::records::Metadata {
                name: "ivt".into(),
                metadata: m,
            })
            .map_err(mcap_at(&self.out))?;
        self.w.finish().map_err(mcap_at(&self.out))?;
        drop(self.w);
        self.staged.commit().map_err(io_at(&self.out))?;
        Ok(RECORDING_CHANNELS
            .iter()
            .zip(self.counts)
            .filter(|(_, n)| *n > 0)
            .map(|(c, n)| (format!("/{}", c.name()), n))
            .collect())
    }
}
