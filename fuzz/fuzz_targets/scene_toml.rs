//! A scene's TOML text: parse and validate it, then estimate its work and
//! output size. Any input must end in `Ok` or a `SceneError`, never a panic.
#![no_main]

use ivt_sim::scene::Scene;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(scene) = Scene::parse(text, "fuzz.toml") {
        let _ = scene.estimated_events().total();
        let _ = scene.estimated_output_bytes();
        let _ = scene.ihb_route_blocker();
        let _ = scene.check_events(ivt_sim::scene::DEFAULT_MAX_EVENTS);
    }
});
