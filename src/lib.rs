//! The IVT toolkit facade: one dependency that re-exports every library crate
//! of the workspace under a short name.
//!
//! | module | crate | what |
//! |---|---|---|
//! | [`kin`] | `ivt-kin` | kinematics and plant coefficients (Ch. 2, §4.1; no_std) |
//! | [`ctrl`] | `ivt-ctrl` | the rig controller (§4.2–4.4; no_std, f32, no heap) |
//! | [`num`] | `ivt-num` | Runge–Kutta tableaux and stepper, damped Newton, faer LU workspace |
//! | [`hb`] | `ivt-hb` | periodic orbits: harmonic balance, continuation, Floquet/Hill, STHB (Ch. 3) |
//! | [`design`] | `ivt-design` | IVT steady state, open-loop law, delay-loop stability (§4.2–4.3) |
//! | [`sim`] | `ivt-sim` | plant integration, closed loop, scenes, MCAP logs |
//! | [`plot`] | `ivt-plot` | PNG figures with an embedded font |
//! | [`wire`] | `ivt-wire` | byte frames shared by the firmware and the host |
//!
//! The `ivt` command line and `ivt reproduce` are the binary of this package
//! (`src/main.rs`), not part of the library's API: their modules are here,
//! hidden, only so that the fuzz target of the argument vector (`fuzz/`)
//! can call them.
//!
//! No input may reach a panic in the command layer or the reproduction
//! report: every failure is a `CliError` (exit 2) or a `ReproError`, which
//! these lints enforce outside tests.
#![warn(missing_docs)]
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

#[doc(hidden)]
pub mod cli;
#[doc(hidden)]
pub mod reproduce;

pub use ivt_ctrl as ctrl;
pub use ivt_design as design;
pub use ivt_hb as hb;
pub use ivt_kin as kin;
pub use ivt_num as num;
pub use ivt_plot as plot;
pub use ivt_sim as sim;
pub use ivt_wire as wire;
