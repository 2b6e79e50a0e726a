//! The Broyden solver's `H = B⁻¹` in factored form: a base (dense, or the
//! [`BlockDiagonal`] `H₀` of a linear Jacobian) plus the untracked rank-one
//! updates as factor pairs, `H = base + Σ_j p_j q_jᵀ`. A product with `H` or
//! `Hᵀ` then costs the base's product plus O(rank·m), and an update O(m) to
//! store: with a block-diagonal base an iteration of a one-shot solve needs no
//! O(m²) pass at all. The dense matrix is formed only when someone reads it.

use std::slice::{ChunksExact, ChunksExactMut};

use crate::vector::{axpy, dot, matvec};

use super::BlockDiagonal;

/// Most stored updates on a block-diagonal base (then folded into the dense
/// matrix): each product with `H` costs 2·rank·m beyond the base, against the
/// m² of a dense one.
fn max_rank(m: usize) -> usize {
    (m / 4).clamp(2, 16)
}

/// `H` as base plus factor pairs (see the module doc).
#[derive(Debug, Clone)]
pub(super) struct InverseJacobian {
    m: usize,
    /// The dense `H` (the base when `blocks_active` is off).
    dense: Vec<f64>,
    /// The base when `blocks_active` is on (`dense` is then stale).
    blocks: BlockDiagonal,
    blocks_active: bool,
    /// The pairs `[p₀, q₀, p₁, q₁, …]`, each of length `m`.
    low_rank: Vec<f64>,
}

impl InverseJacobian {
    /// A zero `m×m` matrix, dense.
    pub(super) fn new(m: usize) -> Self {
        Self {
            m,
            dense: vec![0.0; m * m],
            blocks: BlockDiagonal::default(),
            blocks_active: false,
            low_rank: Vec::new(),
        }
    }

    /// The dense matrix for writing all of it (the factored form is dropped).
    pub(super) fn overwrite(&mut self) -> &mut [f64] {
        self.blocks_active = false;
        self.low_rank.clear();
        &mut self.dense
    }

    /// Sets `H = h0` (a copy of the blocks; nothing dense is written).
    pub(super) fn set_blocks(&mut self, h0: &BlockDiagonal) {
        self.blocks.clone_from(h0);
        self.blocks_active = true;
        self.low_rank.clear();
    }

    /// The dense matrix, current (folds the factored form into it).
    pub(super) fn dense(&mut self) -> &mut [f64] {
        let m = self.m;
        if self.blocks_active {
            self.blocks.to_dense(&mut self.dense);
            self.blocks_active = false;
        }
        for pq in self.low_rank.chunks_exact(2 * m.max(1)) {
            let (p, q) = pq.split_at(m);
            for (pi, hrow) in p.iter().zip(rows_mut(&mut self.dense, m)) {
                axpy(*pi, q, hrow);
            }
        }
        self.low_rank.clear();
        &mut self.dense
    }

    /// `out = H v`.
    pub(super) fn mul(&self, v: &[f64], out: &mut [f64]) {
        let m = self.m;
        if self.blocks_active {
            self.blocks.mul(v, out);
        } else {
            simd(|| matvec(&self.dense, m, m, v, out));
        }
        for pq in self.low_rank.chunks_exact(2 * m.max(1)) {
            let (p, q) = pq.split_at(m);
            axpy(dot(q, v), p, out);
        }
    }

    /// `out = Hᵀ v`.
    pub(super) fn mul_transpose(&self, v: &[f64], out: &mut [f64]) {
        let m = self.m;
        if self.blocks_active {
            self.blocks.mul_transpose(v, out);
        } else {
            out.fill(0.0);
            simd(|| {
                for (vi, hrow) in v.iter().zip(rows(&self.dense, m)) {
                    axpy(*vi, hrow, out);
                }
            });
        }
        for pq in self.low_rank.chunks_exact(2 * m.max(1)) {
            let (p, q) = pq.split_at(m);
            axpy(dot(p, v), q, out);
        }
    }

    /// The base is the dense matrix (not block-diagonal).
    pub(super) fn is_dense(&self) -> bool {
        !self.blocks_active
    }

    /// `out += a·H e_j` on a dense base (column `j` read row by row, then the
    /// pairs' `p·q_j`); nothing on a block-diagonal base (see [`Self::is_dense`]).
    pub(super) fn axpy_column(&self, j: usize, a: f64, out: &mut [f64]) {
        let m = self.m;
        if self.blocks_active {
            return;
        }
        for (o, hrow) in out.iter_mut().zip(rows(&self.dense, m)) {
            *o += a * hrow.get(j).copied().unwrap_or(f64::NAN);
        }
        for pq in self.low_rank.chunks_exact(2 * m.max(1)) {
            let (p, q) = pq.split_at(m);
            axpy(a * q.get(j).copied().unwrap_or(f64::NAN), p, out);
        }
    }

    /// `H ← H + p qᵀ`: stored as a pair while the base is block-diagonal and
    /// fewer than [`max_rank`] pairs are stored, else applied to the dense
    /// matrix (with a dense base, pairs would make every product dearer).
    pub(super) fn add_rank_one(&mut self, p: impl Iterator<Item = f64>, q: &[f64]) {
        let m = self.m;
        if self.blocks_active && self.low_rank.len() < 2 * max_rank(m) * m {
            self.low_rank.extend(p.take(m));
            self.low_rank.extend_from_slice(q);
            return;
        }
        let dense = self.dense();
        simd(|| {
            for (pi, hrow) in p.zip(rows_mut(dense, m)) {
                axpy(pi, q, hrow);
            }
        });
    }
}

/// Runs `kernel` compiled for the widest SIMD instructions the CPU has
/// (AVX2 on most x86-64; the loops inside are inlined there and vectorized):
/// the dense products and updates of `H` are a third of a continuation's time.
#[inline(always)]
fn simd<R>(kernel: impl FnOnce() -> R) -> R {
    pulp::Arch::new().dispatch(kernel)
}

/// The rows of the row-major `m×m` matrix `a` (none when `m = 0`, where
/// `chunks_exact` would refuse the size).
pub(super) fn rows(a: &[f64], m: usize) -> ChunksExact<'_, f64> {
    a.chunks_exact(m.max(1))
}

/// Mutable [`rows`].
pub(super) fn rows_mut(a: &mut [f64], m: usize) -> ChunksExactMut<'_, f64> {
    a.chunks_exact_mut(m.max(1))
}
