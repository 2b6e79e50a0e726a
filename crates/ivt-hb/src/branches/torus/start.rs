//! The torus born at a Neimark–Sacker point. There the periodic orbit has
//! the multipliers `e^{±iφ}`: the variational equation has the solution
//! `Re[e^{iΩt} p(θ₁)]`, `p` periodic, `Ω = φω₁/2π` (`ω₁ = ω_f/p`). In the
//! torus's harmonics that is a null vector of the block `k₂ = 1` of the
//! torus Jacobian at the orbit (the quasi-periodic Hill matrix at the
//! Floquet exponent `iΩ`: at an orbit `∂g` has no `θ₂` content, so that
//! block couples to no other), found by inverse iteration. Ω is fixed
//! modulo ω₁ (`Ω + jω₁` with harmonics `(k₁ − j, 1)` is the same
//! solution); the angle `φ ∈ (0, π]` makes Ω the slow frequency of the
//! modulation, so that the first frequency carries the forcing's harmonics
//! and the second the modulation's (what a box truncation `|k₁| ≤ h₁`,
//! `|k₂| ≤ h₂` keeps best). The first torus is then one
//! step of [`switch_branch`] (Newton on `[R; dᵀ(x − x*) − h] = 0`) along that
//! direction from the orbit: a torus of amplitude `h`, which fixes its ω_f.

use super::{TorusBranch, TorusOptions};
use crate::branches::events::{BifurcationError, LocateOptions};
use crate::branches::family::Family;
use crate::branches::switching::switch_branch;
use crate::error::HbError;
use faer::c64;
use ivt_num::vector::norm2;
use ivt_num::LuWorkspace;
use ivt_path::branch::Branch;
use ivt_path::events::extended::null_vector;

/// A located Neimark–Sacker point of a periodic branch of the family.
#[derive(Debug, Clone, Copy)]
pub struct NeimarkSackerStart<'a> {
    /// The orbit's coefficients (`n_dof` blocks `[a₀, a₁..aₙ, b₁..bₙ]`).
    pub coeffs: &'a [f64],
    /// Its harmonics `n`.
    pub harmonics: usize,
    /// The family's parameter there.
    pub lambda: f64,
    /// Its Floquet multipliers (a pair `e^{±iφ}` on the unit circle).
    pub multipliers: &'a [c64],
}

/// The torus branch planned at a Neimark–Sacker point and its first point.
pub struct TorusStart<F: Family> {
    /// The torus system (phase condition against the critical direction).
    pub branch: TorusBranch<F>,
    /// The first torus: its unknowns (coefficients, Ω) then λ.
    pub first: Vec<f64>,
    /// Ω at the Neimark–Sacker point (`φω₁/2π + jω₁`).
    pub omega2: f64,
    /// The angle φ ∈ (0, π] of the critical multipliers.
    pub angle: f64,
}

/// The angle φ ∈ (0, π] of the critical pair: the multiplier within 1e-4 of
/// the unit circle with the largest imaginary part.
fn critical_angle(multipliers: &[c64]) -> Option<f64> {
    multipliers
        .iter()
        .filter(|z| (z.norm() - 1.0).abs() < 1e-4 && z.im.abs() > 1e-6)
        .max_by(|a, b| a.im.abs().total_cmp(&b.im.abs()))
        .map(|z| z.im.atan2(z.re).abs())
}

/// The orbit's coefficients as the torus's (harmonic `k` at `(k, 0)`; those
/// beyond the truncation dropped), per DOF.
fn embed<F: Family>(
    branch: &TorusBranch<F>,
    coeffs: &[f64],
    n: usize,
) -> Result<Vec<f64>, HbError> {
    let (nd, l) = (branch.n_dof(), branch.harmonics().coeff_len());
    let h = branch.harmonics().len();
    let l1 = 2 * n + 1;
    if coeffs.len() != nd * l1 {
        return Err(HbError::InvalidInput(format!(
            "the Neimark–Sacker orbit must have {} coefficients ({nd} DOF, n = {n}), got {}",
            nd * l1,
            coeffs.len()
        )));
    }
    let mut out = vec![0.0; nd * l];
    for (block, orbit) in out.chunks_exact_mut(l).zip(coeffs.chunks_exact(l1)) {
        let (Some(b0), Some(o0)) = (block.first_mut(), orbit.first()) else {
            continue;
        };
        *b0 = *o0;
        for k in 1..=n {
            if let Some((i, _)) = branch.harmonics().index(k as i64, 0) {
                let (a, b) = (orbit.get(k).copied(), orbit.get(n + k).copied());
                if let (Some(a), Some(b)) = (a, b) {
                    if let Some(x) = block.get_mut(1 + i) {
                        *x = a;
                    }
                    if let Some(x) = block.get_mut(1 + h + i) {
                        *x = b;
                    }
                }
            }
        }
    }
    Ok(out)
}

