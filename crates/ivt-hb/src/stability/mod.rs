//! Stability of HB solutions (§3.2.4): the variational equation Eq. 78 in the
//! state-space form Eq. 79, `V' = Θ(τ) V` with `V = {δx, δx'}` and
//!
//! `Θ = [[0, I], [−M⁻¹(K + G_x)/ω², −M⁻¹(C + G_v)/ω]]`,  `G_x = ∂g/∂x`, `G_v = ∂g/∂v`,
//!
//! analysed by Hsu's method (Eq. 80) and by Hill's method; the two must agree.
//! Classification: stable (all |μ| < 1), fold (a real μ > 1), period doubling (a
//! real μ < −1), Neimark–Sacker (a complex pair outside the unit circle).

use crate::error::HbError;
use crate::orbit::aft::Aft;
use crate::orbit::ihb::HbSolution;
use crate::problem::PeriodicProblem;
use crate::stability::floquet::{eigenvalues, monodromy_strided, monodromy_uniform, HsuRule};
use crate::stability::hill::{fourier_blocks, hill_multipliers};
use faer::c64;
pub use ivt_path::multipliers::{classify, StabilityKind};

pub mod floquet;
pub mod hill;
pub mod hopf;

/// Floquet multipliers and their verdict.
#[derive(Debug, Clone, PartialEq)]
pub struct Floquet {
    /// Multipliers sorted by decreasing modulus.
    pub multipliers: Vec<c64>,
    /// Classification of the leading multiplier.
    pub kind: StabilityKind,
}

impl Floquet {
    /// From multipliers (sorted here).
    pub fn new(mut multipliers: Vec<c64>) -> Self {
        crate::stability::floquet::sort_by_modulus(&mut multipliers);
        let kind = classify(&multipliers);
        Self { multipliers, kind }
    }
    /// Largest |μ|.
    pub fn max_modulus(&self) -> f64 {
        self.multipliers
            .first()
            .map(|m| m.norm())
            .unwrap_or(f64::NAN)
    }
    /// All multipliers strictly inside the unit circle.
    pub fn stable(&self) -> bool {
        self.kind == StabilityKind::Stable
    }
}

/// Reusable buffers to evaluate Θ(τ) of HB solutions on a uniform grid of
/// `2·steps` points and run Hsu/Hill on it.
#[derive(Debug, Clone)]
pub struct StabilityAnalyzer {
    aft: Aft,
    steps: usize,
    nd: usize,
    minv: Vec<f64>,
    theta: Vec<f64>,
    /// `x`, `v = dx/dt` at the grid, sample-major (`2·steps×n_dof`).
    xs: Vec<f64>,
    vs: Vec<f64>,
    column: Vec<f64>,
    /// Excitation phase of each grid point (set per solution: it depends on p).
    phases: Vec<f64>,
    /// `[∂g/∂x | ∂g/∂v]` at every grid point (`2·steps·2n_dof²`).
    dg: Vec<f64>,
    q: Vec<f64>,
}

impl StabilityAnalyzer {
    /// For solutions with `harmonics` harmonics, Hsu with `steps` sub-intervals
    /// (`steps > harmonics`; 256 is enough for flags, 4096 for 1e-9 agreement).
    ///
    /// # Errors
    /// [`HbError::AftTooFewSamples`] if `steps ≤ harmonics`,
    /// [`HbError::InvalidInput`] for a problem without DOFs. A singular mass matrix
    /// gives NaN multipliers, which classify as unstable.
    pub fn new<P: PeriodicProblem>(
        problem: &P,
        harmonics: usize,
        steps: usize,
    ) -> Result<Self, HbError> {
        let aft = Aft::new(harmonics, steps)?;
        let nd = problem.n_dof();
        if nd == 0 {
            return Err(HbError::InvalidInput("n_dof must be positive".into()));
        }
        let minv =
            ivt_num::lu::inverse(problem.mass(), nd).unwrap_or_else(|| vec![f64::NAN; nd * nd]);
        let dim = 2 * nd;
        let ns = 2 * steps;
        Ok(Self {
            aft,
            steps,
            nd,
            minv,
            theta: vec![0.0; ns * dim * dim],
            xs: vec![0.0; nd * ns],
            vs: vec![0.0; nd * ns],
            column: vec![0.0; ns],
            phases: vec![0.0; ns],
            dg: vec![0.0; 2 * ns * nd * nd],
            q: vec![0.0; dim * dim],
        })
    }

