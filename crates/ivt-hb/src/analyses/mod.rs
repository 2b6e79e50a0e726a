//! The analyses layer: answers built from several orbits or branches. Every
//! solution at one frequency by deflated Newton ([`deflation`]) and the
//! limit cycle reached from a state by a transient ([`transient`]).

pub mod deflation;
pub mod transient;
