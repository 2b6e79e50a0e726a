#![doc = include_str!("../README.md")]
// Dense kernels index several arrays with the same row/column counters; iterator
// chains would hide the matrix structure the equations are written in.
#![allow(clippy::needless_range_loop)]

pub mod branch;
pub mod continuation;
mod error;
pub mod events;
pub mod limits;
pub mod multipliers;

pub use branch::{Branch, ResidualBranch};
pub use continuation::{
    correct_at_fixed_lambda, follow_residual, BroydenCorrector, ContinuationOptions, Corrector,
    NewtonCorrector, Path, PathCorrector, PathPoint, Step, Stepper, Termination, Traced, Turn,
};
pub use error::PathError;
pub use events::{
    locate_fold, observe, Bifurcation, BifurcationKind, Detector, Event, EventObserver, Fold,
    FoldLocation, LocateOptions, Observer, PathSoFar, PointMultipliers, Start, TracedPoint,
};
pub use multipliers::{classify, StabilityKind};
