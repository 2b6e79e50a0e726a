//! The dynamic stiffness `D(w) = K − w²M + iwC` of a sparse structure,
//! factored by faer's sparse LU (one symbolic analysis per structure, one
//! numeric factorization per harmonic frequency w), and solved with
//! iterative refinement whose residual is summed in double-double.
//!
//! Why refinement: the stiffness of a fine mesh is ill-conditioned
//! (κ(K) ~ N⁴). Forming `K − w²M` in double rounds each entry at the scale of
//! `K` (1.5e9 for the N = 500 cantilever), where the inertia that decides the
//! response near resonance is ~1e-2: the plain LU solve of the rounded `D`
//! loses ~1e-4 of the tip receptance near ω₁ (measured in
//! `tests/condense.rs`). The residual `b − Kx + w²Mx − iwCx` is instead
//! accumulated from the separately stored `K`, `M`, `C` with error-free
//! products and sums (Ogita, Rump & Oishi, *Accurate sum and dot product*,
//! 2005, Dot2), so each refinement step gains the digits the rounded LU
//! loses, and the size of the last correction estimates the error left.

use super::band::{BandLu, MAX_HALF_BANDWIDTH};
use super::double_double::{Dd, Split, SplitDd};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu as SparseLu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{c64, Mat, MatMut, MatRef};
use ivt_hb::HbError;

/// Units of rounding (ε) per stored entry of `M` and `C` in
/// [`Structure::data_error`]: an assembled entry is a sum of element
/// products (`α·m_e + β·k_e` over two elements: four roundings of ε/2).
pub const DATA_ULPS: f64 = 2.0;

/// Refinement steps at most per solve.
const MAX_REFINEMENTS: usize = 8;

/// Sparse `M`, `C`, `K` on one (union) pattern, with the factorization
/// chosen for it.
#[derive(Debug, Clone)]
pub struct Structure {
    pattern: SymbolicSparseColMat<usize>,
    solver: Solver,
    /// `M`, `C`, `K` all symmetric: `D⁻ᵀ = D⁻¹` (no transposed solves).
    symmetric: bool,
    m: Vec<f64>,
    c: Vec<f64>,
    k: Vec<f64>,
}

/// How `D(w)` is factored: a band LU when the DOFs are numbered along a
/// narrow band (half-bandwidth ≤ [`MAX_HALF_BANDWIDTH`]: the cantilever's
/// is 3), else faer's sparse LU with one symbolic analysis per structure.
#[derive(Debug, Clone)]
enum Solver {
    /// Lower and upper half-bandwidths.
    Band(usize, usize),
    Sparse(SymbolicLu<usize>),
}

/// A numeric factorization of `D(w)`.
#[derive(Debug)]
enum Lu {
    Band(BandLu),
    Sparse(Box<SparseLu<usize, c64>>),
}

impl Lu {
    fn solve_in_place(&self, rhs: MatMut<'_, c64>) {
        match self {
            Self::Band(lu) => lu.solve_in_place(rhs),
            Self::Sparse(lu) => lu.solve_in_place(rhs),
        }
    }

    fn solve_transpose_in_place(&self, rhs: MatMut<'_, c64>) {
        match self {
            Self::Band(lu) => lu.solve_transpose_in_place(rhs),
            Self::Sparse(lu) => lu.solve_transpose_in_place(rhs),
        }
    }
}

/// `D(w)` factored at one frequency, with its entries in double-double for
/// the refinement's residuals.
#[derive(Debug)]
pub struct Factored {
    lu: Lu,
    /// Per pattern entry: `−K + w²M` and `wC`, exact to double-double.
    real: Vec<SplitDd>,
    imag: Vec<SplitDd>,
}

