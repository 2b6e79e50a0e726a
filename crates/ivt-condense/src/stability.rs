//! Floquet multipliers of condensed orbits: the variational equation of the
//! whole structure (Eq. 78 with `g` acting on the DOFs `S` only),
//!
//! `M δẍ + C δẋ + K δx + E_S (G_x(t) E_Sᵀ δx + G_v(t) E_Sᵀ δẋ) = 0`,
//!
//! Galerkin-projected onto a reduced basis `V` and analysed by Hsu's method
//! (Eq. 79–80): by the modal splitting of [`super::modal_hsu`] where the
//! reduced damping is proportional and `g` reads positions only, else (or
//! when the splitting does not meet the tolerance) by [`AdaptiveHsu`].
//!
//! The basis: the load-dependent Ritz vectors of `S` ([`super::ritz`]). It
//! holds the static modes of `S` exactly and converges to the lowest modes
//! as `S` sees them. The time-varying term acts only through `S`, so for
//! proportional damping the modes `S` does not see (zero at `S`) stay
//! uncoupled from the orbit: their multipliers are the linear structure's
//! `exp(λ_j T)` and are not reported. The truncation error is estimated per
//! orbit as the change of the multipliers (|μ| ≥ 0.01) when the basis loses
//! its last block (the spaces are nested, so the change bounds the
//! larger basis's error while the Krylov space converges); the basis grows
//! until that change is below a tolerance, or until it closes an invariant
//! subspace of the linear part (then the estimate is the measured part of
//! the linear part's image outside it, rounding), or a cap. Hsu's own
//! Richardson estimate is added.

use super::branch::CondensedBranch;
use super::modal_hsu::ModalHsu;
use super::ritz::{at, row, Reduced, RitzBasis};
use faer::c64;
use ivt_hb::orbit::ihb::HbSolution;
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::stability::{AdaptiveHsu, Floquet, HsuEstimate, HsuSteps};
use ivt_hb::HbError;
use ivt_num::vector::dot;

/// Multipliers of smaller modulus take no part in the truncation estimate:
/// they are far from deciding stability.
const COMPARED_MODULUS: f64 = 1e-2;

/// Hsu's Richardson estimate assumes the error ratio 2⁴ of Magnus-4 between
/// `S/2` and `S` sub-intervals; it is asymptotic (on the bladed disk near its
/// peak the actual error was 1.025× the estimate), so the reported
/// [`CondensedFloquet::hsu_error`] is twice it.
const HSU_SAFETY: f64 = 2.0;

/// The cap on the Krylov blocks of the basis when not chosen
/// ([`BasisGrowth`]).
pub const DEFAULT_BLOCKS: usize = 64;

/// The basis truncation estimate the basis grows to when not chosen
/// ([`BasisGrowth`]). 1e-4 keeps the cantilever's curves on their first 8
/// blocks, as fast as the fixed basis was (its estimates there are
/// ≤ 1.4e-5, measured, not asserted); 1e-6, Hsu's default tolerance, grows
/// the N = 20 beam's basis to 12 vectors (`tests/condense_stability.rs`). A
/// basis that closes an invariant subspace (the bladed disk's 39 vectors)
/// is exact either way.
pub const DEFAULT_BASIS_TOL: f64 = 1e-4;

/// The blocks the first orbit of a path starts from.
const FIRST_BLOCKS: usize = 8;

/// How far the reduced basis grows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BasisGrowth {
    /// Target of the truncation estimate (the multipliers' change when the
    /// basis loses its last block).
    pub tol: f64,
    /// At most this many Krylov blocks (at least 3); an orbit that reaches
    /// the cap keeps its larger estimate.
    pub max_blocks: usize,
}

impl Default for BasisGrowth {
    /// [`DEFAULT_BASIS_TOL`], at most [`DEFAULT_BLOCKS`] blocks.
    fn default() -> Self {
        Self {
            tol: DEFAULT_BASIS_TOL,
            max_blocks: DEFAULT_BLOCKS,
        }
    }
}

