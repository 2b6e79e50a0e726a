//! Floquet multipliers of condensed orbits: the variational equation of the
//! whole structure (Eq. 78 with `g` acting on the DOFs `S` only),
//!
//! `M δẍ + C δẋ + K δx + E_S (G_x(t) E_Sᵀ δx + G_v(t) E_Sᵀ δẋ) = 0`,
//!
//! Galerkin-projected onto a reduced basis `V` and analysed by Hsu's method
//! (Eq. 79–80, [`AdaptiveHsu`]).
//!
//! The basis: the load-dependent Ritz vectors of `S` (Wilson, Yuan & Dickens,
//! *Dynamic analysis by direct superposition of Ritz vectors*, 1982), the
//! block Krylov space of `K⁻¹M` started from the static modes `K⁻¹E_S`,
//! M-orthonormal. It holds the static modes of `S` exactly and converges to
//! the lowest modes as `S` sees them. The time-varying term acts only through
//! `S`, so for proportional damping the modes `S` does not see (zero at `S`)
//! stay uncoupled from the orbit: their multipliers are the linear
//! structure's `exp(λ_j T)` and are not reported. The truncation error is
//! estimated per orbit as the change of the multipliers (|μ| ≥ 0.01) when
//! the basis loses its last two blocks (the spaces are nested, so the change
//! bounds the larger basis's error while the Krylov space converges), plus
//! Hsu's own Richardson estimate.

use super::branch::CondensedBranch;
use super::dynamic::{Part, Structure};
use crate::error::HbError;
use crate::ihb::HbSolution;
use crate::problem::PeriodicProblem;
use crate::stability::{AdaptiveHsu, Floquet, HsuSteps};
use faer::{c64, Mat};
use ivt_num::vector::dot;

/// Multipliers of smaller modulus take no part in the truncation estimate:
/// they are far from deciding stability.
const COMPARED_MODULUS: f64 = 1e-2;

/// The Krylov blocks of the basis when not chosen ([`ReducedStability::new`]).
pub const DEFAULT_BLOCKS: usize = 8;

/// The multipliers of one condensed orbit.
#[derive(Debug, Clone, PartialEq)]
pub struct CondensedFloquet {
    /// Multipliers of the reduced variational equation and their verdict.
    pub floquet: Floquet,
    /// Basis vectors used.
    pub basis: usize,
    /// Estimated error of the multipliers from the basis truncation: the
    /// Hausdorff distance (|μ| ≥ 0.01) to those of the basis two blocks
    /// smaller.
    pub truncation_error: f64,
    /// Hsu's Richardson estimate of the multipliers' error.
    pub hsu_error: f64,
}

impl CondensedFloquet {
    /// The two estimates together: the error the multipliers carry.
    pub fn error_estimate(&self) -> f64 {
        self.truncation_error + self.hsu_error
    }
}

/// The structure's linear part on the first `size` basis vectors.
#[derive(Debug, Clone)]
struct Reduced {
    size: usize,
    /// `VᵀMV`, `VᵀCV`, `VᵀKV` plus the local problem's own matrices
    /// (`V_Sᵀ M_l V_S`, …), row-major `size×size`.
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
    /// `V_S` (rows `S` of `V`), row-major `s×size`.
    at_dofs: Vec<f64>,
    /// `V_Sᵀ (V_S V_Sᵀ)⁻¹`, row-major `size×s`: the reduced coordinates of
    /// least norm with `V_S z = x_S`.
    lift: Vec<f64>,
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

/// Floquet multipliers of a condensed branch's orbits from a reduced basis
/// (module docs), with the per-orbit error estimates.
#[derive(Debug, Clone)]
pub struct ReducedStability {
    /// The basis of `blocks` blocks, then the one two blocks smaller.
    levels: [Reduced; 2],
    hsu: [AdaptiveHsu; 2],
}

impl ReducedStability {
    /// The basis of `blocks` Krylov blocks (at least 3) for the nonlinear DOFs
    /// of `branch`, Hsu's step counts chosen by `steps`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for fewer than 3 blocks, a basis that stops
    /// growing before its third block or an `M` that is not positive
    /// definite on it; [`HbError::Singular`] (ω = 0) for a singular `K`.
    pub fn new<P: PeriodicProblem>(
        branch: &CondensedBranch<P>,
        blocks: usize,
        steps: HsuSteps,
    ) -> Result<Self, HbError> {
        if blocks < 3 {
            return Err(HbError::InvalidInput(format!(
                "a stability basis needs at least 3 Krylov blocks, got {blocks}"
            )));
        }
        let structure = branch.structure();
        let dofs = branch.dofs();
        let (basis, sizes) = krylov_basis(structure, dofs, blocks)?;
        let small = sizes.get(blocks - 2).copied().unwrap_or(0);
        if sizes.len() < 3 || small == 0 {
            return Err(HbError::InvalidInput(
                "the stability basis stopped growing before its third block".into(),
            ));
        }
        let local = branch.local();
        let big = reduce(structure, &basis, dofs, local)?;
        let small = truncate(&big, small, dofs.len(), local)?;
        let n = branch.options().harmonics;
        let hsu_for = |reduced: &Reduced| {
            let problem = ReducedProblem {
                reduced,
                local,
                s: dofs.len(),
            };
            AdaptiveHsu::new(&problem, n, steps)
        };
        let hsu = [hsu_for(&big)?, hsu_for(&small)?];
        Ok(Self {
            levels: [big, small],
            hsu,
        })
    }

