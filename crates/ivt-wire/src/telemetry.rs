//! Telemetry frames, firmware → host (UART1 of the QEMU image, USART1 of the
//! rig), and their decoding by the host recorder.
//!
//! | kind | name | payload |
//! |------|------|---------|
//! | 0x90 | v1 sample (read only) | `time_ticks: u32, omega, omega_a, r: f32, stepper_position: i32, fault: u8` (21 B) |
//! | 0x91 | v2 sample | `version: u8 = 2, time_ticks: u32, omega, omega_a, r, v_m, t_u: f32, stepper_position: i32, fault: u8` (30 B) |
//! | 0x92 | pulse log | `version: u8 = 2, first: u32, n: u8, ticks: [u32; n]` (n ≤ [`PULSES_PER_FRAME`]) |
//! | 0x93 | stage start | `version: u8 = 2, time_ticks: u32, sequence: u8, index: u16, theta_ct_deg: f32, flags: u8` (13 B) |
//!
//! Frames from v2 on carry a version byte first: a host meets a newer layout
//! with [`WireError::UnsupportedVersion`], never a misread. The v1 sample
//! (firmware before V_m and T_U were sent) is still decoded, as
//! [`TelemetrySample`] with no inputs. `first` of a pulse-log frame counts the
//! edges since the log started, so a lost frame shows as a gap.

use crate::fields::{expect_len, Put};
use crate::frame::{encode, WireError};
use ivt_ctrl::commission::{SequenceName, Stage};

/// Frame kind of a v1 telemetry sample (decoded, no longer sent).
pub const K_TELEMETRY_V1: u8 = 0x90;
/// Frame kind of a v2 telemetry sample.
pub const K_TELEMETRY: u8 = 0x91;
/// Frame kind of a pulse-log batch.
pub const K_PULSE_LOG: u8 = 0x92;
/// Frame kind of a stage start.
pub const K_STAGE: u8 = 0x93;
/// The layout version these frames carry.
pub const TELEMETRY_VERSION: u8 = 2;
/// Edge timestamps per pulse-log frame.
pub const PULSES_PER_FRAME: usize = 60;

const V1_LEN: usize = 21;
const SAMPLE_LEN: usize = 30;
const STAGE_LEN: usize = 13;
const PULSE_HEAD: usize = 6;

/// One telemetry sample streamed by the firmware.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TelemetrySample {
    /// Timer ticks of the sample.
    pub time_ticks: u32,
    /// ω \[rad/s\].
    pub omega: f32,
    /// ω_a \[rad/s\].
    pub omega_a: f32,
    /// Commanded eccentricity r \[m\].
    pub r: f32,
    /// The inputs the firmware read, V_m \[V\] and T_U \[N·m\] (None in a v1 frame).
    pub inputs: Option<[f32; 2]>,
    /// Stepper position \[steps\].
    pub stepper_position: i32,
    /// Fault code.
    pub fault: u8,
}

/// A batch of encoder edge timestamps (pulse-log mode).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PulseBatch {
    /// Number of the first edge since the log started.
    pub first: u32,
    /// How many of `ticks` are used.
    pub len: u8,
    /// Edge timestamps \[ticks\].
    pub ticks: [u32; PULSES_PER_FRAME],
}

impl PulseBatch {
    /// An empty batch starting at edge `first`.
    #[must_use]
    pub const fn new(first: u32) -> Self {
        Self {
            first,
            len: 0,
            ticks: [0; PULSES_PER_FRAME],
        }
    }

    /// Appends one edge; false if the batch is full.
    pub fn push(&mut self, ticks: u32) -> bool {
        match self.ticks.get_mut(usize::from(self.len)) {
            Some(slot) => {
                *slot = ticks;
                self.len += 1;
                true
            }
            None => false,
        }
    }

    /// The edges held.
    #[must_use]
    pub fn edges(&self) -> &[u32] {
        self.ticks.get(..usize::from(self.len)).unwrap_or(&[])
    }
}

