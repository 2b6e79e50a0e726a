// Issue #30 item 1: the panic lints the binary, ivt-py and ivt-ctrl deny,
// denied in this library's shipped code (every failure is a typed error).
// Unit tests (`cfg(test)`) and the tests/ and benches/ targets may unwrap.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing,
        clippy::unreachable,
        clippy::todo,
        clippy::unimplemented
    )
)]
#![doc = include_str!("../README.md")]
#![cfg_attr(not(feature = "host"), no_std)]

pub mod commission;
mod config;
mod fields;
pub mod frame;
pub mod msg;
pub mod telemetry;

#[cfg(feature = "host")]
pub mod host;

pub use frame::{crc16, Decoder, RawFrame, WireError, MAX_FRAME};
pub use msg::{ErrorCode, Reply, Request};
pub use telemetry::{PulseBatch, StageStart, TelemetryFrame, TelemetrySample};