/// The multipliers of one condensed orbit.
#[derive(Debug, Clone, PartialEq)]
pub struct CondensedFloquet {
    /// Multipliers of the reduced variational equation and their verdict.
    pub floquet: Floquet,
    /// Basis vectors used.
    pub basis: usize,
    /// Estimated error of the multipliers from the basis truncation: the
    /// Hausdorff distance (|μ| ≥ 0.01) to those of the basis one block
    /// smaller, or for a basis spanning an invariant subspace of the linear
    /// part the relative part of that part's image outside it (at least
    /// 1e-10, the threshold below which a Krylov vector counts as rounding).
    pub truncation_error: f64,
    /// Twice Hsu's Richardson estimate of the multipliers' error.
    pub hsu_error: f64,
}

impl CondensedFloquet {
    /// The two estimates together: the error the multipliers carry.
    pub fn error_estimate(&self) -> f64 {
        self.truncation_error + self.hsu_error
    }
}

/// The reduced variational problem seen by the stability analysis: the
/// reduced linear part and `g` through `V_S`.
struct ReducedProblem<'a, P> {
    reduced: &'a Reduced,
    local: &'a P,
    s: usize,
}

impl<P: PeriodicProblem> ReducedProblem<'_, P> {
    /// `x_S = V_S z` for each of the sample-major samples of `z`.
    fn to_dofs(&self, z: &[f64]) -> Vec<f64> {
        let (r, s) = (self.reduced.size, self.s);
        z.chunks_exact(r)
            .flat_map(|zi| (0..s).map(move |a| dot(row(&self.reduced.at_dofs, a, r), zi)))
            .collect()
    }
}

impl<P: PeriodicProblem> PeriodicProblem for ReducedProblem<'_, P> {
    fn n_dof(&self) -> usize {
        self.reduced.size
    }
    fn mass(&self) -> &[f64] {
        &self.reduced.m
    }
    fn damping(&self) -> &[f64] {
        &self.reduced.c
    }
    fn stiffness(&self) -> &[f64] {
        &self.reduced.k
    }
    fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        self.nonlinear_samples(x, v, &[theta], out);
    }
    /// `V_Sᵀ g(V_S z, V_S ż, θ)` per sample.
    fn nonlinear_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        let (r, s) = (self.reduced.size, self.s);
        let (xs, vs) = (self.to_dofs(x), self.to_dofs(v));
        let mut g = vec![0.0; theta.len() * s];
        self.local.nonlinear_samples(&xs, &vs, theta, &mut g);
        for (o, gi) in out.chunks_exact_mut(r).zip(g.chunks_exact(s)) {
            for (i, oi) in o.iter_mut().enumerate() {
                *oi = (0..s)
                    .map(|a| at(&self.reduced.at_dofs, a * r + i) * at(gi, a))
                    .sum();
            }
        }
    }
    fn velocity_dependent(&self) -> bool {
        self.local.velocity_dependent()
    }
    /// `[V_Sᵀ G_x V_S | V_Sᵀ G_v V_S]` per sample, `G` the local problem's.
    fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        let (r, s) = (self.reduced.size, self.s);
        let (xs, vs) = (self.to_dofs(x), self.to_dofs(v));
        let mut local = vec![0.0; theta.len() * 2 * s * s];
        self.local
            .nonlinear_jacobian_samples(&xs, &vs, theta, &mut local);
        let vsm = &self.reduced.at_dofs;
        let mut half = vec![0.0; s * r];
        for (out, gl) in dg
            .chunks_exact_mut(2 * r * r)
            .zip(local.chunks_exact(2 * s * s))
        {
            for (o, g) in out.chunks_exact_mut(r * r).zip(gl.chunks_exact(s * s)) {
                // half = G V_S (s×r), o = V_Sᵀ half.
                for a in 0..s {
                    for j in 0..r {
                        if let Some(e) = half.get_mut(a * r + j) {
                            *e = (0..s).map(|b| at(g, a * s + b) * at(vsm, b * r + j)).sum();
                        }
                    }
                }
                for i in 0..r {
                    for j in 0..r {
                        if let Some(e) = o.get_mut(i * r + j) {
                            *e = (0..s)
                                .map(|a| at(vsm, a * r + i) * at(&half, a * r + j))
                                .sum();
                        }
                    }
                }
            }
        }
    }
}