/// A commissioning stage started (see `ivt_ctrl::commission`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StageStart {
    /// Timer ticks of the pulse that started it.
    pub time_ticks: u32,
    /// The sequence.
    pub sequence: SequenceName,
    /// Index of the stage inside its sequence.
    pub index: u16,
    /// Held stepper angle \[deg\] (NaN for a law stage).
    pub theta_ct_deg: f32,
    /// θ_CT held (the law does not act).
    pub hold: bool,
    /// Every edge is logged during the stage.
    pub pulse_log: bool,
}

impl StageStart {
    /// The start of `stage` at `time_ticks`.
    #[must_use]
    pub fn of(stage: &Stage, time_ticks: u32) -> Self {
        Self {
            time_ticks,
            sequence: stage.sequence,
            index: stage.index,
            theta_ct_deg: stage.theta_ct_deg,
            hold: stage.hold,
            pulse_log: stage.pulse_log,
        }
    }
}

/// Any telemetry frame.
// A pulse batch is 248 bytes; boxing it is not an option without a heap, and
// a frame lives only between decoding and handling.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TelemetryFrame {
    /// A sample (v1 or v2).
    Sample(TelemetrySample),
    /// A pulse-log batch.
    Pulses(PulseBatch),
    /// A stage start.
    Stage(StageStart),
}

impl TelemetryFrame {
    /// Encodes the frame (always in the current version) into `out`;
    /// returns the frame length.
    ///
    /// # Errors
    /// [`WireError::BufferTooSmall`].
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, WireError> {
        let mut p = Put::<{ PULSE_HEAD + 4 * PULSES_PER_FRAME }>::new();
        p.bytes(&[TELEMETRY_VERSION]);
        let kind = match self {
            Self::Sample(s) => {
                let [v_m, t_u] = s.inputs.unwrap_or([f32::NAN; 2]);
                p.u32(s.time_ticks);
                p.f32s(&[s.omega, s.omega_a, s.r, v_m, t_u]);
                p.bytes(&s.stepper_position.to_le_bytes());
                p.bytes(&[s.fault]);
                K_TELEMETRY
            }
            Self::Pulses(b) => {
                p.u32(b.first);
                p.bytes(&[b.len]);
                for &t in b.edges() {
                    p.u32(t);
                }
                K_PULSE_LOG
            }
            Self::Stage(s) => {
                p.u32(s.time_ticks);
                p.bytes(&[s.sequence.code()]);
                p.u16(s.index);
                p.f32(s.theta_ct_deg);
                p.flags(&[s.hold, s.pulse_log]);
                K_STAGE
            }
        };
        encode(kind, p.done(), out)
    }