    /// Basis vectors of the larger basis.
    pub fn basis_size(&self) -> usize {
        self.levels[0].size
    }

    /// The multipliers of the condensed orbit `q` at ω_f of `branch`.
    ///
    /// # Errors
    /// As [`AdaptiveHsu::floquet`].
    pub fn floquet<P: PeriodicProblem>(
        &mut self,
        branch: &CondensedBranch<P>,
        q: &[f64],
        omega_f: f64,
    ) -> Result<CondensedFloquet, HbError> {
        let hb = branch.options();
        let s = branch.dofs().len();
        let l = 2 * hb.harmonics + 1;
        let mut results = Vec::with_capacity(2);
        for (reduced, hsu) in self.levels.iter().zip(self.hsu.iter_mut()) {
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
            let problem = ReducedProblem {
                reduced,
                local: branch.local(),
                s,
            };
            results.push(hsu.floquet(&problem, &sol)?);
        }
        let [big, small] = results.as_slice() else {
            return Err(HbError::InvalidInput("two stability bases expected".into()));
        };
        Ok(CondensedFloquet {
            truncation_error: multiplier_distance(
                &big.floquet.multipliers,
                &small.floquet.multipliers,
            ),
            hsu_error: big.error.unwrap_or(0.0),
            basis: self.levels[0].size,
            floquet: big.floquet.clone(),
        })
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

/// The M-orthonormal block Krylov basis of `K⁻¹M` from `K⁻¹E_S`, `blocks`
/// blocks (Gram–Schmidt twice per vector; a vector that loses all but 1e-10
/// of its M-norm is dropped), and the basis size after each block.
fn krylov_basis(
    structure: &Structure,
    dofs: &[usize],
    blocks: usize,
) -> Result<(Vec<Vec<f64>>, Vec<usize>), HbError> {
    let n = structure.n_dof();
    let k = structure.factor(0.0)?;
    let solve = |columns: &[Vec<f64>]| -> Result<Vec<Vec<f64>>, HbError> {
        let mut rhs = Mat::<c64>::from_fn(n, columns.len(), |i, j| {
            c64::new(columns.get(j).map_or(0.0, |c| at(c, i)), 0.0)
        });
        let error = structure.solve_refined(&k, rhs.as_mut());
        if !error.is_finite() {
            return Err(HbError::Singular { omega: 0.0 });
        }
        Ok((0..columns.len())
            .map(|j| (0..n).map(|i| rhs[(i, j)].re).collect())
            .collect())
    };
    let units: Vec<Vec<f64>> = dofs
        .iter()
        .map(|&d| (0..n).map(|i| if i == d { 1.0 } else { 0.0 }).collect())
        .collect();
    let mut block = solve(&units)?;
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let mut mass_basis: Vec<Vec<f64>> = Vec::new();
    let mut sizes = Vec::with_capacity(blocks);
    let mut mv = vec![0.0; n];
    for _ in 0..blocks {
        let start = basis.len();
        for mut v in block {
            structure.times(Part::Mass, &v, &mut mv);
            let before = dot(&v, &mv).sqrt();
            for _ in 0..2 {
                for (b, mb) in basis.iter().zip(&mass_basis) {
                    let c = dot(mb, &v);
                    v.iter_mut().zip(b).for_each(|(x, y)| *x -= c * y);
                }
            }
            structure.times(Part::Mass, &v, &mut mv);
            let norm = dot(&v, &mv).sqrt();
            // NaN (an indefinite M) is dropped too.
            if norm > 1e-10 * before {
                v.iter_mut().for_each(|x| *x /= norm);
                mv.iter_mut().for_each(|x| *x /= norm);
                basis.push(v);
                mass_basis.push(mv.clone());
            }
        }
        if basis.len() == start {
            break;
        }
        sizes.push(basis.len());
        block = solve(mass_basis.get(start..).unwrap_or_default())?;
    }
    Ok((basis, sizes))
}

/// The reduced matrices of the whole basis.
fn reduce<P: PeriodicProblem>(
    structure: &Structure,
    basis: &[Vec<f64>],
    dofs: &[usize],
    local: &P,
) -> Result<Reduced, HbError> {
    let r = basis.len();
    let n = structure.n_dof();
    let mut product = vec![0.0; n];
    let mut project = |part: Part| {
        let mut out = vec![0.0; r * r];
        for (j, v) in basis.iter().enumerate() {
            structure.times(part, v, &mut product);
            for (i, u) in basis.iter().enumerate() {
                if let Some(e) = out.get_mut(i * r + j) {
                    *e = dot(u, &product);
                }
            }
        }
        out
    };
    let (m, c, k) = (
        project(Part::Mass),
        project(Part::Damping),
        project(Part::Stiffness),
    );
    let at_dofs: Vec<f64> = dofs
        .iter()
        .flat_map(|&d| basis.iter().map(move |v| at(v, d)))
        .collect();
    let full = Reduced {
        size: r,
        m,
        c,
        k,
        at_dofs,
        lift: Vec::new(),
    };
    truncate(&full, r, dofs.len(), local)
}

/// The leading `size` basis vectors of `full` (its matrices' leading
/// blocks), with the local problem's own matrices added and the lift.
fn truncate<P: PeriodicProblem>(
    full: &Reduced,
    size: usize,
    s: usize,
    local: &P,
) -> Result<Reduced, HbError> {
    let r = full.size;
    let lead = |a: &[f64]| -> Vec<f64> {
        (0..size * size)
            .map(|e| at(a, (e / size) * r + e % size))
            .collect()
    };
    let at_dofs: Vec<f64> = (0..s * size)
        .map(|e| at(&full.at_dofs, (e / size) * r + e % size))
        .collect();
    let (mut m, mut c, mut k) = (lead(&full.m), lead(&full.c), lead(&full.k));
    if full.lift.is_empty() {
        // V_Sᵀ A_l V_S of the local problem's matrices, added once.
        for (out, a) in [
            (&mut m, local.mass()),
            (&mut c, local.damping()),
            (&mut k, local.stiffness()),
        ] {
            for i in 0..size {
                for j in 0..size {
                    let mut sum = 0.0;
                    for x in 0..s {
                        for y in 0..s {
                            sum += at(&at_dofs, x * size + i)
                                * at(a, x * s + y)
                                * at(&at_dofs, y * size + j);
                        }
                    }
                    if let Some(e) = out.get_mut(i * size + j) {
                        *e += sum;
                    }
                }
            }
        }
    }
    // (V_S V_Sᵀ)⁻¹: V_S has full row rank, the static modes of S being in
    // the basis.
    let gram: Vec<f64> = (0..s * s)
        .map(|e| {
            let (a, b) = (e / s, e % s);
            dot(row(&at_dofs, a, size), row(&at_dofs, b, size))
        })
        .collect();
    let inverse = ivt_num::lu::inverse(&gram, s).ok_or_else(|| {
        HbError::InvalidInput("the stability basis does not reach the nonlinear DOFs".into())
    })?;
    let lift = (0..size * s)
        .map(|e| {
            let (i, a) = (e / s, e % s);
            (0..s)
                .map(|b| at(&at_dofs, b * size + i) * at(&inverse, b * s + a))
                .sum()
        })
        .collect();
    Ok(Reduced {
        size,
        m,
        c,
        k,
        at_dofs,
        lift,
    })
}

/// `v[i]`, or 0 past the end.
fn at(v: &[f64], i: usize) -> f64 {
    v.get(i).copied().unwrap_or(0.0)
}

/// Row `i` of the row-major `v` with rows of `len` (empty past the end).
fn row(v: &[f64], i: usize, len: usize) -> &[f64] {
    v.get(i * len..(i + 1) * len).unwrap_or_default()
}
