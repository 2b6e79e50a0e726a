//! The M-orthonormal basis of the reduction: block Krylov (block Lanczos in
//! shift-invert mode at σ = 0 with full reorthogonalization) of `K⁻¹M` from
//! the static modes `K⁻¹[E_S | F]`, on one sparse Cholesky factorization of
//! `K`, plus any exact solutions the certificate adds; and the projected
//! `VᵀKV`, `VᵀCV` (`VᵀMV = I`).

use crate::double_double::{Dd, Split, SplitDd};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::matmul::sparse_dense_matmul;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::SparseColMatRef;
use faer::{Accum, Mat, MatRef, Par, Side};
use ivt_hb::HbError;

/// A new Krylov vector that keeps at most this part of its M-norm after
/// orthogonalization adds nothing (rounding) and is dropped.
const DROP: f64 = 1e-10;

/// The same for an exact solution at a sample: accurate to rounding, and
/// near a resonance a part of 1e-10 of it moves the receptance by 1e-8
/// (the quality factor 1/(2ζ) = 100 of the plate), so only rounding is
/// dropped.
const DROP_SAMPLE: f64 = 1e-14;

/// The sparse `M`, `C`, `K` of the whole structure.
#[derive(Debug, Clone, Copy)]
pub struct Operators<'a> {
    /// Mass.
    pub m: SparseColMatRef<'a, usize, f64>,
    /// Damping.
    pub c: SparseColMatRef<'a, usize, f64>,
    /// Stiffness.
    pub k: SparseColMatRef<'a, usize, f64>,
}

/// Where a block of the basis came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// The j-th Krylov block (0: the static modes).
    Krylov(usize),
    /// Exact solutions at a sampled frequency.
    Sample,
}

/// The growing basis and its projections.
pub struct KrylovBasis<'a> {
    ops: Operators<'a>,
    llt: Llt<usize, f64>,
    /// `V` block by block, `M V` alike.
    blocks: Vec<Mat<f64>>,
    mass: Vec<Mat<f64>>,
    origin: Vec<Origin>,
    /// `VᵀKV`, `VᵀCV` (`r×r`).
    t: Mat<f64>,
    cv: Mat<f64>,
    /// The static modes `K⁻¹ E_S` (`n×s`), kept for the Craig–Bampton form.
    statics: Mat<f64>,
}

impl<'a> KrylovBasis<'a> {
    /// Factors `K` and starts the basis from `K⁻¹[E_S | loads]` (`loads`:
    /// real load columns, zero ones skipped).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] when `K` is not symmetric positive definite
    /// (the structure is not clamped: give it supports, or use the exact
    /// condensed path) or the sizes do not match.
    pub fn new(ops: Operators<'a>, dofs: &[usize], loads: &[&[f64]]) -> Result<Self, HbError> {
        let n = ops.k.nrows();
        if [ops.m, ops.c, ops.k]
            .iter()
            .any(|a| a.nrows() != n || a.ncols() != n)
        {
            return Err(HbError::InvalidInput(
                "M, C, K must be square and of one size".into(),
            ));
        }
        let spd = || {
            HbError::InvalidInput(
                "the reduction needs a symmetric positive definite K (a clamped structure): \
                 its sparse Cholesky factorization failed"
                    .into(),
            )
        };
        let symbolic = SymbolicLlt::try_new(ops.k.symbolic(), Side::Lower).map_err(|_| spd())?;
        let llt = Llt::try_new_with_symbolic(symbolic, ops.k, Side::Lower).map_err(|_| spd())?;
        let s = dofs.len();
        let live: Vec<&[f64]> = loads
            .iter()
            .copied()
            .filter(|f| f.iter().any(|v| *v != 0.0))
            .collect();
        let mut start = Mat::<f64>::zeros(n, s + live.len());
        for (a, &d) in dofs.iter().enumerate() {
            if d < n {
                start[(d, a)] = 1.0;
            }
        }
        for (b, f) in live.iter().enumerate() {
            for (i, v) in f.iter().enumerate().take(n) {
                start[(i, s + b)] = *v;
            }
        }
        llt.solve_in_place(start.as_mut());
        if !start.col_iter().all(|c| c.iter().all(|v| v.is_finite())) {
            return Err(spd());
        }
        let statics = start.subcols(0, s).to_owned();
        let mut basis = Self {
            ops,
            llt,
            blocks: Vec::new(),
            mass: Vec::new(),
            origin: Vec::new(),
            t: Mat::zeros(0, 0),
            cv: Mat::zeros(0, 0),
            statics,
        };
        basis.add(start, Origin::Krylov(0));
        Ok(basis)
    }