    /// Decodes a telemetry frame's kind and payload (v1 samples included).
    ///
    /// # Errors
    /// [`WireError::UnknownKind`], [`WireError::BadLength`],
    /// [`WireError::UnsupportedVersion`] or [`WireError::BadValue`].
    pub fn decode(kind: u8, payload: &[u8]) -> Result<Self, WireError> {
        if kind == K_TELEMETRY_V1 {
            let mut g = expect_len(kind, payload, V1_LEN)?;
            return Ok(Self::Sample(TelemetrySample {
                time_ticks: g.u32(),
                omega: g.f32(),
                omega_a: g.f32(),
                r: g.f32(),
                inputs: None,
                stepper_position: g.i32(),
                fault: g.u8(),
            }));
        }
        if !matches!(kind, K_TELEMETRY | K_PULSE_LOG | K_STAGE) {
            return Err(WireError::UnknownKind(kind));
        }
        match payload.first() {
            Some(&TELEMETRY_VERSION) => {}
            Some(&version) => return Err(WireError::UnsupportedVersion { kind, version }),
            None => return Err(WireError::BadLength { kind, len: 0 }),
        }
        let body = payload.get(1..).unwrap_or(&[]);
        Ok(match kind {
            K_TELEMETRY => {
                let mut g = expect_len(kind, payload, SAMPLE_LEN)?;
                g.u8();
                let time_ticks = g.u32();
                let [omega, omega_a, r, v_m, t_u] = g.f32s();
                Self::Sample(TelemetrySample {
                    time_ticks,
                    omega,
                    omega_a,
                    r,
                    inputs: Some([v_m, t_u]),
                    stepper_position: g.i32(),
                    fault: g.u8(),
                })
            }
            K_STAGE => {
                let mut g = expect_len(kind, payload, STAGE_LEN)?;
                g.u8();
                let time_ticks = g.u32();
                let sequence = SequenceName::from_code(g.u8()).ok_or(WireError::BadValue)?;
                let index = g.u16();
                let theta_ct_deg = g.f32();
                let [hold, pulse_log] = g.flags();
                Self::Stage(StageStart {
                    time_ticks,
                    sequence,
                    index,
                    theta_ct_deg,
                    hold,
                    pulse_log,
                })
            }
            _ => {
                let n = usize::from(*body.get(4).unwrap_or(&0));
                if n > PULSES_PER_FRAME {
                    return Err(WireError::BadValue);
                }
                let mut g = expect_len(kind, payload, PULSE_HEAD + 4 * n)?;
                g.u8();
                let mut b = PulseBatch::new(g.u32());
                g.u8();
                for _ in 0..n {
                    b.push(g.u32());
                }
                Self::Pulses(b)
            }
        })
    }
}

/// What is wrong at a byte offset of a telemetry stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StreamProblem {
    /// A byte outside any frame (not a SYNC).
    Garbage,
    /// A frame that fails its CRC or does not decode.
    Frame(WireError),
    /// The stream ends inside a frame.
    Truncated,
}

/// A telemetry stream error: the problem and the byte offset where the
/// offending frame (or byte) starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StreamError {
    /// Byte offset from the start of the stream.
    pub offset: usize,
    /// What is wrong there.
    pub problem: StreamProblem,
}

impl core::fmt::Display for StreamError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let at = self.offset;
        match self.problem {
            StreamProblem::Garbage => write!(f, "byte offset {at}: byte outside any frame"),
            StreamProblem::Frame(e) => write!(f, "byte offset {at}: {e}"),
            StreamProblem::Truncated => write!(f, "byte offset {at}: stream ends inside a frame"),
        }
    }
}

/// Reads every telemetry frame of a byte stream with its byte offset; each
/// problem is an `Err` naming its offset (the reader goes on after it, so a
/// lenient caller may count and skip, a strict one stops at the first).
pub struct TelemetryReader<'a> {
    bytes: &'a [u8],
    at: usize,
    dec: crate::frame::Decoder,
}

impl<'a> TelemetryReader<'a> {
    /// A reader over `bytes`.
    #[must_use]
    pub fn new(bytes: &'a [u8]) -> Self {
        Self {
            bytes,
            at: 0,
            dec: crate::frame::Decoder::new(),
        }
    }
}

