//! Rig telemetry → MCAP (`ivt rig record`, `ivt rig commission --port`):
//! decodes the firmware's telemetry frames (`ivt_wire::telemetry`: v2
//! samples with V_m and T_U, pulse-log batches, stage starts; v1 samples of
//! older firmware too) from any byte source and writes a commissioning
//! recording ([`crate::recording`]), so a rig run and a simulated run open
//! side by side in Foxglove and `ivt rig identify` reads both:
//!
//! - `/control`: `t`, `ticks`, `omega`, `omega_a`, `r`, `fault`;
//! - `/stepper`: `t`, `position`;
//! - `/sensors`: `t`, `v_m`, `t_u` (v2 frames only);
//! - `/pulses`, `/sequence`: from pulse-log and stage frames.
//!
//! Time `t` is the frame's timer timestamp unwrapped across u32 wrap-arounds
//! (signed differences, so a pulse batch older than the last sample is
//! placed right) and divided by the timer rate, relative to the first frame.

use std::collections::BTreeMap;
use std::io::{ErrorKind, Read};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use ivt_wire::frame::Decoder;
use ivt_wire::telemetry::{StreamError, StreamProblem, TelemetryFrame, TelemetrySample};

use crate::error::SimError;
use crate::recording::{Recording, RecordingMeta};

/// Encoder samples per revolution the rig firmware is built for
/// (`firmware/src/app.rs`, `PPR`), written into recordings of its telemetry.
pub const FIRMWARE_PPR: u32 = 1200;

/// When to stop, how to read time, and how to treat bad frames.
#[derive(Clone, Debug)]
pub struct RecordOptions {
    /// Rate of the firmware's timestamp timer \[Hz\] (rig: 10 MHz).
    pub f_timer_hz: f64,
    /// Stop after this many sample frames (None: until the source ends or idles).
    pub max_frames: Option<u64>,
    /// Stop when no byte arrived for this long.
    pub idle_timeout: Duration,
    /// Encoder samples per revolution of the firmware (metadata).
    pub ppr: u32,
    /// Stop at the first truncated or corrupt frame with an error naming its
    /// byte offset (a stored capture); false counts and skips them (a live port).
    pub strict: bool,
}

/// What a recording produced.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordSummary {
    /// Telemetry sample frames written.
    pub frames: u64,
    /// Frames dropped for a bad CRC, length, kind or version, garbage runs
    /// and a truncated last frame.
    pub bad_frames: u64,
    /// Byte offset of the first bad frame, if any.
    pub first_bad_offset: Option<usize>,
    /// Time span covered by the frames \[s\].
    pub duration_s: f64,
    /// Highest telemetry frame version seen (1 or 2; 0 if none).
    pub frame_version: u8,
    /// Messages per MCAP channel.
    pub channels: BTreeMap<String, u64>,
    /// The MCAP file.
    pub out: PathBuf,
}

