//! Test support shared by this crate's tests, benches and examples and the
//! workspace's CLI tests: fresh scratch directories, sorted directory
//! listings (used to prove that an atomic write left nothing behind) and the
//! shipped scenes.
//!
//! Not part of the simulator's API; these helpers panic on I/O errors,
//! which is what a test wants. The crate's panic lints are lifted for this
//! module alone: it is test code that integration tests of two packages
//! share, and no library path calls it.
#![allow(clippy::expect_used)]

pub(crate) mod scratch;

use crate::scene::Scene;
pub use scratch::Scratch;
use std::path::Path;

/// A fresh, empty directory `ivt-{name}-{pid}` under the system temporary
/// directory (removed first if a previous run left it), deleted again when
/// the returned guard is dropped.
///
/// # Panics
/// If the directory cannot be created.
pub fn scratch_dir(name: &str) -> Scratch {
    Scratch::new(name)
}

/// The file names in `dir`, sorted.
///
/// # Panics
/// If `dir` cannot be read.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("read directory")
        .map(|e| {
            e.expect("read directory entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    v.sort();
    v
}

/// The scene `file` of the repository's `scenes/` directory, as shipped (so
/// that what is tested or timed is what ships).
///
/// # Panics
/// If the file cannot be read or does not parse.
pub fn shipped_scene(file: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(file);
    Scene::load(&path).expect("shipped scene parses")
}
