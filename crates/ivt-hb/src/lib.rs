#![doc = include_str!("../README.md")]
// Dense kernels index several arrays with the same row/column counters; iterator
// chains would hide the matrix structure the equations are written in.
#![allow(clippy::needless_range_loop)]

pub mod aft;
pub mod autonomous;
pub mod broyden;
pub mod classic;
pub mod continuation;
pub mod floquet;
pub mod fold;
pub mod frc;
pub mod hill;
pub mod ihb;
pub mod limits;
pub mod linalg;
pub mod mathieu;
pub mod modified;
pub mod ode;
pub mod problem;
pub mod stability;

pub use aft::{Aft, AftError};
pub use autonomous::{limit_cycle, limit_cycle_branch, LimitCycle, LimitCycleBranch};
pub use broyden::{
    broyden_solve, BroydenOptions, BroydenStats, BroydenWorkspace, SolveError, System,
};
pub use classic::ClassicIhb;
pub use continuation::{
    pseudo_arclength, ContinuationError, ContinuationOptions, Fold, Path, PathPoint, Termination,
};
pub use faer::c64;
pub use floquet::{eigenvalues, monodromy_hsu, monodromy_uniform, HsuRule};
pub use fold::{locate_fold, Branch, FoldLocation, FoldOptions, HbBranch};
pub use frc::{frequency_response, Frc, FrcFold, FrcOptions, FrcPoint};
pub use hill::{fourier_blocks, hill_multipliers, HillError, HillResult};
pub use ihb::{GalerkinJacobian, HbError, HbOptions, HbResidual, HbSolution, HbSolver};
pub use mathieu::{period_doubling_cascade, CascadeOptions, PeriodDoubling};
pub use modified::ModifiedIhb;
pub use problem::{Duffing, GeneralProblem, MathieuDuffing, PeriodicProblem};
pub use stability::{classify, Floquet, StabilityAnalyzer, StabilityKind};

pub mod sthb;
