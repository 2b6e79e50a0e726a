#![doc = include_str!("../README.md")]

pub mod backend;
pub mod integrate;
pub mod ode;
pub mod pil;
pub mod plant;
pub mod sensors;
