//! Simple branch points of a periodic-orbit branch `R(q, λ) = 0`: where
//! `[∂R/∂q, ∂R/∂λ]` (m × (m+1)) loses rank, located by Newton on the
//! minimally extended system of [`crate::bifurcation`] with two test
//! functions from the two-column bordering `[[R_x, b], [Cᵀ, 0]]` (one
//! [`ivt_num::BorderedLu`]) and an unfolding `R + μ b = 0`.

use crate::bifurcation::{
    border_null_vectors, check_start, dot, extended_newton, factored, finish, jacobian_blocks,
    lambda_step, put_jacobian, Bifurcation, BifurcationError, BifurcationKind, BifurcationOptions,
    Monodromy,
};
use crate::family::{Family, FamilyBranch};
use crate::fold::{residual_lambda_difference as residual_lambda, Branch};
use crate::ihb::HbError;
use ivt_num::vector::norm2;
use ivt_num::BorderedLu;

/// The two-column bordering of `[R_q, R_λ]` for branch points:
/// `[[R_q, R_λ, b], [c₁ᵀ, 0], [c₂ᵀ, 0]]`, i.e. `J = R_q` bordered by the
/// columns `[R_λ, b]` and the rows `cₜ`.
struct BranchPointTest {
    m: usize,
    /// Border column (m).
    b: Vec<f64>,
    jac: Vec<f64>,
    r_lambda: Vec<f64>,
    /// Border blocks of the bordered LU: columns `[R_λ, b]` (m × 2), rows
    /// (2 × m) and corner (2 × 2).
    cols: Vec<f64>,
    rows: Vec<f64>,
    corner: [f64; 4],
    /// LU of the bordered matrix and a right-hand side (reused across evaluations).
    lu: BorderedLu,
    rhs: Vec<f64>,
    /// The last null-space columns `V` (2 × (m+1)).
    v: [Vec<f64>; 2],
}

impl BranchPointTest {
    /// Borders `b` (m) and the rows `c` (2 × (m+1)); `jac`, `r_lambda` scratch.
    fn new(b: Vec<f64>, c: [Vec<f64>; 2], jac: Vec<f64>, r_lambda: Vec<f64>) -> Self {
        let m = b.len();
        let mut rows = vec![0.0; 2 * m];
        for t in 0..2 {
            rows[t * m..(t + 1) * m].copy_from_slice(&c[t][..m]);
        }
        let corner = [c[0][m], 0.0, c[1][m], 0.0];
        Self {
            m,
            b,
            jac,
            r_lambda,
            cols: vec![0.0; 2 * m],
            rows,
            corner,
            lu: BorderedLu::new(m, 2),
            rhs: vec![0.0; m + 2],
            v: [vec![0.0; m + 1], vec![0.0; m + 1]],
        }
    }

    /// `(g₁, g₂)` at `(q, λ)`; keeps `V` (NaN if singular).
    fn eval<B: Branch>(&mut self, branch: &mut B, q: &[f64], lambda: f64, h: f64, out: &mut [f64]) {
        let m = self.m;
        branch.jacobian(q, lambda, &mut self.jac);
        residual_lambda(branch, q, lambda, h, &mut self.r_lambda);
        for i in 0..m {
            self.cols[2 * i] = self.r_lambda[i];
            self.cols[2 * i + 1] = self.b[i];
        }
        // One factorisation serves both right-hand sides; near-singular
        // pivots are accepted, a non-finite solution is refused.
        if !factored(
            self.lu
                .factor(&self.jac, &self.cols, &self.rows, &self.corner),
        ) {
            out.fill(f64::NAN);
            return;
        }
        for t in 0..2 {
            self.rhs.fill(0.0);
            self.rhs[m + t] = 1.0;
            if self.lu.solve(&mut self.rhs).is_err() || !self.rhs.iter().all(|x| x.is_finite()) {
                out.fill(f64::NAN);
                return;
            }
            out[t] = self.rhs[m + 1];
            self.v[t].copy_from_slice(&self.rhs[..m + 1]);
        }
    }
}

/// Locates the simple branch point nearest the converged orbit `(q0, λ0)` of
/// `branch`, where the followed branch has unit tangent `tangent` (`m + 1`
/// entries, λ last, e.g. the secant between two path points). The result
/// carries the null space of `[R_q, R_λ]` there ([`Bifurcation::second_direction`]).
///
/// # Errors
/// As [`crate::bifurcation::locate_multiplier_crossing`] (no neutral-saddle case).
pub fn locate_branch_point<F: Family>(
    branch: &mut FamilyBranch<F>,
    q0: &[f64],
    lambda0: f64,
    tangent: &[f64],
    opts: &BifurcationOptions,
) -> Result<Bifurcation, BifurcationError> {
    check_start(branch, q0, lambda0)?;
    let m = branch.len();
    if tangent.len() != m + 1 || norm2(tangent) == 0.0 {
        return Err(HbError::InvalidInput(format!(
            "tangent must have {} entries, not all zero",
            m + 1
        ))
        .into());
    }
    // Borders from the augmented matrix [[R_q, R_λ], [tᵀ]] at the start: its
    // near-null vectors are the second branch direction (right) and the
    // unfolding direction (left).
    let n1 = m + 1;
    let (jac, r_lambda) = jacobian_blocks(branch, q0, lambda0, opts);
    let t1: Vec<f64> = tangent.iter().map(|x| x / norm2(tangent)).collect();
    let mut aug = vec![0.0; n1 * n1];
    put_jacobian(&mut aug, n1, &jac, &r_lambda);
    aug[m * n1..].copy_from_slice(&t1);
    let seed: Vec<f64> = (0..n1).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
    let (mut right, mut left) = (seed.clone(), seed);
    border_null_vectors(&aug, &mut right, &mut left)?;
    let along = dot(&right, &t1);
    right.iter_mut().zip(&t1).for_each(|(r, t)| *r -= along * t);
    let nr = norm2(&right);
    right.iter_mut().for_each(|r| *r /= nr);
    let mut b = left[..m].to_vec();
    let nb = norm2(&b);
    b.iter_mut().for_each(|x| *x /= nb);
    let mut test = BranchPointTest::new(b.clone(), [t1, right], jac, r_lambda);
    let h = lambda_step(opts, lambda0);
    let (q, lambda, iterations) = extended_newton(
        branch,
        q0,
        lambda0,
        &[b],
        |br: &mut FamilyBranch<F>, q: &[f64], l: f64, out: &mut [f64]| test.eval(br, q, l, h, out),
        opts,
    )?;
    let mut g = [0.0; 2];
    test.eval(branch, &q, lambda, h, &mut g);
    let null_vectors = orthonormal_pair(&test.v);
    let mut mono = Monodromy::new(branch, lambda, opts.stability_steps)?;
    let multipliers = mono.multipliers(branch, &q, lambda);
    finish(
        branch,
        BifurcationKind::BranchPoint,
        q,
        lambda,
        multipliers,
        null_vectors,
        iterations,
    )
}

/// Gram–Schmidt on two vectors.
fn orthonormal_pair(v: &[Vec<f64>; 2]) -> Vec<Vec<f64>> {
    let mut a = v[0].clone();
    let na = norm2(&a);
    a.iter_mut().for_each(|x| *x /= na);
    let along = dot(&v[1], &a);
    let mut b: Vec<f64> = v[1].iter().zip(&a).map(|(x, y)| x - along * y).collect();
    let nb = norm2(&b);
    b.iter_mut().for_each(|x| *x /= nb);
    vec![a, b]
}
