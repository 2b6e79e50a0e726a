//! Harmonic balance (modified and classic IHB), continuation, Floquet/Hill stability, STHB. Being built under issues 3, 4 and 7; nothing here yet.
pub mod ivt;
