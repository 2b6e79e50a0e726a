//! Kinematics and plant coefficients of the geared infinitely variable
//! transmissions of Wang (2017), Chapter 2 and §4.1.
//!
//! `#![no_std]` with `libm`: the same formulas run on the host (f64) and can be
//! linked into bare-metal tools. Angles are radians, lengths metres, unless a
//! function name says otherwise (`*_deg`, `*_inch`).
//!
//! Modules:
//! - [`variant`]: the modulation `f(θ)` of the noncircular gears (Eq. 43, 139)
//!   and the speeds of the SGIVT variant (Eq. 44–47).
//! - [`plant`]: Table 1 parameters and the coefficients of the dynamic
//!   equation Eq. 151.
#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]

pub mod plant;
pub mod variant;

/// π/(2√2): the amplitude of the noncircular-gear ratio, Eq. 38 and Eq. 43.
pub const NCG_AMPLITUDE: f64 = core::f64::consts::PI / (2.0 * core::f64::consts::SQRT_2);