/// One level of the basis: the reduced problem and its monodromies, by
/// the modal splitting ([`ModalHsu`]) where it applies (proportional
/// damping, `g` of positions only, a tolerance on Hsu's steps) and meets
/// the tolerance within the cap, else by Magnus-4.
#[derive(Debug, Clone)]
struct Level {
    reduced: Reduced,
    modal: Option<ModalHsu>,
    magnus: AdaptiveHsu,
}

/// Floquet multipliers of a condensed branch's orbits from a reduced basis
/// grown per orbit (module docs), with the per-orbit error estimates.
#[derive(Debug, Clone)]
pub struct ReducedStability {
    basis: RitzBasis,
    growth: BasisGrowth,
    steps: HsuSteps,
    /// The reduced problem and its Hsu of each block count used so far
    /// (index: blocks − 1).
    levels: Vec<Option<Level>>,
    /// The blocks the next orbit starts from.
    start: usize,
}

impl ReducedStability {
    /// The basis of at most `growth.max_blocks` Krylov blocks for the
    /// nonlinear DOFs of `branch`, Hsu's step counts chosen by `steps`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for a tolerance that is not positive and
    /// finite, a cap below 3 blocks, or a basis that stops growing before its
    /// third block without closing an invariant subspace;
    /// [`HbError::Singular`] (ω = 0) for a singular `K`.
    pub fn new<P: PeriodicProblem>(
        branch: &CondensedBranch<P>,
        growth: BasisGrowth,
        steps: HsuSteps,
    ) -> Result<Self, HbError> {
        if growth.max_blocks < 3 || !(growth.tol > 0.0 && growth.tol.is_finite()) {
            return Err(HbError::InvalidInput(format!(
                "a stability basis needs a positive finite tolerance and a cap of at least 3 \
                 Krylov blocks, got {} and {}",
                growth.tol, growth.max_blocks
            )));
        }
        let basis = RitzBasis::new(branch.structure(), branch.dofs(), growth.max_blocks)?;
        if basis.blocks() < 3 && basis.invariant().is_none() {
            return Err(HbError::InvalidInput(
                "the stability basis stopped growing before its third block".into(),
            ));
        }
        let levels = vec![None; basis.blocks()];
        Ok(Self {
            start: FIRST_BLOCKS.min(basis.blocks()),
            basis,
            growth,
            steps,
            levels,
        })
    }

    /// Basis vectors of the basis the last orbit ended with.
    pub fn basis_size(&self) -> usize {
        self.levels
            .get(self.start.saturating_sub(1))
            .and_then(Option::as_ref)
            .map_or(0, |level| level.reduced.size)
    }

    /// The multipliers of the condensed orbit `q` at ω_f of `branch`: the
    /// basis grows from the previous orbit's blocks by half (at least two)
    /// until the truncation estimate meets the tolerance, the basis closes
    /// an invariant subspace or reaches the cap.
    ///
    /// # Errors
    /// As [`AdaptiveHsu::floquet`]; [`HbError::InvalidInput`] if a level of
    /// the basis cannot be reduced.
    pub fn floquet<P: PeriodicProblem>(
        &mut self,
        branch: &CondensedBranch<P>,
        q: &[f64],
        omega_f: f64,
    ) -> Result<CondensedFloquet, HbError> {
        let last = self.basis.blocks();
        let mut blocks = self.start.min(last);
        let mut seen: Vec<(usize, HsuEstimate)> = Vec::new();
        let (big, truncation_error) = loop {
            let big = self.level_floquet(branch, q, omega_f, blocks, &mut seen)?;
            if blocks == last {
                if let Some(part) = self.basis.invariant() {
                    break (big, part);
                }
            }
            let small = self.level_floquet(branch, q, omega_f, blocks - 1, &mut seen)?;
            let change = multiplier_distance(&big.floquet.multipliers, &small.floquet.multipliers);
            if change <= self.growth.tol || blocks == last || !change.is_finite() {
                break (big, change);
            }
            blocks = (blocks + (blocks / 2).max(2)).min(last);
        };
        self.start = blocks;
        Ok(CondensedFloquet {
            truncation_error,
            hsu_error: HSU_SAFETY * big.error.unwrap_or(0.0),
            basis: self.basis_size(),
            floquet: big.floquet,
        })
    }