    /// Adds the next Krylov block `K⁻¹ M V_last` (of the last Krylov block);
    /// returns the vectors added (0: the space is invariant).
    pub fn grow(&mut self) -> usize {
        let last = self
            .origin
            .iter()
            .enumerate()
            .rev()
            .find_map(|(i, o)| match o {
                Origin::Krylov(j) => Some((i, *j)),
                Origin::Sample => None,
            });
        let Some((index, j)) = last else { return 0 };
        let Some(mv) = self.mass.get(index) else {
            return 0;
        };
        let mut next = mv.clone();
        self.llt.solve_in_place(next.as_mut());
        self.add(next, Origin::Krylov(j + 1))
    }

    /// Adds the columns of `block` (M-orthogonalized against the basis and
    /// among themselves, rounding dropped); returns how many were kept.
    ///
    /// The vectors are orthonormalized twice (`orthonormal`): a
    /// column that keeps only a small part of its M-norm (an exact solution
    /// at a sample lies nearly in the basis and may keep as little as
    /// `DROP_SAMPLE` = 1e-14 of it) loses
    /// that many digits of its orthogonality to the earlier blocks when it
    /// is normalized; the second pass, on vectors of norm one, restores it.
    /// The projections take `VᵀMV = I`: with one pass, the reduced `C_r` of
    /// `C = αM` was 1.1e-6·α off `αM_r` on the 900-DOF plate with a patch of
    /// ten neighbouring nonlinear DOFs (`tests/reduce.rs`), 3e-5·α on the
    /// 3 k plate's.
    pub fn add(&mut self, block: Mat<f64>, origin: Origin) -> usize {
        let drop = match origin {
            Origin::Krylov(_) => DROP,
            Origin::Sample => DROP_SAMPLE,
        };
        let n = block.nrows();
        let (first, _) = self.orthonormal(block, drop);
        if first.is_empty() {
            return 0;
        }
        let block = Mat::<f64>::from_fn(n, first.len(), |i, j| at(&first, i, j));
        let (kept, kept_mass) = self.orthonormal(block, 0.0);
        if kept.is_empty() {
            return 0;
        }
        let b = kept.len();
        let v = Mat::<f64>::from_fn(n, b, |i, j| at(&kept, i, j));
        let mv = Mat::<f64>::from_fn(n, b, |i, j| at(&kept_mass, i, j));
        let kv = compensated_product(self.ops.k, v.as_ref());
        let cv = compensated_product(self.ops.c, v.as_ref());
        self.t = self.extended(&self.t, &v, &kv);
        self.cv = self.extended(&self.cv, &v, &cv);
        self.blocks.push(v);
        self.mass.push(mv);
        self.origin.push(origin);
        b
    }

