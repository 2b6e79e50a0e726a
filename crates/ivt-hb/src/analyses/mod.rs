//! The analyses layer: answers built from several orbits or branches. Every
//! solution at one frequency by deflated Newton ([`deflation`]), the
//! limit cycle reached from a state by a transient ([`transient`]), and the
//! derivative of a located event in a model parameter ([`sensitivity`]).

pub mod deflation;
pub mod sensitivity;
pub mod transient;