/// The rows (and columns) of the coefficients of the harmonics `k₂ = 1`.
fn first_order_rows<F: Family>(branch: &TorusBranch<F>) -> Vec<usize> {
    let (nd, l, h) = (
        branch.n_dof(),
        branch.harmonics().coeff_len(),
        branch.harmonics().len(),
    );
    let ones: Vec<usize> = branch
        .harmonics()
        .iter()
        .enumerate()
        .filter(|(_, k)| k.1 == 1)
        .map(|(i, _)| i)
        .collect();
    (0..nd)
        .flat_map(|d| {
            let ones = &ones;
            ones.iter()
                .map(move |i| d * l + 1 + i)
                .chain(ones.iter().map(move |i| d * l + 1 + h + i))
        })
        .collect()
}

/// A unit null vector of the block `k₂ = 1` of the torus Jacobian at the
/// orbit `orbit` (torus coefficients) with second frequency `omega2`, as a
/// full coefficient vector.
fn critical_direction<F: Family>(
    branch: &mut TorusBranch<F>,
    orbit: &[f64],
    omega2: f64,
    lambda: f64,
) -> Result<Vec<f64>, HbError> {
    let m = branch.len();
    let mut q = orbit.to_vec();
    q.push(omega2);
    let mut jac = vec![0.0; m * m];
    branch.jacobian(&q, lambda, &mut jac);
    let rows = first_order_rows(branch);
    let s = rows.len();
    let mut block = Vec::with_capacity(s * s);
    for &r in &rows {
        for &c in &rows {
            block.push(jac.get(r * m + c).copied().unwrap_or(f64::NAN));
        }
    }
    let mut lu = LuWorkspace::new(s);
    // Singular at the Neimark–Sacker point: only a non-finite factor is refused.
    lu.factor_row_major(&block);
    let mut v: Vec<f64> = (0..s)
        .map(|i| 1.0 / (1.0 + 0.37 * i as f64) + 0.1 * (i as f64).sin())
        .collect();
    if !null_vector(&mut lu, &mut v, false) || !null_vector(&mut lu, &mut v, false) {
        return Err(HbError::InvalidInput(
            "no torus direction at the Neimark–Sacker point (its Hill block is not singular)"
                .into(),
        ));
    }
    let mut full = vec![0.0; branch.coeff_len()];
    for (&r, x) in rows.iter().zip(&v) {
        if let Some(f) = full.get_mut(r) {
            *f = *x;
        }
    }
    Ok(full)
}

/// The torus branch of `family` at the Neimark–Sacker point `ns` and its
/// first torus, `step·‖orbit‖₂` along the critical direction (see the module
/// docs); `locate` bounds the first point's Newton iteration.
///
/// # Errors
/// [`HbError::InvalidInput`] when `ns` has no critical pair on the unit
/// circle, for sizes, or when the Hill block has no null vector;
/// [`TorusBranch::new`]'s; the first point's Newton failure.
pub fn torus_start<F: Family>(
    family: F,
    ns: &NeimarkSackerStart<'_>,
    options: &TorusOptions,
    step: f64,
    locate: &LocateOptions,
) -> Result<TorusStart<F>, HbError> {
    let angle = critical_angle(ns.multipliers).ok_or_else(|| {
        HbError::InvalidInput(
            "not a Neimark–Sacker point: no complex pair of multipliers on the unit circle".into(),
        )
    })?;
    if !(step.is_finite() && step > 0.0) {
        return Err(HbError::InvalidInput(format!(
            "the first step {step} must be finite and > 0"
        )));
    }
    let omega_f = family.at(ns.lambda).1;
    let omega1 = omega_f / options.subharmonic.max(1) as f64;
    let mut branch = TorusBranch::planned(family, options, ns.lambda)?;
    let orbit = embed(&branch, ns.coeffs, ns.harmonics)?;
    let omega2 = angle * omega1 / (2.0 * std::f64::consts::PI);
    let v = critical_direction(&mut branch, &orbit, omega2, ns.lambda)?;
    branch.set_reference(&v)?;
    let mut star = orbit;
    star.push(omega2);
    let mut direction = v;
    direction.extend([0.0, 0.0]);
    let scale = norm2(ns.coeffs).max(f64::MIN_POSITIVE);
    let (q, lambda) = switch_branch(
        &mut branch,
        &star,
        ns.lambda,
        &direction,
        step * scale,
        locate,
    )
    .map_err(|e| match e {
        BifurcationError::Hb(h) => h,
        other => HbError::InvalidInput(other.to_string()),
    })?;
    let mut first = q;
    first.push(lambda);
    Ok(TorusStart {
        branch,
        first,
        omega2,
        angle,
    })
}
