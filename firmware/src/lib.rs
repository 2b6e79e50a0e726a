//! IVT rig firmware: the `ivt-ctrl` controller behind a board layer. See
//! docs/guide/src/rig/firmware.md (the guide) for boards, wiring, the PIL
//! protocol and the measured budgets.
#![no_std]

pub mod app;
pub mod stack;

#[cfg(all(feature = "qemu", feature = "rig"))]
compile_error!("enable exactly one board feature: qemu or rig");

/// The board layer selected by the cargo feature.
#[cfg(feature = "qemu")]
pub mod board {
    pub mod qemu;
}

/// The board layer selected by the cargo feature.
#[cfg(feature = "rig")]
pub mod board {
    pub mod rig;
}
