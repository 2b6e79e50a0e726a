//! Branch switching at a located bifurcation ([`crate::branches::events`]):
//! [`switch_branch`] steps from the bifurcation along a direction transversal to
//! the known branch and corrects onto the new one (the second null vector at a
//! branch point, [`crate::Bifurcation::second_direction`]; at a period doubling
//! the odd-harmonic null vector of the period-2 Galerkin Jacobian,
//! [`period_doubled_start`]).

use crate::branches::events::{dot, Bifurcation, BifurcationError, BifurcationKind, LocateOptions};
use crate::branches::family::{Family, FamilyBranch};
use crate::orbit::ihb::{HbError, HbOptions};
use ivt_num::vector::norm2;
use ivt_num::{newton_bordered, Border, LuWorkspace, NewtonOptions, NewtonWorkspace};
use ivt_path::branch::{full_newton_steps, Branch};
use ivt_path::events::extended::{check_start, null_vector, singular_at_start, BranchWithLambda};

/// A first point on a new branch: Newton on `[R(q, λ); dᵀ(x − x*) − h] = 0`
/// (`x = {q, λ}`) from the predictor `x* + h d`, where `x* = {q, λ}` is the
/// bifurcation and `d` a unit direction (`m + 1` entries) transversal to the
/// known branch. Returns `(q, λ)`.
///
/// # Errors
/// [`BifurcationError::Hb`] for sizes, a singular matrix or non-convergence.
pub fn switch_branch<B: Branch>(
    branch: &mut B,
    q: &[f64],
    lambda: f64,
    direction: &[f64],
    h: f64,
    opts: &LocateOptions,
) -> Result<(Vec<f64>, f64), BifurcationError> {
    check_start(branch, q, lambda)?;
    let m = branch.len();
    let n1 = m + 1;
    if direction.len() != n1 || !(h.is_finite() && h != 0.0) {
        return Err(HbError::InvalidInput(format!(
            "direction must have {n1} entries and h be finite and non-zero"
        ))
        .into());
    }
    let star: Vec<f64> = q.iter().copied().chain([lambda]).collect();
    let mut x: Vec<f64> = star.iter().zip(direction).map(|(s, d)| s + h * d).collect();
    let mut system = BranchWithLambda::new(branch, opts);
    // Full steps until the largest update is below `step_tol` of the
    // largest entry of x (at the predictor).
    let scale = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let nopts = NewtonOptions {
        rtol: 0.0,
        atol: opts.step_tol * scale,
        ..full_newton_steps(0.0, opts.max_iter)
    };
    let border = Border {
        rows: direction,
        values: &[dot(direction, &star) + h],
        origin: &[],
    };
    newton_bordered(
        &mut system,
        border,
        &mut x,
        &mut NewtonWorkspace::bordered(n1, 1),
        &nopts,
    )
    .map_err(|e| BifurcationError::from(HbError::Solve(e)))?;
    let lambda = x.pop().unwrap_or(lambda);
    Ok((x, lambda))
}

/// The period-doubled branch at a located period doubling `pd` of the branch
/// planned with `hb`: the orbit is re-expressed with period 2 (harmonic k → 2k,
/// `2n` harmonics, subharmonic order `2p`, `2N` samples), where the period
/// doubling is a branch point whose new direction is the odd-harmonic null
/// vector of the period-2 Galerkin Jacobian; [`switch_branch`] then steps `h`
/// along it. `family` must be the family of `pd`'s branch. Returns the period-2
/// branch and its first point `(q, λ)`.
///
/// # Errors
/// [`BifurcationError::Hb`] if `pd` is not a period doubling, for sizes, or when
/// the null vector or the corrector fails.
pub fn period_doubled_start<F: Family>(
    family: F,
    hb: &HbOptions,
    pd: &Bifurcation,
    h: f64,
    opts: &LocateOptions,
) -> Result<(FamilyBranch<F>, Vec<f64>, f64), BifurcationError> {
    if pd.kind != BifurcationKind::PeriodDoubling {
        return Err(HbError::InvalidInput("not a period-doubling point".into()).into());
    }
    let n = hb.harmonics;
    let l = 2 * n + 1;
    if !pd.q.len().is_multiple_of(l) {
        return Err(HbError::InvalidInput("orbit size does not match the options".into()).into());
    }
    let mut hb2 = hb.clone();
    hb2.harmonics = 2 * n;
    hb2.n_half = 2 * hb.n_half;
    hb2.subharmonic = 2 * hb.subharmonic;
    let mut branch = FamilyBranch::new(family, &hb2, pd.lambda)?;
    let l2 = 4 * n + 1;
    let q2: Vec<f64> =
        pd.q.chunks_exact(l)
            .flat_map(|c| crate::orbit::aft::embed_subharmonic(c, 2, 2 * n))
            .collect();
    let m2 = q2.len();
    let mut jac = vec![0.0; m2 * m2];
    branch.jacobian(&q2, pd.lambda, &mut jac);
    // Odd harmonics (a_k, b_k, k odd) of every DOF: the period-doubling mode.
    let odd = |i: usize| {
        let k = i % l2;
        let h = if k > 2 * n { k - 2 * n } else { k };
        k != 0 && h % 2 == 1
    };
    let mut v: Vec<f64> = (0..m2).map(|i| if odd(i) { 1.0 } else { 0.0 }).collect();
    // `jac` is singular at the period doubling: only a non-finite factor is refused.
    let mut lu = LuWorkspace::new(m2);
    lu.factor_row_major(&jac);
    if !null_vector(&mut lu, &mut v, false) {
        return Err(HbError::Solve(singular_at_start()).into());
    }
    let mut d: Vec<f64> = v
        .iter()
        .enumerate()
        .map(|(i, vi)| if odd(i) { *vi } else { 0.0 })
        .collect();
    let nd = norm2(&d);
    d.iter_mut().for_each(|x| *x /= nd);
    d.push(0.0);
    let (q, lambda) = switch_branch(&mut branch, &q2, pd.lambda, &d, h, opts)?;
    Ok((branch, q, lambda))
}
