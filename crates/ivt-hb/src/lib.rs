#![doc = include_str!("../README.md")]
// Dense kernels index several arrays with the same row/column counters; iterator
// chains would hide the matrix structure the equations are written in.
#![allow(clippy::needless_range_loop)]

pub mod aft;
pub mod autonomous;
pub mod backbone;
pub mod branch;
pub mod broyden;
pub mod classic;
pub mod codim2;
pub mod condense;
pub mod continuation;
pub mod cycle_branch;
pub mod damped;
pub mod deflation;
pub mod elements;
mod error;
pub mod events;
pub mod family;
pub mod floquet;
pub mod frc;
pub mod galerkin;
pub mod hill;
pub mod hopf;
mod hysteresis;
pub mod ihb;
pub mod jobs;
pub mod limits;
pub mod mathieu;
pub mod models;
pub mod modified;
pub mod ode;
mod peak;
pub mod problem;
pub mod sensitivity;
pub mod stability;
pub mod switching;
pub mod torus;
pub mod transient;

pub use aft::Aft;
pub use autonomous::{limit_cycle, limit_cycle_branch, LimitCycle, LimitCycleBranch};
pub use backbone::{backbone, Backbone, BackboneOptions, BackbonePoint};
pub use branch::{Branch, ResidualBranch};
pub use broyden::{
    broyden_solve, BlockDiagonal, BroydenOptions, BroydenStats, BroydenWorkspace, SolveError,
    System,
};
pub use classic::ClassicIhb;
pub use codim2::{fold_curve, neimark_sacker_points, FoldCurve, FoldPoint, NeimarkSackerPoint};
pub use continuation::{
    BroydenCorrector, ContinuationOptions, Corrector, Fold, NewtonCorrector, Path, PathCorrector,
    PathPoint, Step, Stepper, Termination, Traced,
};
pub use cycle_branch::{cycle_branch, CycleBranch, CycleBranchOptions};
pub use damped::{damped_modes, linear_mode, DampedModePoint, DampedModes};
pub use deflation::{all_solutions, AllSolutions, FoundSolution, SearchOptions, SearchReport};
pub use elements::{element_dofs, restrict_elements, Element, ElementProblem, Harmonic, Law};
pub use error::HbError;
pub use events::{
    locate_branch_point, locate_fold, locate_multiplier_crossing, trace, Bifurcation,
    BifurcationError, BifurcationKind, Event, FoldLocation, LocateOptions, PathOptions, Trace,
    TraceOptions, TracedPoint,
};
pub use faer::c64;
pub use family::{Family, FamilyBranch, Frequency};
pub use floquet::{eigenvalues, monodromy_hsu, monodromy_uniform, HsuRule};
pub use frc::{frequency_response, Frc, FrcFold, FrcOptions, FrcPoint};
pub use galerkin::GalerkinJacobian;
pub use hill::{fourier_blocks, hill_multipliers, HillResult};
pub use hopf::{hopf_points, HopfPoint, HopfSearch, Undecided};
pub use ihb::{HbOptions, HbResidual, HbSolution, HbSolver};
pub use mathieu::{period_doubling_cascade, CascadeOptions, PeriodDoubling};
pub use modified::ModifiedIhb;
pub use problem::{
    central_difference_samples, AtFrequency, Duffing, Excitation, FrequencyExcitation,
    GeneralProblem, MathieuDuffing, Nonlinearity, PeriodicProblem, WithJacobian,
};
pub use stability::{
    classify, AdaptiveHsu, Floquet, HsuEstimate, HsuSteps, StabilityAnalyzer, StabilityKind,
};
pub use switching::{period_doubled_start, switch_branch};
pub use transient::{limit_cycle_from_state, settle, Settled, TransientOptions};

pub mod sthb;
