//! The bordered matrix `A = [[J, B], [Cᵀ, D]]` (`J` m×m, `B` m×k, `Cᵀ` k×m,
//! `D` k×k), factored once by dense LU ([`LuWorkspace`]) and then solved,
//! solved transposed and asked for the sign of its determinant, without
//! allocating: the one bordered solver of the workspace.
//!
//! Every extended system of a path engine has this shape (Govaerts,
//! *Numerical Methods for Bifurcations of Dynamical Equilibria*, ch. 3):
//! the pseudo-arclength corrector `[[R_u, R_λ], [tᵀ]]` (thesis Eq. 72), the
//! fold test `[[J, b], [cᵀ, 0]] [v; g] = [0; 1]` (`g = 0` exactly where `J`
//! is singular, its gradient from the transposed solve), the branch-point
//! test with two border rows, and Newton on a system with linear constraint
//! rows ([`crate::newton::newton_bordered`]). Building them all through one
//! type keeps one place where the border is laid out and factored.

use crate::lu::LuWorkspace;
use faer::MatRef;
use thiserror::Error;

/// Why a bordered factorization or solve was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum BorderedError {
    /// A block or right-hand side has the wrong length.
    #[error("bordered matrix: {what} has {got} entries, expected {expected}")]
    Size {
        /// Which argument.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length `m` and `k` call for.
        expected: usize,
    },
    /// A pivot is not finite or below `n·ε` of the largest. The factor is
    /// kept: a solve with it still gives the near-null direction that
    /// inverse iteration at a bifurcation wants (check its result for
    /// finiteness).
    #[error("bordered matrix is numerically singular")]
    Singular,
}

/// `[[J, B], [Cᵀ, D]]` of size `(m + k) × (m + k)`, its LU and scratch.
#[derive(Debug, Clone)]
pub struct BorderedLu {
    m: usize,
    k: usize,
    lu: LuWorkspace,
}

fn check(what: &'static str, got: usize, expected: usize) -> Result<(), BorderedError> {
    if got == expected {
        Ok(())
    } else {
        Err(BorderedError::Size {
            what,
            got,
            expected,
        })
    }
}

impl BorderedLu {
    /// Workspace for an `m × m` block `J` with `k` border rows and columns
    /// (`k = 0`: a plain LU of `J`).
    pub fn new(m: usize, k: usize) -> Self {
        Self {
            m,
            k,
            lu: LuWorkspace::new(m + k),
        }
    }

    /// Size `m` of the block `J`.
    pub fn inner_dim(&self) -> usize {
        self.m
    }

    /// Number `k` of border rows (and columns).
    pub fn borders(&self) -> usize {
        self.k
    }

    /// Size `m + k` of the whole matrix.
    pub fn dim(&self) -> usize {
        self.m + self.k
    }

    /// Factors `[[J, B], [Cᵀ, D]]` from row-major blocks: `jac` m×m, `b`
    /// m×k (column `j` of the border is `b[i·k + j]`), `c` k×m (row `j` of
    /// the border is `c[j·m..(j+1)·m]`), `d` k×k.
    ///
    /// # Errors
    /// [`BorderedError::Size`] for a block of the wrong length (nothing is
    /// factored), [`BorderedError::Singular`] for a singular matrix.
    pub fn factor(
        &mut self,
        jac: &[f64],
        b: &[f64],
        c: &[f64],
        d: &[f64],
    ) -> Result<(), BorderedError> {
        let (m, k) = (self.m, self.k);
        check("J", jac.len(), m * m)?;
        check("B", b.len(), m * k)?;
        check("C", c.len(), k * m)?;
        check("D", d.len(), k * k)?;
        let a = &mut self.lu.mat;
        for (i, row) in jac.chunks_exact(m.max(1)).take(m).enumerate() {
            for (j, v) in row.iter().enumerate() {
                a[(i, j)] = *v;
            }
        }
        self.put_borders(b, c, d);
        self.finish()
    }

    /// As [`Self::factor`] with `J` given as a faer matrix (column-major
    /// storage, e.g. an assembled Galerkin Jacobian).
    ///
    /// # Errors
    /// As [`Self::factor`].
    pub fn factor_mat(
        &mut self,
        jac: MatRef<'_, f64>,
        b: &[f64],
        c: &[f64],
        d: &[f64],
    ) -> Result<(), BorderedError> {
        let (m, k) = (self.m, self.k);
        check("J rows", jac.nrows(), m)?;
        check("J columns", jac.ncols(), m)?;
        check("B", b.len(), m * k)?;
        check("C", c.len(), k * m)?;
        check("D", d.len(), k * k)?;
        self.lu
            .mat
            .as_mut()
            .submatrix_mut(0, 0, m, m)
            .copy_from(jac);
        self.put_borders(b, c, d);
        self.finish()
    }