    /// Θ(τ_j) on the grid τ_j = 2πj/(2·steps), row-major `2n_dof×2n_dof` each.
    pub fn theta_samples<P: PeriodicProblem>(&mut self, problem: &P, sol: &HbSolution) -> &[f64] {
        self.theta_samples_with(problem, sol, None)
    }

    /// [`Self::theta_samples`] from `∂g` samples the caller already has:
    /// `known` holds `[∂g/∂x | ∂g/∂v]` of `sol` at the same `2·steps` grid
    /// points (layout of [`PeriodicProblem::nonlinear_jacobian_samples`]), as
    /// the Galerkin Jacobian of an orbit with `N = steps` has them; `None` (or
    /// a slice of another length) evaluates them.
    fn theta_samples_with<P: PeriodicProblem>(
        &mut self,
        problem: &P,
        sol: &HbSolution,
        known: Option<&[f64]>,
    ) -> &[f64] {
        let nd = self.nd;
        let dim = 2 * nd;
        let d2 = dim * dim;
        let ns = 2 * self.steps;
        let omega = sol.omega();
        match known {
            Some(dg) if dg.len() == self.dg.len() => self.dg.copy_from_slice(dg),
            _ => {
                let p = sol.subharmonic as f64;
                let q = &sol.coeffs;
                self.aft
                    .synthesize_states(q, nd, 0, 1.0, &mut self.xs, &mut self.column);
                self.aft
                    .synthesize_states(q, nd, 1, omega, &mut self.vs, &mut self.column);
                for (j, phase) in self.phases.iter_mut().enumerate() {
                    *phase = p * self.aft.tau(j);
                }
                problem.nonlinear_jacobian_samples(&self.xs, &self.vs, &self.phases, &mut self.dg);
            }
        }
        let (c, k) = (problem.damping(), problem.stiffness());
        let n2 = nd * nd;
        // nd ≥ 1 (checked in `new`); a problem whose C or K is not nd×nd gives NaN
        // (unstable), as a singular mass does.
        if nd == 0
            || c.len() != n2
            || k.len() != n2
            || self.minv.len() != n2
            || self.theta.len() != ns * d2
        {
            self.theta.fill(f64::NAN);
            return &self.theta;
        }
        let matrices = SystemMatrices {
            minv: &self.minv,
            k,
            c,
            omega,
        };
        crate::stability::floquet::by_size!(
            nd,
            theta_from_tangents(nd, matrices, &self.dg, &mut self.theta)
        );
        &self.theta
    }

    /// Floquet multipliers by Hsu's method (Eq. 80) with the given rule.
    pub fn hsu<P: PeriodicProblem>(
        &mut self,
        problem: &P,
        sol: &HbSolution,
        rule: HsuRule,
    ) -> Floquet {
        self.hsu_with(problem, sol, rule, None)
    }

    /// [`Self::hsu`] with `∂g` samples the caller has (see
    /// [`Self::theta_samples_with`]).
    fn hsu_with<P: PeriodicProblem>(
        &mut self,
        problem: &P,
        sol: &HbSolution,
        rule: HsuRule,
        known: Option<&[f64]>,
    ) -> Floquet {
        self.theta_samples_with(problem, sol, known);
        let dim = 2 * self.nd;
        monodromy_uniform(
            dim,
            &self.theta,
            self.steps,
            2.0 * std::f64::consts::PI,
            rule,
            &mut self.q,
        );
        Floquet::new(eigenvalues(&self.q, dim))
    }

    /// Floquet multipliers by Hill's method with `h` harmonics in the perturbation
    /// (Θ's Fourier blocks up to `2h` from the same grid).
    ///
    /// # Errors
    /// [`HbError::Eigen`] if the eigen-solver fails, [`HbError::InvalidInput`] if
    /// `2·steps ≤ 4h`.
    pub fn hill<P: PeriodicProblem>(
        &mut self,
        problem: &P,
        sol: &HbSolution,
        h: usize,
    ) -> Result<Floquet, HbError> {
        self.theta_samples(problem, sol);
        let dim = 2 * self.nd;
        let ns = 2 * self.steps;
        let kmax = (2 * h).min((ns - 1) / 2);
        let blocks = fourier_blocks(dim, &self.theta, ns, kmax)?;
        let res = hill_multipliers(dim, &blocks, h)?;
        Ok(Floquet::new(res.multipliers))
    }
}

