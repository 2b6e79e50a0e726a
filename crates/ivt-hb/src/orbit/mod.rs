//! The orbit layer: one periodic orbit of a [`crate::problem::PeriodicProblem`]
//! by harmonic balance (thesis §3.2, Eq. 50–67). The AFT residual
//! ([`aft`]: the time samples by FFT, Eq. 61–62), the planned residual and
//! the solver trait ([`ihb`]: `HbResidual`, `HbOptions`, `HbSolver`), the
//! exact Galerkin Jacobian ([`galerkin`], Eq. 56), and the two solvers: the
//! modified IHB on Broyden's update ([`modified`], Eq. 57–67, the thesis's)
//! and the classic IHB on Newton ([`classic`], §3.2.1). It uses the problem
//! layer below it; the layers above (stability, branches, analyses) use it.
//! The one exception: the modified IHB's ε-stepping from the linear solution
//! is a path of the path engine (`ivt_path::follow_residual`), the closure
//! path that phase 2 of issue #40 replaces.

pub mod aft;
pub mod classic;
pub mod galerkin;
pub mod ihb;
pub mod modified;
pub mod peak;
