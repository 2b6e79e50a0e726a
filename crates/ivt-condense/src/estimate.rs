//! The harmonic-truncation error of a condensed orbit: the response of the
//! nonlinear DOFs to the harmonics of `g` beyond the `n` kept,
//! `X_h = −H_SS(hω) G_h` for `h = n+1 ..= min(3n, N−1)` (the spectrum of a cubic
//! `g` of an n-harmonic orbit ends at 3n), the largest relative to the orbit's
//! largest displacement on `S`: the size of what harmonic balance with `n`
//! harmonics leaves out (Krack & Gross §2.4: the residual's omitted
//! harmonics). Every omitted harmonic is needed: on the cantilever at
//! ω = 2.46 the 9th harmonic meets the second mode (22.0 rad/s) and moves the
//! orbit by 2e-8 while the 6th and 7th alone suggest 4e-14. The receptances
//! of these harmonics come from the plain LU (an estimate needs no more).

use super::branch::CondensedBranch;
use faer::{c64, Mat};
use ivt_hb::orbit::aft::Aft;
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::HbError;

/// Estimated relative truncation error of the orbit `q` at ω_f, or 0 when
/// the AFT grid resolves no harmonic above `n` (then nothing can be said:
/// choose `N > 3n`).
///
/// # Errors
/// As [`crate::Structure::factor`] for the omitted harmonics.
pub fn truncation_error<P: PeriodicProblem>(
    branch: &CondensedBranch<P>,
    q: &[f64],
    omega_f: f64,
) -> Result<f64, HbError> {
    let hb = branch.options();
    let (n, n_half, p) = (hb.harmonics, hb.n_half, hb.subharmonic);
    let top = (3 * n).min(n_half - 1);
    if top <= n {
        return Ok(0.0);
    }
    let s = branch.dofs().len();
    let mut small = Aft::new(n, n_half)?;
    let mut wide = Aft::new(n_half - 1, n_half)?;
    let ns = small.n_samples();
    let omega = omega_f / p as f64;
    let (mut xs, mut vs, mut gs) = (vec![0.0; ns * s], vec![0.0; ns * s], vec![0.0; ns * s]);
    let mut column = vec![0.0; ns];
    small.synthesize_states(q, s, 0, 1.0, &mut xs, &mut column);
    if branch.local().velocity_dependent() {
        small.synthesize_states(q, s, 1, omega, &mut vs, &mut column);
    }
    let thetas: Vec<f64> = (0..ns).map(|i| p as f64 * small.tau(i)).collect();
    branch.local().nonlinear_samples(&xs, &vs, &thetas, &mut gs);
    let lw = wide.coeff_len();
    let nw = n_half - 1;
    let mut spectra = vec![0.0; s * lw];
    for (d, spectrum) in spectra.chunks_exact_mut(lw).enumerate() {
        wide.galerkin_state(&gs, s, d, spectrum, &mut column);
    }
    // G_h of local DOF b (0 past the spectrum).
    let at = |b: usize, h: usize| {
        let get = |i: usize| spectra.get(b * lw + i).copied().unwrap_or(0.0);
        c64::new(get(h), -get(nw + h))
    };
    let structure = branch.structure();
    // Harmonics `g` does not excite (to rounding: the even ones of an odd `g`
    // on an odd orbit) need no factorization.
    let size = |h: usize| (0..s).map(|b| at(b, h).norm()).fold(0.0f64, f64::max);
    let largest = (0..=nw).map(size).fold(0.0f64, f64::max);
    let mut worst = 0.0f64;
    for h in (n + 1..=top).filter(|&h| size(h) > 1e-13 * largest) {
        let factored = structure.factor(h as f64 * omega)?;
        let mut u = Mat::<c64>::zeros(structure.n_dof(), s);
        for (b, &d) in branch.dofs().iter().enumerate() {
            u[(d, b)] = c64::new(1.0, 0.0);
        }
        structure.solve_plain(&factored, u.as_mut());
        for &dof in branch.dofs() {
            let row = u.as_ref().row(dof);
            let x: c64 = row.iter().enumerate().map(|(b, ub)| -ub * at(b, h)).sum();
            worst = worst.max(x.norm());
        }
    }
    let scale = xs.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    Ok(if scale > 0.0 { worst / scale } else { worst })
}
