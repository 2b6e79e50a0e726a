#![doc = include_str!("../README.md")]
// Dense kernels index several arrays with the same row/column counters; iterator
// chains would hide the matrix structure the equations are written in.
#![allow(clippy::needless_range_loop)]

pub mod analyses;
pub mod branches;
mod error;
pub mod limits;
pub mod orbit;
pub mod problem;
pub mod stability;

pub use analyses::deflation::{
    all_solutions, AllSolutions, FoundSolution, SearchOptions, SearchReport,
};
pub use analyses::transient::{limit_cycle_from_state, settle, Settled, TransientOptions};
pub use branches::autonomous::{limit_cycle, limit_cycle_branch, LimitCycle, LimitCycleBranch};
pub use branches::backbone::{backbone, Backbone, BackboneOptions, BackbonePoint};
pub use branches::codim2::{fold_curve, FoldCurve, FoldPoint};
pub use branches::cycle_branch::{cycle_branch, CycleBranch, CycleBranchOptions};
pub use branches::damped::{damped_modes, linear_mode, DampedModePoint, DampedModes};
pub use branches::events::{
    locate_branch_point, locate_fold, locate_multiplier_crossing, trace, Bifurcation,
    BifurcationError, BifurcationKind, Event, FoldLocation, LocateOptions, PathOptions, Trace,
    TraceOptions, TracedPoint,
};
pub use branches::family::{Family, FamilyBranch, Frequency};
pub use branches::frc::{frequency_response, Frc, FrcFold, FrcOptions, FrcPoint};
pub use branches::mathieu::{period_doubling_cascade, CascadeOptions, PeriodDoubling};
pub use branches::switching::{period_doubled_start, switch_branch};
pub use error::HbError;
pub use faer::c64;
pub use ivt_num::{
    broyden_solve, BlockDiagonal, BroydenOptions, BroydenStats, BroydenWorkspace, SolveError,
    System,
};
pub use ivt_path::{Branch, PathError, ResidualBranch};
pub use ivt_path::{
    BroydenCorrector, ContinuationOptions, Corrector, NewtonCorrector, Path, PathCorrector,
    PathPoint, Step, Stepper, Termination, Traced, Turn,
};
pub use orbit::aft::Aft;
pub use orbit::classic::ClassicIhb;
pub use orbit::galerkin::GalerkinJacobian;
pub use orbit::ihb::{HbOptions, HbResidual, HbSolution, HbSolver};
pub use orbit::modified::ModifiedIhb;
pub use problem::elements::{
    element_dofs, restrict_elements, Element, ElementProblem, Harmonic, Law,
};
pub use problem::{
    central_difference_samples, AtFrequency, BoxedProblem, Duffing, Excitation,
    FrequencyExcitation, GeneralProblem, MathieuDuffing, Nonlinearity, Oscillator, PeriodicProblem,
    WithJacobian,
};
pub use stability::floquet::{eigenvalues, monodromy_hsu, monodromy_uniform, HsuRule};
pub use stability::hill::{fourier_blocks, hill_multipliers, HillResult};
pub use stability::hopf::{hopf_points, HopfPoint, HopfSearch, Undecided};
pub use stability::{
    classify, AdaptiveHsu, Floquet, HsuEstimate, HsuSteps, StabilityAnalyzer, StabilityKind,
};