    /// Factors the matrix given by its row blocks: `top = [J, B]` (m rows of
    /// `m + k`, row-major) and `bottom = [Cᵀ, D]` (k rows of `m + k`). The
    /// layout of a Jacobian `∂R/∂(u, λ)` bordered by constraint rows.
    ///
    /// # Errors
    /// As [`Self::factor`].
    pub fn factor_rows(&mut self, top: &[f64], bottom: &[f64]) -> Result<(), BorderedError> {
        let n = self.dim();
        check("[J, B]", top.len(), self.m * n)?;
        check("[Cᵀ, D]", bottom.len(), self.k * n)?;
        let a = &mut self.lu.mat;
        for (i, row) in top
            .chunks_exact(n.max(1))
            .chain(bottom.chunks_exact(n.max(1)))
            .enumerate()
        {
            for (j, v) in row.iter().enumerate() {
                a[(i, j)] = *v;
            }
        }
        self.finish()
    }

    /// B (m rows of k), Cᵀ (k rows of m) and D (k rows of k), row-major, into
    /// the matrix beside J (their sizes are checked by the callers).
    fn put_borders(&mut self, b: &[f64], c: &[f64], d: &[f64]) {
        let (m, k) = (self.m, self.k);
        let a = &mut self.lu.mat;
        for (i, row) in b.chunks_exact(k.max(1)).take(m).enumerate() {
            for (j, v) in row.iter().enumerate() {
                a[(i, m + j)] = *v;
            }
        }
        for (j, row) in c.chunks_exact(m.max(1)).take(k).enumerate() {
            for (i, v) in row.iter().enumerate() {
                a[(m + j, i)] = *v;
            }
        }
        for (i, row) in d.chunks_exact(k.max(1)).take(k).enumerate() {
            for (j, v) in row.iter().enumerate() {
                a[(m + i, m + j)] = *v;
            }
        }
    }

    fn finish(&mut self) -> Result<(), BorderedError> {
        if self.lu.factor() {
            Ok(())
        } else {
            Err(BorderedError::Singular)
        }
    }

    /// Solves `A x = rhs` in place (`m + k` entries) with the last factor.
    ///
    /// # Errors
    /// [`BorderedError::Size`] if `rhs` has not `m + k` entries.
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<(), BorderedError> {
        check("right-hand side", rhs.len(), self.dim())?;
        self.lu.solve(rhs);
        Ok(())
    }

    /// Solves `Aᵀ x = rhs` in place (`m + k` entries) with the last factor:
    /// left null vectors, the gradient of a bordered test function.
    ///
    /// # Errors
    /// As [`Self::solve`].
    pub fn solve_transpose(&mut self, rhs: &mut [f64]) -> Result<(), BorderedError> {
        check("right-hand side", rhs.len(), self.dim())?;
        self.lu.solve_transpose(rhs);
        Ok(())
    }

