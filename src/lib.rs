//! The IVT toolkit facade: one dependency that re-exports the crates of the
//! workspace, plus the `ivt` command line (`cli`).
//!
//! | crate | what |
//! |---|---|
//! | [`kin`] | kinematics and plant coefficients (no_std) |
//! | [`ctrl`] | the rig controller (no_std, f32, no heap) |
#![warn(missing_docs)]

pub use ivt_ctrl as ctrl;
pub use ivt_kin as kin;

pub mod cli;
pub mod reproduce;