    /// The multipliers of `q` on the basis of `blocks` blocks (reused from
    /// `seen` when this orbit had them).
    fn level_floquet<P: PeriodicProblem>(
        &mut self,
        branch: &CondensedBranch<P>,
        q: &[f64],
        omega_f: f64,
        blocks: usize,
        seen: &mut Vec<(usize, HsuEstimate)>,
    ) -> Result<HsuEstimate, HbError> {
        if let Some((_, known)) = seen.iter().find(|(b, _)| *b == blocks) {
            return Ok(known.clone());
        }
        let hb = branch.options();
        let s = branch.dofs().len();
        let local = branch.local();
        let slot = blocks
            .checked_sub(1)
            .and_then(|i| self.levels.get_mut(i))
            .ok_or_else(|| {
                HbError::InvalidInput(format!("no stability basis of {blocks} blocks"))
            })?;
        if slot.is_none() {
            let reduced = self.basis.reduced(blocks, s, local)?;
            let modal = ModalHsu::new(&reduced, hb.harmonics, self.steps);
            let problem = ReducedProblem {
                reduced: &reduced,
                local,
                s,
            };
            let magnus = AdaptiveHsu::new(&problem, hb.harmonics, self.steps)?;
            *slot = Some(Level {
                reduced,
                modal,
                magnus,
            });
        }
        let Level {
            reduced,
            modal,
            magnus: hsu,
        } = slot
            .as_mut()
            .ok_or_else(|| HbError::InvalidInput("stability level missing".into()))?;
        if let Some(modal) = modal {
            let omega = omega_f / hb.subharmonic as f64;
            if let Some(estimate) = modal.floquet(local, q, omega, hb.subharmonic)? {
                seen.push((blocks, estimate.clone()));
                return Ok(estimate);
            }
        }
        let l = 2 * hb.harmonics + 1;
        let r = reduced.size;
        let mut coeffs = vec![0.0; r * l];
        for (i, zi) in coeffs.chunks_exact_mut(l).enumerate() {
            for a in 0..s {
                let w = at(&reduced.lift, i * s + a);
                zi.iter_mut()
                    .zip(row(q, a, l))
                    .for_each(|(z, x)| *z += w * x);
            }
        }
        let sol = HbSolution {
            coeffs,
            omega_f,
            harmonics: hb.harmonics,
            subharmonic: hb.subharmonic,
            stats: Default::default(),
        };
        let problem = ReducedProblem { reduced, local, s };
        let estimate = hsu.floquet(&problem, &sol)?;
        seen.push((blocks, estimate.clone()));
        Ok(estimate)
    }
}

/// Hausdorff distance between the multipliers of modulus ≥ 0.01 of `a`
/// and those of `b` (each to its nearest in the whole other set): the
/// truncation estimate, and the tests' distance to the full system's.
pub fn multiplier_distance(a: &[c64], b: &[c64]) -> f64 {
    let one_way = |x: &[c64], y: &[c64]| {
        x.iter()
            .filter(|z| z.norm() >= COMPARED_MODULUS)
            .map(|z| {
                y.iter()
                    .map(|w| (z - w).norm())
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0f64, f64::max)
    };
    one_way(a, b).max(one_way(b, a))
}
