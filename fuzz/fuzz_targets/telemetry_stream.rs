//! The firmware's byte stream as the host reads it: every byte through the
//! frame decoder, every frame through the telemetry, request and reply
//! decoders (ivt-wire), as `ivt rig record` and the PIL link do.
#![no_main]

use ivt_wire::frame::Decoder;
use ivt_wire::msg::{Reply, Request};
use ivt_wire::telemetry::TelemetryFrame;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut dec = Decoder::new();
    for &b in data {
        let _ = dec.skips(b);
        let _ = dec.frame_start();
        if let Some(Ok(f)) = dec.push(b) {
            let _ = TelemetryFrame::decode(f.kind, f.payload);
            let _ = Request::decode(f.kind, f.payload);
            let _ = Reply::decode(f.kind, f.payload);
        }
    }
    let _ = dec.in_frame();
});
