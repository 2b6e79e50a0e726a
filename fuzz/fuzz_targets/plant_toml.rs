//! A plant file's text: its `[plant]` table (nothing else), every value in
//! its range, or a `SceneError`, never a panic. A table that parses must
//! round-trip: `to_toml` of it parses to the same table (what `ivt rig
//! identify --out` writes is what `--plant-file` reads). Seeds
//! (fuzz/corpus/plant_toml): the presets, overrides of every key, a file
//! written by `ivt rig identify`.
#![no_main]

use ivt_sim::scene::PlantSection;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(section) = PlantSection::parse_file(text, "fuzz.toml") {
        let params = section.params();
        assert!(params.is_ok(), "parse_file accepted an invalid plant");
        let again = PlantSection::parse_file(&section.to_toml(), "again.toml");
        assert_eq!(again.ok(), Some(section), "the plant file does not round-trip");
    }
});
