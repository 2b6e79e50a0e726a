//! Events on a branch `R(u, λ) = 0`, each one [`Detector`]: a test function
//! at every accepted path point and a locator — Newton on a minimally
//! extended system (Govaerts' bordering on [`ivt_num::BorderedLu`],
//! [`extended`]) — started where the test changes sign. The [`observe`]
//! driver hands each point of a [`Stepper`](crate::Stepper) to an
//! [`Observer`] as it arrives, as BifurcationKit does, instead of searching
//! the finished path; the [`EventObserver`] runs detectors and, through a
//! [`PointMultipliers`], gives each point its Floquet multipliers.
//!
//! Here: the [`Fold`] of any branch ([`fold`]: the λ component of the secant
//! changes sign; located by [`locate_fold`]) and the [`Crossing`] of a set
//! value by one component of the path vector ([`crossing`]: the requested
//! points of a curve). The events of the Floquet
//! multipliers (period doubling, Neimark–Sacker) and the branch point need
//! the monodromy of the orbits; they are ivt-hb's (`ivt_hb::branches::events`).
//!
//! The location error of an event is the detector's `E` (a branch whose
//! locators fail in its own terms, as ivt-hb's, reports its own error type;
//! the path engine's failures convert into it, `E: From<PathError>`).

pub mod crossing;
mod detector;
pub mod extended;
pub mod fold;
mod observe;

pub use crossing::Crossing;
pub use detector::{
    dot, Bifurcation, BifurcationKind, Detector, Event, LocateOptions, Observer, PathSoFar, Start,
    TracedPoint, Unlocated,
};
pub use fold::{locate_fold, Fold, FoldLocation};
pub use observe::{observe, observe_residual, EventObserver, PointMultipliers};