impl Structure {
    /// The structure of `M`, `C`, `K` (square, same size, finite).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for mismatched sizes, non-finite entries or a
    /// failed symbolic analysis.
    pub fn new(
        m: SparseColMatRef<'_, usize, f64>,
        c: SparseColMatRef<'_, usize, f64>,
        k: SparseColMatRef<'_, usize, f64>,
    ) -> Result<Self, HbError> {
        let n = m.nrows();
        let mats = [m, c, k];
        if n == 0 || mats.iter().any(|a| a.nrows() != n || a.ncols() != n) {
            return Err(HbError::InvalidInput(
                "M, C, K must be square, non-empty and of one size".into(),
            ));
        }
        if mats.iter().any(|a| !a.val().iter().all(|v| v.is_finite())) {
            return Err(HbError::InvalidInput(
                "M, C, K have non-finite entries".into(),
            ));
        }
        let mut col_ptr = vec![0usize];
        let mut rows = Vec::new();
        let mut column = Vec::new();
        for j in 0..n {
            column.clear();
            for a in &mats {
                column.extend(a.symbolic().row_idx_of_col_raw(j).iter().copied());
            }
            column.sort_unstable();
            column.dedup();
            rows.extend_from_slice(&column);
            col_ptr.push(rows.len());
        }
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows);
        let values = |a: &SparseColMatRef<'_, usize, f64>| {
            let mut out = vec![0.0; pattern.row_idx().len()];
            for j in 0..n {
                let range = pattern.col_range(j);
                let slots = pattern.row_idx().get(range.clone()).unwrap_or_default();
                let entries = a.symbolic().row_idx_of_col_raw(j).iter();
                for (i, v) in entries.zip(a.val_of_col(j)) {
                    // The union pattern holds every row of every matrix.
                    let slot = slots.binary_search(i).ok();
                    if let Some(o) = slot.and_then(|pos| out.get_mut(range.start + pos)) {
                        *o += v;
                    }
                }
            }
            out
        };
        let (mv, cv, kv) = (values(&m), values(&c), values(&k));
        let (kl, ku) = bandwidths(&pattern);
        let solver =
            if kl.max(ku) <= MAX_HALF_BANDWIDTH {
                Solver::Band(kl, ku)
            } else {
                Solver::Sparse(SymbolicLu::try_new(pattern.as_ref()).map_err(|e| {
                    HbError::InvalidInput(format!("sparse LU analysis failed: {e:?}"))
                })?)
            };
        let symmetric = [&mv, &cv, &kv].iter().all(|v| is_symmetric(&pattern, v));
        Ok(Self {
            pattern,
            solver,
            symmetric,
            m: mv,
            c: cv,
            k: kv,
        })
    }

    /// The structure of `n` DOFs from `(row, col, value)` triplets of `M`, `C`
    /// and `K` (duplicates summed).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for an index out of range, as [`Self::new`]
    /// otherwise.
    pub fn from_triplets(
        n: usize,
        m: &[(usize, usize, f64)],
        c: &[(usize, usize, f64)],
        k: &[(usize, usize, f64)],
    ) -> Result<Self, HbError> {
        let [m, c, k] = [m, c, k].map(|t| {
            if t.iter().any(|&(i, j, _)| i >= n || j >= n) {
                return Err(HbError::InvalidInput(format!(
                    "a matrix index is out of range for {n} DOFs"
                )));
            }
            crate::models::from_triplets(n, t)
        });
        Self::new(m?.as_ref(), c?.as_ref(), k?.as_ref())
    }

    /// Number of DOFs.
    pub fn n_dof(&self) -> usize {
        self.pattern.nrows()
    }

    /// Whether `M`, `C`, `K` are symmetric (then `D(w)` is complex symmetric).
    pub fn is_symmetric(&self) -> bool {
        self.symmetric
    }

    /// Factors `D(w) = K − w²M + iwC` (rounded to double entry by entry).
    ///
    /// # Errors
    /// [`HbError::Singular`] (with `omega = w`) when the numeric LU fails.
    pub fn factor(&self, w: f64) -> Result<Factored, HbError> {
        let vals = (self.k.iter().zip(&self.m).zip(&self.c))
            .map(|((k, m), c)| c64::new(k - w * w * m, w * c));
        let lu = match &self.solver {
            Solver::Band(kl, ku) => {
                let entries = entries(&self.pattern)
                    .zip(vals)
                    .map(|((i, j), v)| (i, j, v));
                Lu::Band(BandLu::factor(self.n_dof(), (*kl, *ku), entries, w)?)
            }
            Solver::Sparse(symbolic) => {
                let vals: Vec<c64> = vals.collect();
                let d = SparseColMatRef::new(self.pattern.as_ref(), &vals);
                Lu::Sparse(Box::new(
                    SparseLu::try_new_with_symbolic(symbolic.clone(), d)
                        .map_err(|_| HbError::Singular { omega: w })?,
                ))
            }
        };
        let w2 = Dd::product(w, w);
        let real = self
            .m
            .iter()
            .zip(&self.k)
            .map(|(&m, &k)| SplitDd::from(w2.scale(m).add(-k)))
            .collect();
        let imag = self
            .c
            .iter()
            .map(|&c| SplitDd::from(Dd::product(w, c)))
            .collect();
        Ok(Factored { lu, real, imag })
    }

    /// Solves `D(w) X = B` in place (`rhs` = B on entry) by the LU of `factored`
    /// and iterative refinement with compensated residuals. Returns the
    /// estimated relative error of the columns (largest over them): the
    /// relative size of the last correction, or infinity if the iteration
    /// diverged or produced non-finite values.
    pub fn solve_refined(&self, factored: &Factored, rhs: MatMut<'_, c64>) -> f64 {
        self.refine(factored, rhs).error
    }

    /// [`Self::solve_refined`], reporting also the relative size of the
    /// first correction: the plain LU's own error on these columns.
    pub(crate) fn refine(&self, factored: &Factored, mut rhs: MatMut<'_, c64>) -> Refinement {
        let b = rhs.to_owned();
        factored.lu.solve_in_place(rhs.as_mut());
        let mut r = Mat::<c64>::zeros(b.nrows(), b.ncols());
        // The first correction measures the LU's error e₀ (relative to x);
        // each step multiplies the error by ρ ≈ the observed ratio of
        // successive corrections (ρ ≈ e₀ for the first), so the error after
        // a correction of size d is about ρ·d.
        let mut prev = 1.0;
        let mut first = None;
        let done = |error: f64, first: Option<f64>| Refinement {
            error,
            plain_error: first.unwrap_or(error),
        };
        for _ in 0..MAX_REFINEMENTS {
            self.residual(factored, b.as_ref(), rhs.as_ref(), r.as_mut());
            factored.lu.solve_in_place(r.as_mut());
            let size = relative_size(r.as_ref(), rhs.as_ref());
            if !size.is_finite() {
                return done(f64::INFINITY, Some(f64::INFINITY));
            }
            let first = *first.get_or_insert(size);
            if size > 0.5 * prev {
                // No contraction (rounding level reached, or divergence):
                // keep the iterate, report the correction as the error.
                return done(size.max(f64::EPSILON), Some(first));
            }
            rhs += &r;
            let left = size * (size / prev);
            prev = size;
            if left <= 2.0 * f64::EPSILON {
                return done(left.max(f64::EPSILON), Some(first));
            }
        }
        done(prev, first)
    }

    /// `X = D(w)⁻¹ B` in place by the LU alone (no refinement): what the
    /// refinement starts from, and enough where only a size is wanted.
    pub fn solve_plain(&self, factored: &Factored, rhs: MatMut<'_, c64>) {
        factored.lu.solve_in_place(rhs);
    }

    /// `X = D(w)⁻ᵀ B` in place, without refinement (the transposed solves
    /// enter only derivatives in ω).
    pub fn solve_transpose(&self, factored: &Factored, rhs: MatMut<'_, c64>) {
        factored.lu.solve_transpose_in_place(rhs);
    }

    /// `out = A x` for the stored `M`, `C` or `K` (`part`) and a real `x`
    /// (`n_dof` each): the products of the reduced bases.
    pub fn times(&self, part: Part, x: &[f64], out: &mut [f64]) {
        let values = match part {
            Part::Mass => &self.m,
            Part::Damping => &self.c,
            Part::Stiffness => &self.k,
        };
        out.fill(0.0);
        for ((i, j), a) in entries(&self.pattern).zip(values) {
            if let (Some(o), Some(xj)) = (out.get_mut(i), x.get(j)) {
                *o += a * xj;
            }
        }
    }

    /// The first-order relative change of the receptances `x_a = X[dofs[a], a]`
    /// (`X = D(w)⁻¹ E_S`, the columns of `x`) when each stored entry of `M`
    /// and `C` moves by [`DATA_ULPS`] units of rounding:
    /// `δH_aa ≤ DATA_ULPS·ε Σ_ij |X_ia| (w²|M_ij| + w|C_ij|) |X_ja|` (with
    /// `D⁻ᵀ = D⁻¹`; for a non-symmetric structure the same sum is taken as
    /// the estimate). What rounding the element formulas into the stored
    /// matrices moves: the model's own data error, which no solver of the
    /// stored matrices removes. `K` counts as exact (the cantilever's are
    /// integers): its rounding would weigh κ(K)·ε.
    pub fn data_error(&self, w: f64, x: MatRef<'_, c64>, dofs: &[usize]) -> f64 {
        if w == 0.0 {
            return 0.0;
        }
        let rows = self.pattern.row_idx();
        let mut worst = 0.0f64;
        let mut size = vec![0.0; self.n_dof()];
        for (a, &d) in dofs.iter().enumerate().take(x.ncols()) {
            size.iter_mut()
                .zip(x.col(a).iter())
                .for_each(|(s, z)| *s = z.norm());
            let mut sum = 0.0;
            for (j, sj) in size.iter().enumerate() {
                let range = self.pattern.col_range(j);
                let entries = rows.get(range.clone()).into_iter().flatten();
                let weights = self.m.get(range.clone()).into_iter().flatten();
                let damping = self.c.get(range).into_iter().flatten();
                for ((&i, m), c) in entries.zip(weights).zip(damping) {
                    let si = size.get(i).copied().unwrap_or(0.0);
                    sum += si * (w * w * m.abs() + w * c.abs()) * sj;
                }
            }
            let h = size.get(d).copied().unwrap_or(0.0);
            let rel = DATA_ULPS * f64::EPSILON * sum / h;
            worst = worst.max(if rel.is_nan() { f64::INFINITY } else { rel });
        }
        worst
    }

    /// `out = (−2wM + iC) X`: `∂D/∂w` applied to the columns of `x`.
    pub fn apply_derivative(&self, w: f64, x: MatRef<'_, c64>, mut out: MatMut<'_, c64>) {
        out.fill(c64::new(0.0, 0.0));
        self.add_mass_damping(x, out, |m, c| c64::new(-2.0 * w * m, c));
    }

    /// `out += M X`: with [`Self::apply_derivative`], `∂²D/∂w² = −2M` for
    /// the second ω-derivatives of the receptances.
    pub(crate) fn add_mass(&self, x: MatRef<'_, c64>, out: MatMut<'_, c64>) {
        self.add_mass_damping(x, out, |m, _| c64::new(m, 0.0));
    }

    /// `out += A X` with `A_ij = entry(M_ij, C_ij)`, column by column over
    /// the stored columns' contiguous slices.
    fn add_mass_damping(
        &self,
        x: MatRef<'_, c64>,
        mut out: MatMut<'_, c64>,
        entry: impl Fn(f64, f64) -> c64,
    ) {
        let n = self.n_dof();
        let (col_ptr, rows) = (self.pattern.col_ptr(), self.pattern.row_idx());
        let mut acc = vec![c64::new(0.0, 0.0); n];
        for col in 0..x.ncols().min(out.ncols()) {
            acc.iter_mut()
                .zip(out.as_ref().col(col).iter())
                .for_each(|(a, b)| *a = *b);
            for (xj, bounds) in x.col(col).iter().zip(col_ptr.windows(2)) {
                let &[start, end] = bounds else { continue };
                let stored = rows.get(start..end).unwrap_or_default().iter();
                let m = self.m.get(start..end).unwrap_or_default();
                let c = self.c.get(start..end).unwrap_or_default();
                for ((&i, &m), &c) in stored.zip(m).zip(c) {
                    if let Some(a) = acc.get_mut(i) {
                        *a += entry(m, c) * xj;
                    }
                }
            }
            out.as_mut()
                .col_mut(col)
                .iter_mut()
                .zip(&acc)
                .for_each(|(o, a)| *o = *a);
        }
    }

    /// `R = B − (K − w²M + iwC) X`, each entry summed in double-double
    /// (error-free products and sums): the stored `K`, `M`, `C` and `w` enter
    /// exactly (the entries of `factored` are exact double-doubles).
    /// `wC_ij` needs it as much as `K`: `C = αM + βK` cancels on smooth `X`
    /// like `K` does, and rounding `wC_ij` alone cost 1e-7 of the tip
    /// receptance at N = 500.
    fn residual(
        &self,
        factored: &Factored,
        b: MatRef<'_, c64>,
        x: MatRef<'_, c64>,
        mut out: MatMut<'_, c64>,
    ) {
        let n = self.n_dof();
        let mut re = vec![Dd::default(); n];
        let mut im = vec![Dd::default(); n];
        let col_ptr = self.pattern.col_ptr();
        let rows = self.pattern.row_idx();
        for col in 0..x.ncols() {
            for ((r, i), z) in re.iter_mut().zip(im.iter_mut()).zip(b.col(col).iter()) {
                *r = Dd::from(z.re);
                *i = Dd::from(z.im);
            }
            for (xj, bounds) in x.col(col).iter().zip(col_ptr.windows(2)) {
                let range = match bounds {
                    [start, end] => *start..*end,
                    _ => continue,
                };
                // Each x_j split once for all its column's entries.
                let (xr, xi) = (Split::of(xj.re), Split::of(xj.im));
                let entries = rows.get(range.clone()).unwrap_or_default().iter();
                let real = factored.real.get(range.clone()).unwrap_or_default();
                let imag = factored.imag.get(range).unwrap_or_default();
                for ((&i, a), c) in entries.zip(real).zip(imag) {
                    // (−K + w²M) x − iwC x.
                    if let (Some(ri), Some(ii)) = (re.get_mut(i), im.get_mut(i)) {
                        ri.add_split_product(a, xr);
                        ri.add_split_product(c, xi);
                        ii.add_split_product(a, xi);
                        ii.sub_split_product(c, xr);
                    }
                }
            }
            for (i, (r, m)) in re.iter().zip(&im).enumerate() {
                out[(i, col)] = c64::new(r.value(), m.value());
            }
        }
    }
}

