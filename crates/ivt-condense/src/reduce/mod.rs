//! Large solids reduced once, on a certified basis (issue 42).
//!
//! The exact condensed path factors `D_h = K − (hω)²M + ihωC` of the whole
//! structure per harmonic and per corrector step: exact, but on a 3-D solid
//! of 10⁵ DOFs each point costs minutes. Here the structure is projected
//! once (Galerkin) onto a basis `V` that reproduces its receptances at the
//! nonlinear DOFs `S` and its response to the load over every frequency the
//! harmonic balance asks for (`h·ω`, `h = 0..=n`, ω in the band), and the
//! condensed harmonic balance then runs on the small reduced model.
//!
//! **The basis** ([`basis`]): the static modes of `S` and of the load,
//! `K⁻¹[E_S | F]` (Craig–Bampton's constraint modes; pyHarm's and NLvib's
//! reductions keep them too), continued by the block Krylov sequence
//! `(K⁻¹M)ʲ K⁻¹[E_S | F]`, M-orthonormal with full reorthogonalization:
//! block Lanczos in shift-invert mode at σ = 0, on one sparse Cholesky
//! factorization of `K` (faer's supernodal `LLᵀ`). Why Cholesky at σ = 0:
//! `K` of a clamped structure is symmetric positive definite, so `K − σM`
//! is for every σ below the first eigenvalue; σ = 0 gives the static modes
//! from the same factorization, needs no estimate of the spectrum (no
//! scale: the SI plate has `K` ~ 1e9 and `M` ~ 1e-3) and converges from the
//! low end, where the band is. Why Krylov from the static modes rather than
//! the lowest eigenmodes and a residual flexibility: the Galerkin projection
//! onto this space matches the receptances' moments about ω = 0 and its Ritz
//! values converge to exactly the modes `S` and the load see (the others do
//! not enter the receptances at `S`), so the error falls geometrically with
//! the basis instead of as (ω/ω_cut)² (residual flexibility) or
//! (ω/ω_cut)⁴ (Craig–Bampton). The basis grows by blocks until
//!
//! - its Ritz values pass the cut-off `ω_c = CUTOFF·n·ω_max/p` (the modes
//!   up to there are in it; those converged are counted as `modes`), and
//! - the receptances on it change by at most `tol`/[`NESTED_MARGIN`] (relative)
//!   from those on the basis one block smaller, on a grid of every harmonic
//!   band `h·[ω_min, ω_max]` ([`certify`]).
//!
//! **The certificate** ([`certify`]): at sampled frequencies (the highest
//! harmonic's band end and where the nested change is largest) the reduced
//! receptances are compared with exact sparse solves of the whole
//! structure (faer's sparse LU with refinement in double-double residuals,
//! [`super::Structure::solve_refined`]). A sample beyond `tol` adds its exact
//! solutions to the basis (the projection then interpolates there) and the
//! check repeats. The reported `error_estimate` is the larger of the
//! samples' errors and the nested change on the grid.
//!
//! **The reduced model** ([`model`]): the basis rewritten so that its first
//! `s` coordinates are `x_S` themselves (`Ψ`, the static modes scaled to
//! unit displacement at `S`) and the rest vanish at `S` (`W`, rotated to the
//! eigenvectors of `WᵀKW`): `K_r` is block diagonal, `M_r` an arrow, so
//! the reduced [`super::Structure`] factors in `O(r·s²)`, and the exact
//! condensed path runs on it unchanged ([`super::CondensedBranch`] with the
//! nonlinear DOFs `0..s`).

pub mod basis;
pub mod certify;
pub mod model;
pub mod response;

pub use certify::Sample;
pub use model::ReducedModel;
pub use response::{reduced_response, ReducedFrc, ReducedPoint, Verdict};

/// The cut-off of the basis, in units of the highest harmonic's frequency
/// `n·ω_max/p`: the Ritz values reach beyond it before the basis may stop.
pub const CUTOFF: f64 = 1.5;

/// The nested change the basis grows to, relative to the tolerance: the
/// change from one block fewer estimates the smaller basis's error, which
/// bounds the larger's while the Krylov sequence converges.
pub const NESTED_MARGIN: f64 = 10.0;

/// How the reduction is sized and checked.
#[derive(Debug, Clone, PartialEq)]
pub struct ReductionOptions {
    /// The band of excitation frequencies ω_f.
    pub band: (f64, f64),
    /// Harmonics `n` of the balance.
    pub harmonics: usize,
    /// The response's period is `p` excitation periods (ω = ω_f/p).
    pub subharmonic: usize,
    /// Relative receptance error at the nonlinear DOFs the basis must meet.
    pub tol: f64,
    /// Exact sparse solves of the whole structure that check it.
    pub samples: usize,
    /// Excitation frequencies per harmonic band on the grid of the nested
    /// estimate.
    pub grid: usize,
    /// The basis stops growing at this many vectors (its estimate then says
    /// how good it is).
    pub max_basis: usize,
}

impl Default for ReductionOptions {
    /// tol = 1e-8, 3 samples, 24 grid points per band, at most 1500 vectors.
    fn default() -> Self {
        Self {
            band: (1.0, 2.0),
            harmonics: 7,
            subharmonic: 1,
            tol: 1e-8,
            samples: 3,
            grid: 24,
            max_basis: 1500,
        }
    }
}

/// What the reduction reports with every result.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Reduction {
    /// `"krylov_static"`: block Lanczos (shift-invert at 0, sparse Cholesky
    /// of `K`) from the static modes of the nonlinear DOFs and the load.
    pub method: &'static str,
    /// DOFs of the whole structure.
    pub n_dof: usize,
    /// Basis vectors (the reduced model's DOFs).
    pub basis: usize,
    /// Krylov blocks.
    pub blocks: usize,
    /// Converged Ritz values (eigenmodes) below the cut-off.
    pub modes: usize,
    /// The cut-off frequency `CUTOFF·n·ω_max/p` in rad/s.
    pub cutoff: f64,
    /// The lowest Ritz frequency in rad/s (the first mode S or the load see).
    pub first_frequency: f64,
    /// Estimated relative receptance error over every harmonic band: the
    /// larger of the samples' errors and the nested change.
    pub error_estimate: f64,
    /// The largest nested change on the grid (the samples excluded).
    pub nested_change: f64,
    /// The exact checks, in the order made.
    pub sampled: Vec<Sample>,
    /// Wall time of the reduction in seconds (measured, for benchmarks).
    pub seconds: f64,
}