/// Reads telemetry frames from `src` until `opts` says stop (frame count,
/// end of stream, an I/O error of a closed pty, idling, or SIGINT/SIGTERM
/// through [`crate::atomic::on_interrupt`]) and writes them to
/// `out` as MCAP.
///
/// # Errors
/// Output creation/writing, a read error other than a time-out or a
/// closed peer, and under `strict` the first bad frame
/// ([`SimError::TelemetryStream`], with its byte offset).
pub fn record<R: Read>(
    mut src: R,
    out: &Path,
    opts: &RecordOptions,
) -> Result<RecordSummary, SimError> {
    if !(opts.f_timer_hz.is_finite() && opts.f_timer_hz > 0.0) {
        return Err(SimError::BadTimer(opts.f_timer_hz));
    }
    // Written under a temporary name and renamed once the footer is on; a
    // SIGINT/SIGTERM stops the reading like the end of the stream does.
    let _listener = crate::atomic::listen();
    let mut rec = Recording::create(
        out,
        &RecordingMeta {
            frame_version: ivt_wire::telemetry::TELEMETRY_VERSION,
            ppr: opts.ppr,
            f_timer_hz: opts.f_timer_hz,
            plant: None,
            steps_per_rev: None,
            source: "rig telemetry".into(),
        },
    )?;
    let mut sink = Sink {
        rec: &mut rec,
        clock: Unwrap::default(),
        f_timer_hz: opts.f_timer_hz,
        frames: 0,
        bad: 0,
        first_bad: None,
        t_last: 0.0,
        version: 0,
        strict: opts.strict,
    };
    let mut dec = Decoder::new();
    // A pty holds ~4 KiB: drain all of it per read, so a recorder that gets
    // little CPU (a loaded machine) still empties it before it overflows.
    let mut buf = [0u8; 4096];
    let mut last_byte = Instant::now();
    'read: loop {
        if crate::atomic::interrupted() || opts.max_frames.is_some_and(|m| sink.frames >= m) {
            break;
        }
        let n = match src.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {
                if last_byte.elapsed() >= opts.idle_timeout {
                    break;
                }
                continue;
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            // The other side went away: a pty reads as EIO, which the
            // serialport crate reports as a broken pipe.
            Err(e)
                if e.raw_os_error() == Some(5)
                    || matches!(e.kind(), ErrorKind::BrokenPipe | ErrorKind::UnexpectedEof) =>
            {
                break
            }
            Err(e) => return Err(SimError::TelemetryRead(e)),
        };
        last_byte = Instant::now();
        for &b in buf.get(..n).unwrap_or_default() {
            if dec.skips(b) {
                // Bytes between frames: an error in a stored capture; on a
                // live port the line noise before the first frame is normal.
                if opts.strict {
                    sink.bad(dec.position(), StreamProblem::Garbage)?;
                }
                dec.push(b);
                continue;
            }
            let offset = dec.frame_start();
            let Some(frame) = dec.push(b) else { continue };
            match frame.and_then(|f| TelemetryFrame::decode(f.kind, f.payload)) {
                Ok(f) => sink.frame(f)?,
                Err(e) => sink.bad(offset, StreamProblem::Frame(e))?,
            }
            if opts.max_frames.is_some_and(|m| sink.frames >= m) {
                break 'read;
            }
        }
    }
    if dec.in_frame() && opts.max_frames.is_none_or(|m| sink.frames < m) {
        sink.bad(dec.frame_start(), StreamProblem::Truncated)?;
    }
    let (frames, bad, first_bad, t_last, version) = (
        sink.frames,
        sink.bad,
        sink.first_bad,
        sink.t_last,
        sink.version,
    );
    rec.set_frame_version(version);
    let channels = rec.finish()?;
    Ok(RecordSummary {
        frames,
        bad_frames: bad,
        first_bad_offset: first_bad,
        duration_s: t_last,
        frame_version: version,
        channels,
        out: out.to_path_buf(),
    })
}

/// Where decoded frames go.
struct Sink<'a> {
    rec: &'a mut Recording,
    clock: Unwrap,
    f_timer_hz: f64,
    frames: u64,
    bad: u64,
    first_bad: Option<usize>,
    t_last: f64,
    version: u8,
    strict: bool,
}

impl Sink<'_> {
    fn t(&mut self, ticks: u32) -> f64 {
        self.clock.ticks(ticks) as f64 / self.f_timer_hz
    }

    fn bad(&mut self, offset: usize, problem: StreamProblem) -> Result<(), SimError> {
        if self.strict {
            return Err(SimError::TelemetryStream(StreamError { offset, problem }));
        }
        self.bad += 1;
        self.first_bad.get_or_insert(offset);
        Ok(())
    }

    fn frame(&mut self, f: TelemetryFrame) -> Result<(), SimError> {
        if !matches!(f, TelemetryFrame::Sample(_)) {
            self.version = self.version.max(ivt_wire::telemetry::TELEMETRY_VERSION);
        }
        match f {
            TelemetryFrame::Sample(s) => self.sample(&s),
            TelemetryFrame::Pulses(b) => {
                let ticks = b.edges();
                let t: Vec<f64> = ticks.iter().map(|&k| self.t(k)).collect();
                self.rec.pulses(&t, ticks)
            }
            TelemetryFrame::Stage(s) => {
                let t = self.t(s.time_ticks);
                self.rec
                    .stage(t, s.sequence, s.index, s.theta_ct_deg, s.hold)
            }
        }
    }

    fn sample(&mut self, s: &TelemetrySample) -> Result<(), SimError> {
        let t = self.t(s.time_ticks);
        self.t_last = t;
        let v = if s.inputs.is_some() { 2 } else { 1 };
        self.version = self.version.max(v);
        let ctl = serde_json::json!({
            "t": t, "ticks": s.time_ticks, "omega": finite(s.omega),
            "omega_a": finite(s.omega_a), "r": finite(s.r), "fault": s.fault,
        });
        self.rec.json("control", t, &ctl)?;
        let stp = serde_json::json!({ "t": t, "position": s.stepper_position });
        self.rec.json("stepper", t, &stp)?;
        if let Some([v_m, t_u]) = s.inputs {
            let sen = serde_json::json!({ "t": t, "v_m": finite(v_m), "t_u": finite(t_u) });
            self.rec.json("sensors", t, &sen)?;
        }
        self.frames += 1;
        Ok(())
    }
}

