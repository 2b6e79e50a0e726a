//! A commissioning recording's bytes, read as `ivt rig identify` reads them
//! (`ivt::cli::commissioning::read_from`: mcap's framing, the records parsed
//! with every length checked, zstd chunks within their budgets, the JSON
//! messages into the arrays), then its nominal plant. Any input must end in
//! a recording or a `ReadError` — never a panic, an abort, a hang or memory
//! beyond the reader's budgets. Seeds (fuzz/corpus/recording_mcap): small
//! recordings forged record by record as `tests/common/mcap_forge.rs` does
//! (top-level messages, a zstd chunk, an uncompressed chunk, a preset in the
//! metadata, a truncated file).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut src = data;
    if let Ok(c) = ivt::cli::commissioning::read_from(&mut src, data.len() as u64, "fuzz.mcap") {
        let _ = ivt::cli::commissioning::nominal_params(&c);
    }
});
