//! Simple branch points of a periodic-orbit branch `R(q, λ) = 0`: where
//! `[∂R/∂q, ∂R/∂λ]` (m × (m+1)) loses rank. On a traced path the test is the
//! sign of `det [[R_q, R_λ], [tᵀ]]` (`t` the tangent), which keeps its sign
//! through a fold where only `det R_q` changes; the locator is Newton on the
//! minimally extended system with two test functions from the two-column
//! bordering `[[R_q, R_λ, b], [Cᵀ, 0]]` (one [`ivt_num::BorderedLu`]) and an
//! unfolding `R + μ b = 0` that makes it square and regular.

use super::multipliers::Monodromy;
use super::BifurcationError;
use crate::branches::family::{Family, FamilyBranch};
use crate::orbit::ihb::HbError;
use ivt_num::vector::norm2;
use ivt_num::BorderedLu;
use ivt_path::branch::{residual_lambda_difference, Branch};
use ivt_path::events::extended::{
    augmented_null_vectors, check_start, extended_newton, factored, finish, jacobian_blocks,
    lambda_step,
};
use ivt_path::events::{
    dot, Bifurcation, BifurcationKind, Detector, LocateOptions, PathSoFar, Start,
};
use ivt_path::PathError;

/// The two-column bordering of `[R_q, R_λ]` for branch points:
/// `[[R_q, R_λ, b], [c₁ᵀ, 0], [c₂ᵀ, 0]]`, i.e. `J = R_q` bordered by the
/// columns `[R_λ, b]` and the rows `cₜ`.
struct BranchPointTest {
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
    /// Borders `b` (m) and the rows `c` (2 × (m+1), λ entry last); `jac`,
    /// `r_lambda` scratch.
    fn new(b: Vec<f64>, c: [&[f64]; 2], jac: Vec<f64>, r_lambda: Vec<f64>) -> Self {
        let m = b.len();
        let split = |c: &[f64]| {
            c.split_last()
                .map_or((0.0, Vec::new()), |(l, q)| (*l, q.to_vec()))
        };
        let ((l1, c1), (l2, c2)) = (split(c[0]), split(c[1]));
        Self {
            b,
            jac,
            r_lambda,
            cols: vec![0.0; 2 * m],
            rows: [c1, c2].concat(),
            corner: [l1, 0.0, l2, 0.0],
            lu: BorderedLu::new(m, 2),
            rhs: vec![0.0; m + 2],
            v: [vec![0.0; m + 1], vec![0.0; m + 1]],
        }
    }

