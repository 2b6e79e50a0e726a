//! Telemetry streams as the recorder reads them: the committed v1 bytes
//! (`tests/data/telemetry_v1.bin`, written by `tests/data/make_v1.py`
//! independently of this crate) still decode, mixed v1/v2 streams decode,
//! and truncated or corrupted streams give errors at the right byte offset.
// Test code: the crate's panic lints guard shipped code only.
#![allow(clippy::indexing_slicing, clippy::unwrap_used, clippy::panic)]

mod common;

use ivt_wire::telemetry::{StreamProblem, TelemetryReader};
use ivt_wire::{TelemetryFrame, TelemetrySample, WireError, MAX_FRAME};

const V1: &[u8] = include_bytes!("data/telemetry_v1.bin");
const V1_FRAME: usize = 21 + 5;

fn samples(bytes: &[u8]) -> Vec<(usize, TelemetrySample)> {
    TelemetryReader::new(bytes)
        .map(|r| match r.unwrap() {
            (at, TelemetryFrame::Sample(s)) => (at, s),
            other => panic!("not a sample: {other:?}"),
        })
        .collect()
}

#[test]
fn committed_v1_bytes_decode_to_the_values_that_wrote_them() {
    let got = samples(V1);
    assert_eq!(got.len(), 20);
    for (k, (at, s)) in got.iter().enumerate() {
        let kf = k as f32;
        assert_eq!(*at, k * V1_FRAME);
        assert_eq!(s.time_ticks, 0xFFFF_F000u32.wrapping_add(1000 * k as u32));
        assert_eq!(s.omega, 10.0 + kf / 4.0);
        assert_eq!(s.omega_a, 10.5);
        assert_eq!(s.r, kf / 1024.0);
        assert_eq!(s.stepper_position, 3 * k as i32 - 7);
        assert_eq!(s.fault, if k % 5 == 4 { 3 } else { 0 });
        assert_eq!(s.inputs, None, "v1 frames carry no inputs");
    }
}

#[test]
fn v1_and_v2_frames_mix_in_one_stream() {
    let mut bytes = V1[..2 * V1_FRAME].to_vec();
    let v2 = common::v2_sample();
    let mut buf = [0u8; MAX_FRAME];
    let n = TelemetryFrame::Sample(v2).encode(&mut buf).unwrap();
    bytes.extend_from_slice(&buf[..n]);
    let got = samples(&bytes);
    assert_eq!(got.len(), 3);
    assert_eq!(got[2], (2 * V1_FRAME, v2));
}

#[test]
fn truncation_and_corruption_name_the_byte_offset() {
    // Cut inside the 4th frame.
    let cut = &V1[..3 * V1_FRAME + 10];
    let errs: Vec<_> = TelemetryReader::new(cut).filter_map(Result::err).collect();
    assert_eq!(errs.len(), 1);
    assert_eq!(errs[0].offset, 3 * V1_FRAME);
    assert_eq!(errs[0].problem, StreamProblem::Truncated);
    assert!(
        errs[0].to_string().contains("byte offset 78"),
        "{}",
        errs[0]
    );

    // A flipped payload bit in frame 7 → CRC error at its start; a run of
    // garbage before frame 12 → one garbage error at its first byte.
    let mut bad = V1.to_vec();
    bad[7 * V1_FRAME + 9] ^= 0x04;
    bad.splice(12 * V1_FRAME..12 * V1_FRAME, [0x00, 0x13, 0x37]);
    let all: Vec<_> = TelemetryReader::new(&bad).collect();
    let errs: Vec<_> = all.iter().filter_map(|r| r.err()).collect();
    assert_eq!(errs.len(), 2, "{errs:?}");
    assert_eq!(errs[0].offset, 7 * V1_FRAME);
    assert_eq!(errs[0].problem, StreamProblem::Frame(WireError::BadCrc));
    assert_eq!(errs[1].offset, 12 * V1_FRAME);
    assert_eq!(errs[1].problem, StreamProblem::Garbage);
    // Every other frame decodes, the ones after the garbage at shifted offsets.
    let ok: Vec<usize> = all
        .iter()
        .filter_map(|r| r.ok().map(|(at, _)| at))
        .collect();
    assert_eq!(ok.len(), 19);
    assert_eq!(*ok.last().unwrap(), 19 * V1_FRAME + 3);
}