impl Iterator for TelemetryReader<'_> {
    type Item = Result<(usize, TelemetryFrame), StreamError>;

    fn next(&mut self) -> Option<Self::Item> {
        while let Some(&b) = self.bytes.get(self.at) {
            let at = self.at;
            self.at += 1;
            if self.dec.skips(b) {
                // Swallow the rest of the garbage run: one error per run (the
                // decoder sees every byte, so its offsets stay the stream's).
                self.dec.push(b);
                while let Some(&g) = self.bytes.get(self.at).filter(|&&g| self.dec.skips(g)) {
                    self.dec.push(g);
                    self.at += 1;
                }
                return Some(Err(StreamError {
                    offset: at,
                    problem: StreamProblem::Garbage,
                }));
            }
            // A frame completes on its last CRC byte, long after its SYNC set
            // the start offset read here.
            let offset = self.dec.frame_start();
            if let Some(r) = self.dec.push(b) {
                return Some(
                    r.and_then(|f| TelemetryFrame::decode(f.kind, f.payload))
                        .map(|f| (offset, f))
                        .map_err(|e| StreamError {
                            offset,
                            problem: StreamProblem::Frame(e),
                        }),
                );
            }
        }
        if self.dec.in_frame() {
            let offset = self.dec.frame_start();
            self.dec = crate::frame::Decoder::new();
            return Some(Err(StreamError {
                offset,
                problem: StreamProblem::Truncated,
            }));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Decoder, MAX_FRAME};

    fn round_trip(f: TelemetryFrame) -> (usize, TelemetryFrame) {
        let mut buf = [0u8; MAX_FRAME];
        let n = f.encode(&mut buf).unwrap();
        let mut dec = Decoder::new();
        for &b in &buf[..n] {
            if let Some(r) = dec.push(b) {
                let raw = r.unwrap();
                return (n, TelemetryFrame::decode(raw.kind, raw.payload).unwrap());
            }
        }
        panic!("no frame");
    }

    #[test]
    fn v2_frames_round_trip_with_their_lengths() {
        let s = TelemetryFrame::Sample(TelemetrySample {
            time_ticks: 0xFFFF_FFFE,
            omega: 10.25,
            omega_a: 10.5,
            r: 0.004,
            inputs: Some([8.6, -0.0]),
            stepper_position: -12,
            fault: 3,
        });
        assert_eq!(round_trip(s), (SAMPLE_LEN + 5, s));
        let mut b = PulseBatch::new(7);
        for k in 0..PULSES_PER_FRAME as u32 {
            assert!(b.push(k * 1000));
        }
        assert!(!b.push(1), "a full batch refuses more");
        let pulses = TelemetryFrame::Pulses(b);
        assert_eq!(round_trip(pulses), (PULSE_HEAD + 240 + 5, pulses));
        let empty = TelemetryFrame::Pulses(PulseBatch::new(3));
        assert_eq!(round_trip(empty), (PULSE_HEAD + 5, empty));
        let st = TelemetryFrame::Stage(StageStart {
            time_ticks: 99,
            sequence: SequenceName::Hold,
            index: 2,
            theta_ct_deg: 1113.5,
            hold: true,
            pulse_log: true,
        });
        assert_eq!(round_trip(st), (STAGE_LEN + 5, st));
    }

    #[test]
    fn other_versions_and_bad_payloads_are_refused() {
        let mut p = [0u8; SAMPLE_LEN];
        p[0] = 3;
        assert_eq!(
            TelemetryFrame::decode(K_TELEMETRY, &p),
            Err(WireError::UnsupportedVersion {
                kind: K_TELEMETRY,
                version: 3
            })
        );
        p[0] = TELEMETRY_VERSION;
        assert!(TelemetryFrame::decode(K_TELEMETRY, &p[..29]).is_err());
        assert!(TelemetryFrame::decode(K_TELEMETRY, &[]).is_err());
        // A pulse count over the batch size, and one the length contradicts.
        assert_eq!(
            TelemetryFrame::decode(K_PULSE_LOG, &[2, 0, 0, 0, 0, 61]),
            Err(WireError::BadValue)
        );
        assert!(TelemetryFrame::decode(K_PULSE_LOG, &[2, 0, 0, 0, 0, 2, 1, 2, 3, 4]).is_err());
        // An unknown sequence code.
        let mut st = [0u8; STAGE_LEN];
        st[0] = 2;
        st[5] = 9;
        assert_eq!(
            TelemetryFrame::decode(K_STAGE, &st),
            Err(WireError::BadValue)
        );
        assert_eq!(
            TelemetryFrame::decode(0x82, &[]),
            Err(WireError::UnknownKind(0x82))
        );
    }
}
