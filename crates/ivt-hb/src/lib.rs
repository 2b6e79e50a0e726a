#![doc = include_str!("../README.md")]

pub mod aft;
pub mod broyden;
pub mod classic;
pub mod continuation;
pub mod floquet;
pub mod hill;
pub mod ihb;
pub mod linalg;
pub mod modified;
pub mod problem;

pub use aft::{Aft, AftError};
pub use broyden::{
    broyden_solve, BroydenOptions, BroydenStats, BroydenWorkspace, SolveError, System,
};
pub use classic::ClassicIhb;
pub use continuation::{
    pseudo_arclength, ContinuationError, ContinuationOptions, Fold, Path, PathPoint, Termination,
};
pub use faer::c64;
pub use floquet::{eigenvalues, monodromy_hsu, monodromy_uniform, HsuRule};
pub use hill::{fourier_blocks, hill_multipliers, HillError, HillResult};
pub use ihb::{HbError, HbOptions, HbResidual, HbSolution};
pub use modified::ModifiedIhb;
pub use problem::{Duffing, GeneralProblem, MathieuDuffing, PeriodicProblem};

pub mod ivt;
pub mod sthb;
