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
//! the panic lints of Cargo.toml's `[lints]` enforce outside tests.
#![warn(missing_docs)]

#[doc(hidden)]
pub mod cli;
#[doc(hidden)]
pub mod reproduce;

pub use ivt_condense as condense;
pub use ivt_ctrl as ctrl;
pub use ivt_design as design;
pub use ivt_hb as hb;
pub use ivt_jobs as jobs;
pub use ivt_kin as kin;
pub use ivt_num as num;
pub use ivt_path as path;
pub use ivt_plot as plot;
pub use ivt_sim as sim;
pub use ivt_sthb as sthb;
pub use ivt_wire as wire;

/// The guide's chapters (docs/guide/src) as doctests: every ```rust block of
/// the book compiles and runs under `cargo test --doc` (tests/guide.rs checks
/// that each chapter is listed here).
#[cfg(doctest)]
mod guide {
    #[doc = include_str!("../docs/guide/src/accuracy-speed.md")]
    mod accuracy_speed {}
    #[doc = include_str!("../docs/guide/src/api.md")]
    mod api {}
    #[doc = include_str!("../docs/guide/src/architecture.md")]
    mod architecture {}
    #[doc = include_str!("../docs/guide/src/contributing.md")]
    mod contributing {}
    #[doc = include_str!("../docs/guide/src/getting-started.md")]
    mod getting_started {}
    #[doc = include_str!("../docs/guide/src/limits.md")]
    mod limits {}
    #[doc = include_str!("../docs/guide/src/kinematics.md")]
    mod kinematics {}
    #[doc = include_str!("../docs/guide/src/reproducing.md")]
    mod reproducing {}
    #[doc = include_str!("../docs/guide/src/thesis-findings.md")]
    mod thesis_findings {}
    mod controller {
        #[doc = include_str!("../docs/guide/src/controller/gains.md")]
        mod gains {}
        #[doc = include_str!("../docs/guide/src/controller/inside.md")]
        mod inside {}
        #[doc = include_str!("../docs/guide/src/controller/open-loop.md")]
        mod open_loop {}
        #[doc = include_str!("../docs/guide/src/controller/reading-a-run.md")]
        mod reading_a_run {}
        #[doc = include_str!("../docs/guide/src/controller/scenes.md")]
        mod scenes {}
        #[doc = include_str!("../docs/guide/src/controller/simulator.md")]
        mod simulator {}
    }
    mod model {
        #[doc = include_str!("../docs/guide/src/model/all-solutions.md")]
        mod all_solutions {}
        #[doc = include_str!("../docs/guide/src/model/backbones.md")]
        mod backbones {}
        #[doc = include_str!("../docs/guide/src/model/elements.md")]
        mod elements {}
        #[doc = include_str!("../docs/guide/src/model/fe-models.md")]
        mod fe_models {}
        #[doc = include_str!("../docs/guide/src/model/frc.md")]
        mod frc {}
        #[doc = include_str!("../docs/guide/src/model/large-models.md")]
        mod large_models {}
        #[doc = include_str!("../docs/guide/src/model/limit-cycles.md")]
        mod limit_cycles {}
        #[doc = include_str!("../docs/guide/src/model/orbit.md")]
        mod orbit {}
        #[doc = include_str!("../docs/guide/src/model/string.md")]
        mod string {}
        #[doc = include_str!("../docs/guide/src/model/tori-diagrams.md")]
        mod tori_diagrams {}
        #[doc = include_str!("../docs/guide/src/model/two-parameter.md")]
        mod two_parameter {}
    }
    mod rig {
        #[doc = include_str!("../docs/guide/src/rig/commissioning.md")]
        mod commissioning {}
        #[doc = include_str!("../docs/guide/src/rig/firmware.md")]
        mod firmware {}
        #[doc = include_str!("../docs/guide/src/rig/identification.md")]
        mod identification {}
        #[doc = include_str!("../docs/guide/src/rig/recording.md")]
        mod recording {}
    }
}