    /// The columns of `block` M-orthogonalized against the basis (classical
    /// Gram–Schmidt, twice) and among themselves (twice), normalized, with
    /// their images under `M`; a column left with at most `drop` of its
    /// M-norm is dropped.
    fn orthonormal(&self, mut block: Mat<f64>, drop: f64) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
        let n = block.nrows();
        let before = self.product(self.ops.m, block.as_ref());
        let norms: Vec<f64> = (0..block.ncols())
            .map(|j| dot(block.col(j), before.col(j)).abs().sqrt())
            .collect();
        for _ in 0..2 {
            for (v, mv) in self.blocks.iter().zip(&self.mass) {
                let coeffs = mv.transpose() * &block;
                block -= v * &coeffs;
            }
        }
        let mut kept: Vec<Vec<f64>> = Vec::new();
        let mut kept_mass: Vec<Vec<f64>> = Vec::new();
        for (j, before) in norms.iter().enumerate() {
            let mut v: Vec<f64> = block.col(j).iter().copied().collect();
            for _ in 0..2 {
                for (a, ma) in kept.iter().zip(&kept_mass) {
                    let c: f64 = ma.iter().zip(&v).map(|(x, y)| x * y).sum();
                    v.iter_mut().zip(a).for_each(|(x, y)| *x -= c * y);
                }
            }
            let column = Mat::<f64>::from_fn(n, 1, |i, _| v.get(i).copied().unwrap_or(0.0));
            let mv = self.product(self.ops.m, column.as_ref());
            let norm = dot(column.col(0), mv.col(0)).abs().sqrt();
            if norm.is_finite() && norm > drop * before && norm > 0.0 {
                kept.push(v.iter().map(|x| x / norm).collect());
                kept_mass.push(mv.col(0).iter().map(|x| x / norm).collect());
            }
        }
        (kept, kept_mass)
    }

    /// `[[A, Vᵀ X], [Xᵀ V, Wᵀ X]]` symmetrized: the projection `A` of an
    /// operator extended by the new vectors `W` with images `X`.
    fn extended(&self, a: &Mat<f64>, w: &Mat<f64>, x: &Mat<f64>) -> Mat<f64> {
        let (r, b) = (a.nrows(), w.ncols());
        let mut out = Mat::<f64>::zeros(r + b, r + b);
        out.as_mut().submatrix_mut(0, 0, r, r).copy_from(a);
        let mut row = 0;
        for v in &self.blocks {
            let cross = v.transpose() * x;
            for i in 0..cross.nrows() {
                for j in 0..b {
                    out[(row + i, r + j)] = cross[(i, j)];
                    out[(r + j, row + i)] = cross[(i, j)];
                }
            }
            row += v.ncols();
        }
        let own = w.transpose() * x;
        for i in 0..b {
            for j in 0..b {
                out[(r + i, r + j)] = 0.5 * (own[(i, j)] + own[(j, i)]);
            }
        }
        out
    }

    /// `A X` for a sparse operator.
    fn product(&self, a: SparseColMatRef<'_, usize, f64>, x: MatRef<'_, f64>) -> Mat<f64> {
        let mut out = Mat::<f64>::zeros(a.nrows(), x.ncols());
        sparse_dense_matmul(out.as_mut(), Accum::Replace, a, x, 1.0, Par::Seq);
        out
    }

    /// Basis vectors.
    pub fn size(&self) -> usize {
        self.blocks.iter().map(|b| b.ncols()).sum()
    }

    /// Krylov blocks.
    pub fn krylov_blocks(&self) -> usize {
        self.origin
            .iter()
            .filter(|o| matches!(o, Origin::Krylov(_)))
            .count()
    }

    /// `VᵀKV`.
    pub fn stiffness(&self) -> &Mat<f64> {
        &self.t
    }

    /// `VᵀCV`.
    pub fn damping(&self) -> &Mat<f64> {
        &self.cv
    }

    /// The basis indices without the last Krylov block (the nested basis of
    /// the estimates), or all of them when there is one Krylov block only.
    pub fn without_last_block(&self) -> Vec<usize> {
        let last = self
            .origin
            .iter()
            .rposition(|o| matches!(o, Origin::Krylov(j) if *j > 0));
        let mut out = Vec::with_capacity(self.size());
        let mut start = 0;
        for (b, v) in self.blocks.iter().enumerate() {
            if Some(b) != last {
                out.extend(start..start + v.ncols());
            }
            start += v.ncols();
        }
        out
    }

    /// Rows `dofs` of `V` (`len × r`).
    pub fn rows(&self, dofs: &[usize]) -> Mat<f64> {
        let mut out = Mat::<f64>::zeros(dofs.len(), self.size());
        let mut start = 0;
        for v in &self.blocks {
            for (a, &d) in dofs.iter().enumerate() {
                if d < v.nrows() {
                    for j in 0..v.ncols() {
                        out[(a, start + j)] = v[(d, j)];
                    }
                }
            }
            start += v.ncols();
        }
        out
    }

    /// `Vᵀ x` for the columns of `x` (`r × cols`).
    pub fn project(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        let mut out = Mat::<f64>::zeros(self.size(), x.ncols());
        let mut start = 0;
        for v in &self.blocks {
            let part = v.transpose() * x;
            out.as_mut()
                .submatrix_mut(start, 0, v.ncols(), x.ncols())
                .copy_from(&part);
            start += v.ncols();
        }
        out
    }

    /// The coordinates of the static modes `K⁻¹E_S` in the basis,
    /// `Vᵀ M K⁻¹ E_S` (`r × s`; exact, the static modes being in it).
    pub fn static_coordinates(&self) -> Mat<f64> {
        let mut out = Mat::<f64>::zeros(self.size(), self.statics.ncols());
        let mut start = 0;
        for mv in &self.mass {
            let part = mv.transpose() * &self.statics;
            out.as_mut()
                .submatrix_mut(start, 0, mv.ncols(), self.statics.ncols())
                .copy_from(&part);
            start += mv.ncols();
        }
        out
    }

    /// `V G` (`n × cols`) for coefficients `g` (`r × cols`).
    pub fn combine(&self, g: MatRef<'_, f64>) -> Mat<f64> {
        let n = self.statics.nrows();
        let mut out = Mat::<f64>::zeros(n, g.ncols());
        let mut start = 0;
        for v in &self.blocks {
            out += v * g.subrows(start, v.ncols());
            start += v.ncols();
        }
        out
    }
}

