#![doc = include_str!("../README.md")]
// No scene, stream or file may reach a panic in the simulator: every failure
// is a typed `SimError`/`SceneError` (issue 30; the panic lints of
// Cargo.toml). Tests may unwrap.

pub mod atomic;
pub mod backend;
pub mod commission;
pub mod error;
pub mod field;
pub mod input;
pub mod integrate;
pub mod output;
pub mod pil;
pub mod plant;
pub mod plot;
pub mod profile;
pub mod progress;
pub mod pulse_log;
pub mod record;
pub mod recording;
pub mod run;
pub mod scene;
pub mod sensors;
pub mod steady;
pub mod telemetry;
#[doc(hidden)]
pub mod testing;
pub mod work_precision;

pub use error::SimError;