/// How many Hsu sub-intervals the multipliers of each point of a path get.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HsuSteps {
    /// This many at every point (Magnus-4, no error estimate).
    Fixed(usize),
    /// Chosen per point ([`AdaptiveHsu`]): doubled from `max(2(n + 1), 32)`
    /// until the Richardson estimate of the multipliers' error is at most
    /// `tol` (relative to max(1, |μ|)), at most `max` sub-intervals.
    Tolerance {
        /// Target error of the multipliers.
        tol: f64,
        /// Cap on the sub-intervals (a point that reaches it keeps its larger
        /// error estimate).
        max: usize,
    },
}

impl Default for HsuSteps {
    /// Multipliers to 1e-6 (the accuracy 256 fixed steps had on the Duffing
    /// and chain curves, 5.6e-7 at worst, now held at every point), at most
    /// 4096 sub-intervals.
    fn default() -> Self {
        Self::Tolerance {
            tol: 1e-6,
            max: 4096,
        }
    }
}

/// The multipliers of one orbit by [`AdaptiveHsu`], with the sub-intervals used
/// and the error estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct HsuEstimate {
    /// Multipliers and verdict.
    pub floquet: Floquet,
    /// Hsu sub-intervals used.
    pub steps: usize,
    /// Richardson estimate of the multipliers' error from those of `S/2`
    /// sub-intervals (relative to max(1, |μ|); Magnus-4 is fourth order);
    /// `None` for [`HsuSteps::Fixed`].
    pub error: Option<f64>,
}

/// Hsu's method (Magnus-4) along a path of orbits with the step count chosen
/// per orbit: the multipliers of the monodromy Φ_S of `S` sub-intervals and
/// of Φ_{S/2} from every other Θ sample of the same grid give the Richardson
/// error estimate ([`richardson_error`], fourth order; third at the first
/// level, whose `S/2` is pre-asymptotic); `S` doubles until it meets the
/// tolerance, and the next orbit starts at the `S` that met it (or half of it
/// when the estimate was 32× below). Estimating on the multipliers, not on
/// Φ's entries, takes their conditioning into account: next to a fold the
/// multiplier at +1 moves 20× more than Φ's entries. One
/// [`StabilityAnalyzer`] per step count is kept.
#[derive(Debug, Clone)]
pub struct AdaptiveHsu {
    control: HsuSteps,
    harmonics: usize,
    /// Step count of level 0; level `k` has `base·2^k`.
    base: usize,
    /// Highest level (`base·2^top ≤ max`).
    top: usize,
    /// Level the next orbit starts at.
    level: usize,
    levels: Vec<StabilityAnalyzer>,
    coarse: Vec<f64>,
}

impl AdaptiveHsu {
    /// For orbits of `problem` with `harmonics` harmonics.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for a tolerance that is not positive and finite
    /// or a cap below the first step count; [`HbError::AftTooFewSamples`] for a
    /// fixed count `≤ harmonics`.
    pub fn new<P: PeriodicProblem>(
        problem: &P,
        harmonics: usize,
        control: HsuSteps,
    ) -> Result<Self, HbError> {
        let (base, top) = match control {
            HsuSteps::Fixed(steps) => (steps, 0),
            HsuSteps::Tolerance { tol, max } => {
                let base = (2 * (harmonics + 1)).max(32);
                if !(tol > 0.0 && tol.is_finite()) || max < base {
                    return Err(HbError::InvalidInput(format!(
                        "Hsu tolerance {tol:?} must be positive and finite and the cap {max} at \
                         least {base} sub-intervals (2(n + 1), at least 32)"
                    )));
                }
                (base, (max / base).ilog2() as usize)
            }
        };
        let first = StabilityAnalyzer::new(problem, harmonics, base)?;
        let dim = 2 * problem.n_dof();
        Ok(Self {
            control,
            harmonics,
            base,
            top,
            level: 0,
            levels: vec![first],
            coarse: vec![0.0; dim * dim],
        })
    }

