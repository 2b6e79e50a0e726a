//! IVT rig firmware: the `ivt-ctrl` controller behind a board layer.
#![no_std]

#[cfg(feature = "qemu")]
pub mod board {
    pub mod qemu;
}