    /// Sign (±1) of `det A` of the last factored matrix: with `k = 1` and
    /// the border `[R_λ; tᵀ]`, the branch-point test function along a path.
    pub fn det_sign(&self) -> f64 {
        self.lu.det_sign
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Independent reference: Gaussian elimination with partial pivoting
    /// written out on the assembled row-major matrix (allocating, slow,
    /// obvious), returning the solution and the sign of the determinant.
    fn dense_solve(a: &[f64], n: usize, b: &[f64]) -> (Vec<f64>, f64) {
        let mut a = a.to_vec();
        let mut x = b.to_vec();
        let mut sign = 1.0;
        for col in 0..n {
            let piv = (col..n)
                .max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))
                .unwrap();
            if piv != col {
                sign = -sign;
                for j in 0..n {
                    a.swap(col * n + j, piv * n + j);
                }
                x.swap(col, piv);
            }
            sign *= a[col * n + col].signum();
            for i in col + 1..n {
                let f = a[i * n + col] / a[col * n + col];
                for j in col..n {
                    a[i * n + j] -= f * a[col * n + j];
                }
                x[i] -= f * x[col];
            }
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|j| a[i * n + j] * x[j]).sum();
            x[i] = (x[i] - s) / a[i * n + i];
        }
        (x, sign)
    }

    fn transpose(a: &[f64], n: usize) -> Vec<f64> {
        (0..n * n).map(|p| a[(p % n) * n + p / n]).collect()
    }

    /// Random blocks (xorshift, fixed seed) for m = 1, 5, 40 and k = 0, 1,
    /// 2: the bordered solves, transposed solves and determinant sign equal
    /// those of elimination on the assembled matrix to 1e-12 relative, for
    /// all three ways of giving the blocks.
    #[test]
    fn equals_elimination_on_the_assembled_matrix() {
        let mut next = crate::test_rng::uniform(0x9e37_79b9_7f4a_7c15u64);
        for m in [1usize, 5, 40] {
            for k in [0usize, 1, 2] {
                let n = m + k;
                let mut gen = |len: usize| (0..len).map(|_| next()).collect::<Vec<_>>();
                let (jac, b, c, d) = (gen(m * m), gen(m * k), gen(k * m), gen(k * k));
                let rhs = gen(n);
                let mut full = vec![0.0; n * n];
                for i in 0..m {
                    full[i * n..i * n + m].copy_from_slice(&jac[i * m..(i + 1) * m]);
                    for j in 0..k {
                        full[i * n + m + j] = b[i * k + j];
                        full[(m + j) * n + i] = c[j * m + i];
                    }
                }
                for i in 0..k {
                    for j in 0..k {
                        full[(m + i) * n + m + j] = d[i * k + j];
                    }
                }
                let (want, want_sign) = dense_solve(&full, n, &rhs);
                let (want_t, _) = dense_solve(&transpose(&full, n), n, &rhs);
                let scale = want
                    .iter()
                    .chain(&want_t)
                    .fold(1.0f64, |a, v| a.max(v.abs()));
                let mut lu = BorderedLu::new(m, k);
                let jac_mat = faer::Mat::from_fn(m, m, |i, j| jac[i * m + j]);
                for way in 0..3 {
                    match way {
                        0 => lu.factor(&jac, &b, &c, &d).unwrap(),
                        1 => lu.factor_mat(jac_mat.as_ref(), &b, &c, &d).unwrap(),
                        _ => lu.factor_rows(&full[..m * n], &full[m * n..]).unwrap(),
                    }
                    let mut x = rhs.clone();
                    lu.solve(&mut x).unwrap();
                    let mut xt = rhs.clone();
                    lu.solve_transpose(&mut xt).unwrap();
                    for (got, want) in x.iter().zip(&want).chain(xt.iter().zip(&want_t)) {
                        assert!((got - want).abs() <= 1e-12 * scale, "m {m} k {k} way {way}");
                    }
                    assert_eq!(lu.det_sign(), want_sign, "m {m} k {k} way {way}");
                }
            }
        }
    }

    /// The fold test function in closed form: `J = diag(μ, 1)`, `b = c =
    /// e₁`, `D = 0`: `[[J, b], [cᵀ, 0]] [v; g] = [0; 0; 1]` gives `g = −μ`
    /// (so `g` changes sign with the eigenvalue μ), `v = e₁`, and the
    /// determinant `det = −1` for every μ (the border keeps it regular).
    #[test]
    fn fold_test_function_closed_form() {
        for mu in [0.3, 0.0, -2.0] {
            let mut lu = BorderedLu::new(2, 1);
            lu.factor(&[mu, 0.0, 0.0, 1.0], &[1.0, 0.0], &[1.0, 0.0], &[0.0])
                .unwrap();
            let mut x = [0.0, 0.0, 1.0];
            lu.solve(&mut x).unwrap();
            let mut y = [0.0, 0.0, 1.0];
            lu.solve_transpose(&mut y).unwrap();
            for (got, want) in x.iter().chain(&y).zip([1.0, 0.0, -mu, 1.0, 0.0, -mu]) {
                assert!((got - want).abs() <= 1e-15, "μ = {mu}: {x:?} {y:?}");
            }
            assert_eq!(lu.det_sign(), -1.0);
        }
    }

    /// Wrong lengths are typed errors, not panics; an exactly singular
    /// matrix (`b = 0`) reports `Singular`.
    #[test]
    fn sizes_and_singularity_are_errors() {
        let mut lu = BorderedLu::new(2, 1);
        assert!(matches!(
            lu.factor(&[1.0; 3], &[0.0; 2], &[0.0; 2], &[0.0]),
            Err(BorderedError::Size {
                what: "J",
                got: 3,
                expected: 4
            })
        ));
        assert_eq!(
            lu.factor(&[1.0, 0.0, 0.0, 1.0], &[0.0; 2], &[1.0, 0.0], &[0.0]),
            Err(BorderedError::Singular)
        );
        assert!(matches!(
            lu.solve(&mut [0.0; 2]),
            Err(BorderedError::Size { .. })
        ));
        assert!(matches!(
            lu.factor_rows(&[0.0; 5], &[0.0; 3]),
            Err(BorderedError::Size { .. })
        ));
    }
}
