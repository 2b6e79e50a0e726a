//! The `ivt` argument vector: NUL-separated arguments parsed as the binary
//! parses them, the pure `kin` commands run ([`ivt::cli::fuzz_args`]).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::ffi::OsString;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let args: Vec<OsString> = std::iter::once("ivt")
        .chain(text.split('\0'))
        .map(OsString::from)
        .collect();
    let _ = ivt::cli::fuzz_args(&args);
});
