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
