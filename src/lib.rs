//! The IVT toolkit facade: one dependency that re-exports the crates of the
//! workspace, plus the `ivt` command line (`cli`).
//!
//! | crate | what |
//! |---|---|
//! | [`kin`] | kinematics and plant coefficients (no_std) |
#![warn(missing_docs)]

pub use ivt_kin as kin;

pub mod cli;
