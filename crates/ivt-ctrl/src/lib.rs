#![doc = include_str!("../README.md")]
#![no_std]
#![warn(missing_docs)]

#[macro_use]
mod coded;

pub mod actuator;
pub mod averager;
pub mod commission;
pub mod config;
pub mod controller;
pub mod dispatch;
pub mod law;
pub mod open_loop;
pub mod units;

pub use actuator::{ActuatorMap, StepGenerator, StepperLimits};
pub use averager::{AngleAverager, SpeedError, TargetTicks, Targets};
pub use commission::{Plan, Selection, SequenceName, Sequencer, Stage};
pub use controller::{Config, ControlOutput, Controller, Fault, Gains, LawKind, StepTick};
pub use dispatch::{is_supported_ppr, AnyController, UnsupportedPpr, SUPPORTED_PPR};
pub use law::FeedbackLaw;
pub use open_loop::{OlRegion, OpenLoopCoeffs, OpenLoopPreset, REFIT, THESIS};
