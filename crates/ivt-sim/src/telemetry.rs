//! Rig telemetry → MCAP (`ivt rig record`): decodes the firmware's telemetry
//! frames (`ivt_wire::Telemetry`, see firmware/README.md) from any byte
//! source and writes them into the simulator's channels, so a rig run and a
//! simulated run open side by side in Foxglove:
//!
//! - `/control` (schema `ivt.control`): `t`, `ticks`, `omega`, `omega_a`,
//!   `r`, `fault` (the fields the rig sends; the others of the simulator's
//!   control samples are absent);
//! - `/stepper` (schema `ivt.stepper`): `t`, `position`.
//!
//! Time `t` is the frame's timer timestamp unwrapped across u32 wrap-arounds
//! and divided by the timer rate, relative to the first frame.

use std::collections::BTreeMap;
use std::io::{BufWriter, ErrorKind, Read};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use ivt_wire::frame::Decoder;
use ivt_wire::msg::Telemetry;

use crate::error::{io_at, mcap_at, SimError};
use crate::output::add_json_channel;
use crate::record::Channel;

/// When to stop and how to read time.
#[derive(Clone, Debug)]
pub struct RecordOptions {
    /// Rate of the firmware's timestamp timer \[Hz\] (rig: 10 MHz).
    pub f_timer_hz: f64,
    /// Stop after this many frames (None: until the source ends or idles).
    pub max_frames: Option<u64>,
    /// Stop when no byte arrived for this long.
    pub idle_timeout: Duration,
}

/// What a recording produced.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordSummary {
    /// Telemetry frames written.
    pub frames: u64,
    /// Frames dropped for a bad CRC, length or kind.
    pub bad_frames: u64,
    /// Time span covered by the frames \[s\].
    pub duration_s: f64,
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
/// Output creation/writing, or a read error other than a time-out or a
/// closed peer.
pub fn record<R: Read>(
    mut src: R,
    out: &Path,
    opts: &RecordOptions,
) -> Result<RecordSummary, SimError> {
    if !(opts.f_timer_hz.is_finite() && opts.f_timer_hz > 0.0) {
        return Err(SimError::BadTimer(opts.f_timer_hz));
    }
    let mcap_err = mcap_at(out);
    // Written under a temporary name and renamed once the footer is on; a
    // SIGINT/SIGTERM stops the reading like the end of the stream does.
    let _listener = crate::atomic::listen();
    let mut staged = crate::atomic::Staged::new();
    let (_, file) = staged.file(out).map_err(io_at(out))?;
    let mut w = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .profile("")
        .create(BufWriter::new(file))
        .map_err(&mcap_err)?;
    let mut meta = BTreeMap::new();
    meta.insert("source".to_string(), "rig telemetry".to_string());
    let control = add_json_channel(&mut w, Channel::Control, &meta).map_err(&mcap_err)?;
    let stepper = add_json_channel(&mut w, Channel::Stepper, &meta).map_err(&mcap_err)?;

    let mut dec = Decoder::new();
    let mut buf = [0u8; 512];
    let (mut frames, mut bad) = (0u64, 0u64);
    let mut clock = Unwrap::default();
    let mut last_byte = Instant::now();
    let mut t_last = 0.0;
    'read: loop {
        if crate::atomic::interrupted() {
            break;
        }
        if opts.max_frames.is_some_and(|m| frames >= m) {
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
        for &b in &buf[..n] {
            let Some(frame) = dec.push(b) else { continue };
            let Ok(sample) = frame.and_then(|f| Telemetry::decode(f.kind, f.payload)) else {
                bad += 1;
                continue;
            };
            let t = clock.ticks(sample.time_ticks) as f64 / opts.f_timer_hz;
            t_last = t;
            let ns = (t * 1e9).round() as u64;
            let ctl = serde_json::json!({
                "t": t, "ticks": sample.time_ticks, "omega": finite(sample.omega),
                "omega_a": finite(sample.omega_a), "r": finite(sample.r), "fault": sample.fault,
            });
            let stp = serde_json::json!({ "t": t, "position": sample.stepper_position });
            for (id, msg) in [(control, ctl), (stepper, stp)] {
                let header = mcap::records::MessageHeader {
                    channel_id: id,
                    sequence: frames as u32,
                    log_time: ns,
                    publish_time: ns,
                };
                w.write_to_known_channel(&header, msg.to_string().as_bytes())
                    .map_err(&mcap_err)?;
            }
            frames += 1;
            if opts.max_frames.is_some_and(|m| frames >= m) {
                break 'read;
            }
        }
    }
    w.finish().map_err(&mcap_err)?;
    drop(w);
    staged.commit().map_err(io_at(out))?;
    Ok(RecordSummary {
        frames,
        bad_frames: bad,
        duration_s: t_last,
        channels: [
            ("/control".to_string(), frames),
            ("/stepper".to_string(), frames),
        ]
        .into(),
        out: out.to_path_buf(),
    })
}

/// NaN/∞ as JSON `null`, like the simulator's logs.
fn finite(x: f32) -> Option<f32> {
    x.is_finite().then_some(x)
}

/// Unwraps u32 timer ticks into a monotonic count from the first frame.
#[derive(Default)]
struct Unwrap {
    last: Option<u32>,
    total: u64,
}

impl Unwrap {
    fn ticks(&mut self, now: u32) -> u64 {
        if let Some(last) = self.last {
            self.total += u64::from(now.wrapping_sub(last));
        }
        self.last = Some(now);
        self.total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(t: &Telemetry) -> Vec<u8> {
        let mut b = [0u8; 64];
        let n = t.encode(&mut b).unwrap();
        b[..n].to_vec()
    }

    #[test]
    fn records_frames_skips_garbage_and_unwraps_time() {
        let mut bytes = vec![0x00, 0x13];
        let mut sent = 0;
        for k in 0..50u32 {
            let s = Telemetry {
                time_ticks: 0xFFFF_FF00u32.wrapping_add(k * 100), // wraps at k = 3
                omega: 10.0,
                omega_a: if k < 5 { f32::NAN } else { 10.5 },
                r: 0.001 * k as f32,
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
            bytes.extend(frame(&Telemetry {
                time_ticks: k,
                omega: 1.0,
                omega_a: 1.0,
                r: 0.0,
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
        };
        assert_eq!(record(&bytes[..], &out, &opts).unwrap().frames, 4);
        let _ = std::fs::remove_file(&out);
    }
}