    /// The multipliers of `sol` with the error estimate and the steps used.
    ///
    /// # Errors
    /// [`HbError`] if the analyzer of a finer level cannot be set up.
    pub fn floquet<P: PeriodicProblem>(
        &mut self,
        problem: &P,
        sol: &HbSolution,
    ) -> Result<HsuEstimate, HbError> {
        self.floquet_with_samples(problem, sol, None)
    }

    /// [`Self::floquet`] with `∂g` samples of `sol` the caller already has:
    /// `known` holds `[∂g/∂x | ∂g/∂v]` on the uniform grid of `M` points
    /// (`M = known.len()/(2n_dof²)`, layout of
    /// [`PeriodicProblem::nonlinear_jacobian_samples`]), e.g. the AFT samples
    /// of a Galerkin assembly at `sol` ([`crate::FamilyBranch::jacobian_samples_at`]).
    /// The level with `2·steps = M` uses them instead of calling `g`; the
    /// other levels evaluate their own. An AFT of `N = max(2(n + 1), 32)` (2N
    /// samples) matches the first level of [`HsuSteps::Tolerance`], so an
    /// orbit that needs no finer level costs no `g` evaluation.
    ///
    /// # Errors
    /// As [`Self::floquet`].
    pub fn floquet_with_samples<P: PeriodicProblem>(
        &mut self,
        problem: &P,
        sol: &HbSolution,
        known: Option<&[f64]>,
    ) -> Result<HsuEstimate, HbError> {
        let HsuSteps::Tolerance { tol, .. } = self.control else {
            let an = level_mut(&mut self.levels, problem, self.harmonics, self.base, 0)?;
            return Ok(HsuEstimate {
                floquet: an.hsu_with(problem, sol, HsuRule::Magnus4, known),
                steps: self.base,
                error: None,
            });
        };
        let dim = 2 * problem.n_dof();
        let period = 2.0 * std::f64::consts::PI;
        let mut level = self.level;
        // Multipliers of the level below, when it was just computed.
        let mut coarse: Option<Vec<c64>> = None;
        loop {
            let an = level_mut(&mut self.levels, problem, self.harmonics, self.base, level)?;
            an.theta_samples_with(problem, sol, known);
            monodromy_uniform(
                dim,
                &an.theta,
                an.steps,
                period,
                HsuRule::Magnus4,
                &mut an.q,
            );
            let fine = eigenvalues(&an.q, dim);
            let coarse_mu = match coarse.take() {
                Some(mu) => mu,
                None => {
                    let samples = 2 * an.steps;
                    let phi = &mut self.coarse;
                    monodromy_strided(dim, &an.theta, samples, 2, period, HsuRule::Magnus4, phi);
                    eigenvalues(phi, dim)
                }
            };
            // Level 0's coarse member has S/2 = n + 1 steps, at the edge of
            // resolving the n harmonics and short of the fourth-order regime
            // (Duffing, Fig. 28, ω_f = 0.654: error ratio 7.2 from S/2 to S
            // against 14–16 above; measured): there the change counts as
            // third order.
            let order = if level == 0 { 3 } else { 4 };
            let error = richardson_error(&fine, &coarse_mu, order);
            // NaN (singular mass, non-finite Θ) stops here and classifies as unstable.
            if error <= tol || level == self.top || !error.is_finite() {
                self.level = if error * 32.0 <= tol && level > 0 {
                    level - 1
                } else {
                    level
                };
                return Ok(HsuEstimate {
                    floquet: Floquet::new(fine),
                    steps: an.steps,
                    error: Some(error),
                });
            }
            coarse = Some(fine);
            level += 1;
        }
    }
}

/// The analyzer of `level` of [`AdaptiveHsu`] (`base·2^level` sub-intervals),
/// made with the levels below it on first use.
fn level_mut<'a, P: PeriodicProblem>(
    levels: &'a mut Vec<StabilityAnalyzer>,
    problem: &P,
    harmonics: usize,
    base: usize,
    level: usize,
) -> Result<&'a mut StabilityAnalyzer, HbError> {
    while levels.len() <= level {
        let steps = base << levels.len();
        levels.push(StabilityAnalyzer::new(problem, harmonics, steps)?);
    }
    levels
        .get_mut(level)
        .ok_or_else(|| HbError::InvalidInput(format!("no Hsu level {level}")))
}