/// `A X` with every entry summed in double-double (error-free products and
/// sums) and rounded once: the stiffness of a fine mesh applied to a smooth
/// vector cancels, and in double its product carries an error of
/// ε·|K||x|, ε·κ(K) relative (1e-10 of the 3 k plate's first eigenvalue
/// in `VᵀKV`, which its resonance amplifies by 1/(2ζ) in the receptance).
fn compensated_product(a: SparseColMatRef<'_, usize, f64>, x: MatRef<'_, f64>) -> Mat<f64> {
    let n = a.nrows();
    let mut out = Mat::<f64>::zeros(n, x.ncols());
    let mut acc = vec![Dd::default(); n];
    for col in 0..x.ncols() {
        acc.iter_mut().for_each(|v| *v = Dd::default());
        for j in 0..a.ncols().min(x.nrows()) {
            let xj = Split::of(x[(j, col)]);
            let rows = a.symbolic().row_idx_of_col_raw(j);
            for (&i, &v) in rows.iter().zip(a.val_of_col(j)) {
                if let Some(slot) = acc.get_mut(i) {
                    slot.add_split_product(&SplitDd::from(Dd::from(v)), xj);
                }
            }
        }
        for (i, v) in acc.iter().enumerate() {
            out[(i, col)] = v.value();
        }
    }
    out
}

/// `xᵀ y` of two columns.
fn dot(x: faer::ColRef<'_, f64>, y: faer::ColRef<'_, f64>) -> f64 {
    x.iter().zip(y.iter()).map(|(a, b)| a * b).sum()
}

/// Entry `i` of column `j` of `cols` (0 past the end).
fn at(cols: &[Vec<f64>], i: usize, j: usize) -> f64 {
    cols.get(j).and_then(|c| c.get(i)).copied().unwrap_or(0.0)
}
