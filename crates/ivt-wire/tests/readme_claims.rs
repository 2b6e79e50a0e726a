//! The frame table of the guide's firmware chapter (`docs/guide/src/rig/firmware.md`): `0xA5 kind len payload crc_lo
//! crc_hi`, each message's kind byte and payload length, and the CRC over
//! `kind len payload`, read back from encoded frames (the CRC's check value
//! 0x29B1 is asserted in `frame::tests`).
// Test code: the crate's panic lints guard shipped code only.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

mod common;

use ivt_ctrl::{Config, ControlOutput};
use ivt_ctrl::{Plan, Selection, SequenceName};
use ivt_wire::{
    crc16, ErrorCode, PulseBatch, Reply, Request, StageStart, TelemetryFrame, MAX_FRAME,
};

/// (kind, payload length) of an encoded frame, after checking the layout.
fn kind_and_len(encode: impl FnOnce(&mut [u8]) -> usize) -> (u8, usize) {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode(&mut buf);
    let frame = &buf[..n];
    assert_eq!(frame[0], 0xA5, "start byte");
    let len = usize::from(frame[2]);
    assert_eq!(n, len + 5, "start, kind, len, payload, two CRC bytes");
    let crc = crc16(&frame[1..3 + len]);
    assert_eq!(frame[3 + len..], crc.to_le_bytes(), "CRC low byte first");
    (frame[1], len)
}

#[test]
fn frame_table_kinds_and_payload_lengths() {
    let req = |r: Request| kind_and_len(|b| r.encode(b).unwrap());
    let rep = |r: Reply| kind_and_len(|b| r.encode(b).unwrap());
    assert_eq!(req(Request::Hello), (0x01, 0));
    assert_eq!(req(Request::Pulse { ticks: 7 }), (0x02, 4));
    assert_eq!(req(Request::Inputs { v_m: 8.0, t_u: 6.0 }), (0x03, 8));
    assert_eq!(req(Request::Exit), (0x04, 0));
    assert_eq!(req(Request::Configure(Config::default())), (0x05, 172));
    assert_eq!(
        rep(Reply::Hello {
            version: 2,
            ppr: 1200
        }),
        (0x81, 6)
    );
    assert_eq!(rep(Reply::Output(ControlOutput::IDLE)), (0x82, 31));
    assert_eq!(rep(Reply::Ack), (0x83, 0));
    assert_eq!(rep(Reply::Error(1)), (0x8F, 1));
    assert_eq!(
        req(Request::Commission {
            selection: Selection::ALL,
            plan: Plan::default()
        }),
        (0x06, 138)
    );
    assert_eq!(
        rep(Reply::Sequenced {
            out: ControlOutput::IDLE,
            stage: 0,
            started: true,
            pulse_log: false,
            done: false
        }),
        (0x84, 36)
    );
    let tel = |f: TelemetryFrame| kind_and_len(|b| f.encode(b).unwrap());
    let sample = common::v2_sample();
    assert_eq!(tel(TelemetryFrame::Sample(sample)), (0x91, 30));
    let mut batch = PulseBatch::new(0);
    for k in 0..60 {
        batch.push(k);
    }
    assert_eq!(tel(TelemetryFrame::Pulses(batch)), (0x92, 6 + 4 * 60));
    let stage = StageStart {
        time_ticks: 0,
        sequence: SequenceName::Sweep,
        index: 0,
        theta_ct_deg: 0.0,
        hold: true,
        pulse_log: false,
    };
    assert_eq!(tel(TelemetryFrame::Stage(stage)), (0x93, 13));
    // Every v2 telemetry frame starts its payload with the version byte 2.
    let mut buf = [0u8; MAX_FRAME];
    for f in [
        TelemetryFrame::Sample(sample),
        TelemetryFrame::Pulses(batch),
        TelemetryFrame::Stage(stage),
    ] {
        f.encode(&mut buf).unwrap();
        assert_eq!(buf[3], 2);
    }
}

/// The Error frame's codes: 1 CRC, 2 unknown kind, 3 length, 4 bad value.
#[test]
fn error_codes_are_the_table_values() {
    let codes = [
        ErrorCode::BadCrc,
        ErrorCode::UnknownKind,
        ErrorCode::BadLength,
        ErrorCode::BadValue,
    ];
    assert_eq!(codes.map(|c| c as u8), [1, 2, 3, 4]);
}
