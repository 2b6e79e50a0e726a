//! Copies the repository's `scenes/*.toml` into `python/ivt/_scenes/`, where
//! maturin picks them up as package data of the wheel (`ivt.scenes`). The
//! repository's `scenes/` stays the one source; the copy is not tracked.
//! (maturin does not follow a symlink there.)
//!
//! The crate denies `expect` for the bindings (no Python input may panic);
//! a build script reports failure by panicking, with the message cargo shows.
#![allow(clippy::expect_used)]

use std::fs;
use std::path::Path;

fn main() {
    let dir = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let crate_dir = Path::new(&dir);
    let src = crate_dir.join("../../scenes");
    let dst = crate_dir.join("python/ivt/_scenes");
    println!("cargo::rerun-if-changed={}", src.display());
    fs::create_dir_all(&dst).expect("create python/ivt/_scenes");
    let is_scene = |p: &Path| p.extension().is_some_and(|e| e == "toml");
    for entry in fs::read_dir(&dst).expect("read python/ivt/_scenes") {
        let p = entry.expect("list python/ivt/_scenes").path();
        if is_scene(&p) && !src.join(p.file_name().unwrap_or_default()).exists() {
            fs::remove_file(&p).expect("remove a stale scene copy");
        }
    }
    for entry in fs::read_dir(&src).expect("read scenes/") {
        let p = entry.expect("list scenes/").path();
        if is_scene(&p) {
            let to = dst.join(p.file_name().unwrap_or_default());
            fs::copy(&p, &to).expect("copy a scene into python/ivt/_scenes");
        }
    }
}