/// NaN/∞ as JSON `null`, like the simulator's logs.
fn finite(x: f32) -> Option<f32> {
    x.is_finite().then_some(x)
}

/// Unwraps u32 timer ticks into a count from the first frame, by signed
/// differences (steps of less than 2³¹ ticks either way).
#[derive(Default)]
struct Unwrap {
    last: Option<u32>,
    total: i64,
}

impl Unwrap {
    fn ticks(&mut self, now: u32) -> i64 {
        if let Some(last) = self.last {
            self.total += i64::from(now.wrapping_sub(last) as i32);
        }
        self.last = Some(now);
        self.total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(t: &TelemetrySample) -> Vec<u8> {
        let mut b = [0u8; 64];
        let n = TelemetryFrame::Sample(*t).encode(&mut b).unwrap();
        b[..n].to_vec()
    }

    #[test]
    fn records_frames_skips_garbage_and_unwraps_time() {
        let mut bytes = vec![0x00, 0x13];
        let mut sent = 0;
        for k in 0..50u32 {
            let s = TelemetrySample {
                time_ticks: 0xFFFF_FF00u32.wrapping_add(k * 100), // wraps at k = 3
                omega: 10.0,
                omega_a: if k < 5 { f32::NAN } else { 10.5 },
                r: 0.001 * k as f32,
                inputs: Some([8.0, 6.0]),
                stepper_position: k as i32,
                fault: 0,
            };
            let mut f = frame(&s);
            if k == 7 {
                f[5] ^= 0xFF; // corrupt one frame
            } else {
                sent += 1;
            }
            bytes.extend(f);
        }
        let dir = std::env::temp_dir().join(format!("ivt-telemetry-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("t.mcap");
        let opts = RecordOptions {
            f_timer_hz: 1.0e6,
            max_frames: None,
            idle_timeout: Duration::from_millis(100),
            ppr: 1200,
            strict: false,
        };
        let s = record(&bytes[..], &out, &opts).unwrap();
        assert_eq!((s.frames, s.bad_frames), (sent, 1));
        // 49 intervals of 100 ticks at 1 MHz across the wrap.
        assert!(
            (s.duration_s - 49.0 * 100.0 / 1.0e6).abs() < 1e-12,
            "{}",
            s.duration_s
        );
        // Read back: both channels, one message per good frame.
        let data = std::fs::read(&out).unwrap();
        let mut count: BTreeMap<String, u64> = BTreeMap::new();
        for m in mcap::MessageStream::new(&data).unwrap() {
            let m = m.unwrap();
            *count.entry(m.channel.topic.clone()).or_default() += 1;
        }
        assert_eq!(count, s.channels);
        assert_eq!(count["/control"], sent);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn max_frames_stops_early() {
        let mut bytes = vec![];
        for k in 0..10 {
            bytes.extend(frame(&TelemetrySample {
                time_ticks: k,
                omega: 1.0,
                omega_a: 1.0,
                r: 0.0,
                inputs: None,
                stepper_position: 0,
                fault: 0,
            }));
        }
        let out =
            std::env::temp_dir().join(format!("ivt-telemetry-max-{}.mcap", std::process::id()));
        let opts = RecordOptions {
            f_timer_hz: 1.0,
            max_frames: Some(4),
            idle_timeout: Duration::from_millis(100),
            ppr: 1200,
            strict: false,
        };
        assert_eq!(record(&bytes[..], &out, &opts).unwrap().frames, 4);
        let _ = std::fs::remove_file(&out);
    }

    fn opts(strict: bool) -> RecordOptions {
        RecordOptions {
            f_timer_hz: 1.0e6,
            max_frames: None,
            idle_timeout: Duration::from_millis(100),
            ppr: 1200,
            strict,
        }
    }

    /// The committed v1 capture of ivt-wire (20 frames, written by an
    /// independent Python encoder) records into /control and /stepper; cut
    /// inside its 4th frame, a strict read names byte offset 78 and writes
    /// no file, a lenient one keeps the 3 whole frames and counts the rest.
    #[test]
    fn v1_capture_records_and_a_truncated_one_names_the_offset() {
        let v1: &[u8] = include_bytes!("../../ivt-wire/tests/data/telemetry_v1.bin");
        let dir = std::env::temp_dir().join(format!("ivt-telemetry-v1-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("v1.mcap");
        let s = record(v1, &out, &opts(true)).unwrap();
        assert_eq!((s.frames, s.bad_frames, s.frame_version), (20, 0, 1));
        assert_eq!(s.channels["/control"], 20);
        assert!(
            !s.channels.contains_key("/sensors"),
            "v1 frames carry no inputs"
        );

        let cut = dir.join("cut.mcap");
        let err = record(&v1[..3 * 26 + 10], &cut, &opts(true)).unwrap_err();
        assert!(err.to_string().contains("byte offset 78"), "{err}");
        assert!(!cut.exists(), "no recording from a bad capture");
        let s = record(&v1[..3 * 26 + 10], &cut, &opts(false)).unwrap();
        assert_eq!(
            (s.frames, s.bad_frames, s.first_bad_offset),
            (3, 1, Some(78))
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Pulse-log and stage frames become /pulses and /sequence messages, in
    /// seconds from the first frame.
    #[test]
    fn pulse_log_and_stage_frames_are_recorded() {
        use ivt_ctrl::commission::SequenceName;
        use ivt_wire::{PulseBatch, StageStart};
        let mut bytes = frame(&TelemetrySample {
            time_ticks: 1_000,
            omega: 1.0,
            omega_a: 1.0,
            r: 0.0,
            inputs: Some([8.0, 6.0]),
            stepper_position: 0,
            fault: 0,
        });
        let mut b = [0u8; 300];
        let n = TelemetryFrame::Stage(StageStart {
            time_ticks: 1_500,
            sequence: SequenceName::Hold,
            index: 0,
            theta_ct_deg: 1000.0,
            hold: true,
            pulse_log: true,
        })
        .encode(&mut b)
        .unwrap();
        bytes.extend_from_slice(&b[..n]);
        let mut batch = PulseBatch::new(0);
        for k in 0..5 {
            batch.push(900 + 100 * k); // the first edge is older than the sample
        }
        let n = TelemetryFrame::Pulses(batch).encode(&mut b).unwrap();
        bytes.extend_from_slice(&b[..n]);
        let out =
            std::env::temp_dir().join(format!("ivt-telemetry-log-{}.mcap", std::process::id()));
        let s = record(&bytes[..], &out, &opts(true)).unwrap();
        assert_eq!(s.channels["/pulses"], 1);
        assert_eq!(s.channels["/sequence"], 1);
        let data = std::fs::read(&out).unwrap();
        for m in mcap::MessageStream::new(&data).unwrap() {
            let m = m.unwrap();
            let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
            match m.channel.topic.as_str() {
                "/pulses" => {
                    assert_eq!(v["t"][0].as_f64().unwrap(), -100e-6);
                    assert_eq!(v["t"][4].as_f64().unwrap(), 300e-6);
                    assert_eq!(v["ticks"][4], 1300);
                }
                "/sequence" => {
                    assert_eq!(v["name"], "hold");
                    assert_eq!(v["t"].as_f64().unwrap(), 500e-6);
                    assert_eq!(v["hold"], true);
                }
                _ => {}
            }
        }
        let _ = std::fs::remove_file(&out);
    }
}
