//! A pulse log for `ivt ctrl replay`: parsed rows or a `PulseLogError`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = ivt_sim::pulse_log::parse_pulse_log(text);
});