    /// `(g₁, g₂)` at `(q, λ)` into `out`; keeps `V` (NaN if singular).
    fn eval<B: Branch>(&mut self, branch: &mut B, q: &[f64], lambda: f64, h: f64, out: &mut [f64]) {
        branch.jacobian(q, lambda, &mut self.jac);
        residual_lambda_difference(branch, q, lambda, h, &mut self.r_lambda);
        for (col, (r_l, b)) in self
            .cols
            .chunks_exact_mut(2)
            .zip(self.r_lambda.iter().zip(&self.b))
        {
            col.copy_from_slice(&[*r_l, *b]);
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
        let m = self.b.len();
        for (t, (o, v)) in out.iter_mut().zip(self.v.iter_mut()).enumerate() {
            self.rhs.fill(0.0);
            if let Some(e) = self.rhs.get_mut(m + t) {
                *e = 1.0;
            }
            let solved = self.lu.solve(&mut self.rhs).is_ok();
            match (self.rhs.get(..=m), self.rhs.get(m + 1)) {
                (Some(head), Some(&g))
                    if solved
                        && self.rhs.iter().all(|x| x.is_finite())
                        && head.len() == v.len() =>
                {
                    *o = g;
                    v.copy_from_slice(head);
                }
                _ => {
                    out.fill(f64::NAN);
                    return;
                }
            }
        }
    }
}

/// `v / ‖v‖₂` in place.
fn normalize(v: &mut [f64]) {
    let n = norm2(v);
    v.iter_mut().for_each(|x| *x /= n);
}

/// Locates the simple branch point nearest the converged orbit `(q0, λ0)` of
/// `branch`, where the followed branch has unit tangent `tangent` (`m + 1`
/// entries, λ last, e.g. the secant between two path points). The result
/// carries the null space of `[R_q, R_λ]` there ([`Bifurcation::second_direction`]).
///
/// # Errors
/// As [`crate::locate_multiplier_crossing`] (no neutral-saddle case).
pub fn locate_branch_point<F: Family>(
    branch: &mut FamilyBranch<F>,
    q0: &[f64],
    lambda0: f64,
    tangent: &[f64],
    opts: &LocateOptions,
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
    let mut t1 = tangent.to_vec();
    normalize(&mut t1);
    let seed: Vec<f64> = (0..n1).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
    let (mut right, mut left) = (seed.clone(), seed);
    let mut aug = BorderedLu::new(m, 1);
    augmented_null_vectors(&mut aug, (&jac, &r_lambda, &t1), &mut right, &mut left)
        .map_err(PathError::from)?;
    let along = dot(&right, &t1);
    right.iter_mut().zip(&t1).for_each(|(r, t)| *r -= along * t);
    normalize(&mut right);
    left.truncate(m);
    let mut b = left;
    normalize(&mut b);
    let mut test = BranchPointTest::new(b.clone(), [&t1, &right], jac, r_lambda);
    let h = lambda_step(opts, lambda0);
    let (q, lambda, iterations) = extended_newton(
        branch,
        (q0, lambda0),
        &[b],
        |br: &mut FamilyBranch<F>, q: &[f64], l: f64, out: &mut [f64]| test.eval(br, q, l, h, out),
        opts,
    )?;
    let mut g = [0.0; 2];
    test.eval(branch, &q, lambda, h, &mut g);
    let [v1, v2] = test.v;
    let null_vectors = orthonormal_pair(v1, v2);
    let mut mono = Monodromy::new(branch, lambda, opts.stability_steps)?;
    let multipliers = mono.multipliers(branch, &q, lambda);
    Ok(finish(
        branch,
        BifurcationKind::BranchPoint,
        (q, lambda),
        multipliers,
        null_vectors,
        iterations,
    ))
}

/// Gram–Schmidt on two vectors.
fn orthonormal_pair(mut a: Vec<f64>, b: Vec<f64>) -> Vec<Vec<f64>> {
    normalize(&mut a);
    let along = dot(&b, &a);
    let mut b: Vec<f64> = b.iter().zip(&a).map(|(x, y)| x - along * y).collect();
    normalize(&mut b);
    vec![a, b]
}

/// Sign of `det [[R_q, R_λ], [tᵀ]]` (the bordered LU's, [`BorderedLu::det_sign`];
/// NaN where the matrix is not finite, which brackets no event).
fn augmented_sign<F: Family>(
    branch: &mut FamilyBranch<F>,
    (q, lambda): (&[f64], f64),
    t: &[f64],
    opts: &LocateOptions,
) -> f64 {
    let m = q.len();
    let (jac, r_lambda) = jacobian_blocks(branch, q, lambda, opts);
    let Some((corner, row)) = t.split_last() else {
        return f64::NAN;
    };
    let mut aug = BorderedLu::new(m, 1);
    if factored(aug.factor(&jac, &r_lambda, row, std::slice::from_ref(corner))) {
        aug.det_sign()
    } else {
        f64::NAN
    }
}

/// The branch-point event of a traced path: the sign of
/// `det [[R_q, R_λ], [tᵀ]]` from the exact corrector's tangent LU
/// ([`crate::PathPoint::bordered_sign`]) or, after Broyden (no factored
/// bordered matrix), assembled with the secant into the point as `t`.
#[derive(Debug, Clone, Default)]
pub struct BranchPoint {
    opts: LocateOptions,
}

impl BranchPoint {
    /// The detector whose assembled test uses `opts`' difference step.
    pub fn new(opts: &LocateOptions) -> Self {
        Self { opts: opts.clone() }
    }
}

impl<F: Family> Detector<FamilyBranch<F>, BifurcationError> for BranchPoint {
    fn kind(&self) -> BifurcationKind {
        BifurcationKind::BranchPoint
    }

    fn test(&mut self, branch: &mut FamilyBranch<F>, path: &PathSoFar, k: usize) -> f64 {
        if let Some(sign) = path.points.get(k).and_then(|p| p.bordered_sign) {
            return sign;
        }
        let secant = path.secant(k.saturating_sub(1));
        match (path.q_lambda(k), secant) {
            (Some(at), Some(t)) => augmented_sign(branch, at, &t, &self.opts),
            _ => 0.0,
        }
    }

    /// From the start point along the secant to the next point.
    fn locate(&mut self, at: Start<'_, FamilyBranch<F>>) -> Result<Bifurcation, BifurcationError> {
        let (q, lambda) = at.point()?;
        let t = at.path.secant(at.index).ok_or_else(|| {
            HbError::InvalidInput(format!("no secant out of path point {}", at.index))
        })?;
        locate_branch_point(at.branch, q, lambda, &t, at.opts)
    }
}