/// The matrices of Θ's lower rows besides the `∂g` samples: M⁻¹ and K, C
/// (row-major `n×n`) and ω.
#[derive(Clone, Copy)]
struct SystemMatrices<'a> {
    minv: &'a [f64],
    k: &'a [f64],
    c: &'a [f64],
    omega: f64,
}

/// Θ's samples (Eq. 80's system matrix, row-major `2n×2n` each) from the
/// `[∂g/∂x | ∂g/∂v]` samples `dg`: upper rows `[0 | I]`, lower rows
/// `[−M⁻¹(K + G_x)/ω² | −M⁻¹(C + G_v)/ω]` accumulated row by row, with the
/// DOF count `N = n` known at compile time (every loop unrolled) or read
/// from `nd` for `N = 0`. Slices shorter than their sizes give NaN.
fn theta_from_tangents<const N: usize>(
    nd: usize,
    matrices: SystemMatrices<'_>,
    dg: &[f64],
    theta: &mut [f64],
) {
    let nd = if N == 0 { nd } else { N };
    let (n2, dim) = (nd * nd, 2 * nd);
    let SystemMatrices { minv, k, c, omega } = matrices;
    let (Some(minv), Some(k), Some(c), true) = (minv.get(..n2), k.get(..n2), c.get(..n2), nd > 0)
    else {
        return theta.fill(f64::NAN);
    };
    for (dg, th) in dg
        .chunks_exact(2 * n2)
        .zip(theta.chunks_exact_mut(dim * dim))
    {
        let (dgx, dgv) = dg.split_at(n2);
        th.fill(0.0);
        let (upper, lower) = th.split_at_mut(nd * dim);
        for (row, one) in upper.chunks_exact_mut(dim).zip(nd..) {
            if let Some(x) = row.get_mut(one) {
                *x = 1.0;
            }
        }
        // Row i: Σ_l (M⁻¹)_il (K + G_x)_l·, the rows l of K and G_x contiguous.
        for (row, minv_row) in lower.chunks_exact_mut(dim).zip(minv.chunks_exact(nd)) {
            let (row_k, row_c) = row.split_at_mut(nd);
            let rows_l = k.chunks_exact(nd).zip(dgx.chunks_exact(nd));
            let rows_l = rows_l.zip(c.chunks_exact(nd).zip(dgv.chunks_exact(nd)));
            for (&m, ((k_l, gx_l), (c_l, gv_l))) in minv_row.iter().zip(rows_l) {
                for (t, (a, b)) in row_k.iter_mut().zip(k_l.iter().zip(gx_l)) {
                    *t += m * (a + b);
                }
                for (t, (a, b)) in row_c.iter_mut().zip(c_l.iter().zip(gv_l)) {
                    *t += m * (a + b);
                }
            }
            row_k.iter_mut().for_each(|t| *t = -*t / (omega * omega));
            row_c.iter_mut().for_each(|t| *t = -*t / omega);
        }
    }
}

/// Richardson estimate of the error of the multipliers `fine` of `S` steps of
/// a method of order `order` from those of `S/2`, `coarse`: their
/// [`multiplier_distance`] over `2^order − 1` (15 for Magnus-4 in its
/// asymptotic regime).
pub fn richardson_error(fine: &[c64], coarse: &[c64], order: u32) -> f64 {
    multiplier_distance(fine, coarse) / f64::from((1u32 << order) - 1)
}

/// The Hausdorff distance between two multiplier sets, each distance relative
/// to max(1, |μ|) (the pairing by nearest neighbour needs no common order of
/// the two lists).
pub fn multiplier_distance(a: &[c64], b: &[c64]) -> f64 {
    let nearest = |z: &c64, set: &[c64]| {
        set.iter()
            .map(|w| (z - w).norm() / z.norm().max(1.0))
            .fold(f64::INFINITY, f64::min)
    };
    let one_way = |a: &[c64], b: &[c64]| a.iter().map(|z| nearest(z, b)).fold(0.0, f64::max);
    one_way(a, b).max(one_way(b, a))
}
