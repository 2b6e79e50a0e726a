//! Kinematics and plant coefficients of the geared infinitely variable
//! transmissions of Wang (2017), Chapter 2 and §4.1.
//!
//! `#![no_std]` with `libm`: the same formulas run on the host (f64) and can be
//! linked into bare-metal tools. Angles are radians, lengths metres, unless a
//! function name says otherwise (`*_deg`, `*_inch`).
//!
//! Modules:
//! - [`givt`]: the crank-slider GIVT (§2.1, Eq. 1–19).
//! - [`sgivt`]: the scotch-yoke SGIVT (§2.2, Eq. 20–35) and the prototype's
//!   stepper ↔ crank map (Eq. 182–185).
//! - [`ncg`]: noncircular gears: ratios Eq. 13/38/42, pitch profiles
//!   Eq. 14–17/39–41, and the Fourier fit of Eq. 42.
//! - [`arcs`]: tangent-continuous circular-arc approximation of a pitch
//!   profile (§2.2.4).
//! - [`units`]: inch/degree/rpm helpers for the edges.
//! - [`variant`]: the modulation `f(θ)` of the noncircular gears (Eq. 43, 139)
//!   and the speeds of the SGIVT variant (Eq. 44–47).
//! - [`params`]: every user-settable number described once (key, unit,
//!   range, f32), with the CLI flags and Python arguments that set it.
//! - [`plant`]: Table 1 parameters and the coefficients of the dynamic
//!   equation Eq. 151.
#![doc = ""]
#![doc = include_str!("../README.md")]
#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]

pub mod arcs;
pub mod error;
pub mod givt;
pub mod ncg;
pub mod params;
pub mod plant;
mod quad;
pub mod sgivt;
pub mod units;
pub mod variant;

pub use error::KinError;

/// π/(2√2): the amplitude of the noncircular-gear ratio, Eq. 38 and Eq. 43.
pub const NCG_AMPLITUDE: f64 = core::f64::consts::PI / (2.0 * core::f64::consts::SQRT_2);