/// What [`Structure::refine`] reports.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Refinement {
    /// Estimated relative error left (as [`Structure::solve_refined`]).
    pub(crate) error: f64,
    /// Relative size of the first correction: the error of the plain LU
    /// solve of the same columns.
    pub(crate) plain_error: f64,
}

/// One of the stored matrices of a [`Structure`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// `M`.
    Mass,
    /// `C`.
    Damping,
    /// `K`.
    Stiffness,
}

/// The lower and upper half-bandwidths `(max i − j, max j − i)` of `pattern`.
fn bandwidths(pattern: &SymbolicSparseColMat<usize>) -> (usize, usize) {
    entries(pattern).fold((0, 0), |(kl, ku), (i, j)| {
        (kl.max(i.saturating_sub(j)), ku.max(j.saturating_sub(i)))
    })
}

/// The `(row, column)` of every stored entry of `pattern`, in storage order.
fn entries(pattern: &SymbolicSparseColMat<usize>) -> impl Iterator<Item = (usize, usize)> + '_ {
    (0..pattern.ncols()).flat_map(move |j| {
        let rows = pattern
            .row_idx()
            .get(pattern.col_range(j))
            .unwrap_or_default();
        rows.iter().map(move |&i| (i, j))
    })
}

/// Whether the values `v` on `pattern` form a symmetric matrix.
fn is_symmetric(pattern: &SymbolicSparseColMat<usize>, v: &[f64]) -> bool {
    let rows = pattern.row_idx();
    entries(pattern).zip(v).all(|((i, j), a)| {
        let mirror = pattern.col_range(i);
        let column = rows.get(mirror.clone()).unwrap_or_default();
        match column.binary_search(&j) {
            Ok(q) => v.get(mirror.start + q) == Some(a),
            Err(_) => *a == 0.0,
        }
    })
}

/// `max_col ‖d_col‖∞ / ‖x_col‖∞`.
fn relative_size(d: MatRef<'_, c64>, x: MatRef<'_, c64>) -> f64 {
    let mut worst = 0.0f64;
    for col in 0..d.ncols() {
        let (mut dn, mut xn) = (0.0f64, 0.0f64);
        for i in 0..d.nrows() {
            dn = dn.max(d[(i, col)].norm_sqr());
            xn = xn.max(x[(i, col)].norm_sqr());
        }
        let (dn, xn) = (dn.sqrt(), xn.sqrt());
        let rel = if xn > 0.0 {
            dn / xn
        } else if dn == 0.0 {
            0.0
        } else {
            f64::INFINITY
        };
        worst = worst.max(if rel.is_nan() { f64::INFINITY } else { rel });
    }
    worst
}
