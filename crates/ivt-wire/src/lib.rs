#![doc = include_str!("../README.md")]
#![no_std]

pub mod frame;
pub mod msg;

pub use frame::{crc16, Decoder, RawFrame, WireError, MAX_FRAME};
pub use msg::{ErrorCode, Output, Reply, Request, Telemetry};
