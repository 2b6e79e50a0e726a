#![doc = include_str!("../README.md")]

pub mod integrate;
pub mod ode;
pub mod plant;
