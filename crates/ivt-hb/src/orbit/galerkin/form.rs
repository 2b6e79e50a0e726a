//! The nonlinear part of the bilinear form `wᵀΦ_q v` of the Galerkin Jacobian
//! (Eq. 56) sampled on the AFT grid, without assembling `Φ_q`, and its gradient
//! in `q`: the fold test of [`crate::FamilyBranch`].
//!
//! Slice lengths are the callers' contract; a slice of the wrong length is not a
//! panic: the value (and gradient) is NaN, which the solvers report as
//! [`crate::HbError::NonFinite`].

use crate::orbit::ihb::HbResidual;
use crate::problem::PeriodicProblem;

/// The nonlinear part of `wᵀΦ_q v` without assembling `Φ_q` (the fold test of
/// [`crate::FamilyBranch`]), and its gradient in `q`, with all scratch.
#[derive(Debug, Clone)]
pub(crate) struct GalerkinForm {
    /// `n_dof ≥ 1` (an [`HbResidual`] holds at least one DOF).
    n_dof: usize,
    /// Coefficients per DOF, `2n + 1 ≥ 1`.
    l: usize,
    p: f64,
    velocity: bool,
    basis: Vec<f64>,
    thetas: Vec<f64>,
    /// Sample-major (`2N·n_dof`): the orbit `x`, `ẋ`, the syntheses `w̃`, `ṽ`, `ṽ'`,
    /// and a displaced copy of `x` or `ẋ`.
    xs: Vec<f64>,
    vs: Vec<f64>,
    wt: Vec<f64>,
    vt: Vec<f64>,
    vdt: Vec<f64>,
    moved: Vec<f64>,
    dg: Vec<f64>,
    /// Per sample: ψᵢ at the orbit and displaced ±, the difference steps.
    at: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    steps: Vec<f64>,
}

/// `w̃`, `ṽ`, `ṽ'` sampled: the vectors of one bilinear form.
struct Syntheses<'a> {
    wt: &'a [f64],
    vt: &'a [f64],
    vdt: &'a [f64],
}

impl GalerkinForm {
    /// Scratch for `res`'s size and the problem it evaluates.
    pub(crate) fn new<P: PeriodicProblem>(res: &HbResidual, problem: &P) -> Self {
        let (nd, n, ns) = (res.n_dof(), res.harmonics(), res.n_samples());
        let p = res.subharmonic() as f64;
        let states = vec![0.0; ns * nd];
        Self {
            n_dof: nd.max(1),
            l: 2 * n + 1,
            p,
            velocity: problem.velocity_dependent(),
            basis: quadrature_basis(n, ns),
            thetas: (0..ns)
                .map(|i| p * 2.0 * std::f64::consts::PI * i as f64 / ns as f64)
                .collect(),
            xs: states.clone(),
            vs: states.clone(),
            wt: states.clone(),
            vt: states.clone(),
            vdt: states.clone(),
            moved: states,
            dg: vec![0.0; 2 * ns * nd * nd],
            at: vec![0.0; ns],
            plus: vec![0.0; ns],
            minus: vec![0.0; ns],
            steps: vec![0.0; ns],
        }
    }

    /// The nonlinear part of `wᵀJv`: `(2/2N) Σᵢ ψᵢ` with
    /// `ψᵢ = w̃ᵀ(G_x ṽ + ω G_v ṽ')` at sample τᵢ (`w̃`, `ṽ`, `ṽ'` the syntheses of
    /// `w`, `v` and `v'`, Eq. 56's sum). With `grad`, also its gradient in `q`:
    /// `∂ψᵢ/∂x`, `∂ψᵢ/∂ẋ` by central differences of `∂g` (steps relative to the
    /// orbit's scale) projected back on the basis — O(2N·m), where differencing
    /// assembled Jacobians would cost 2m assemblies. `∂g` is taken at all samples
    /// per call (`nonlinear_jacobian_samples`): 1 + 2·n_dof calls (twice that with
    /// velocity dependence) whatever the number of samples. Allocation-free if the
    /// problem's `nonlinear_jacobian_samples` is. NaN (and a NaN gradient) if a
    /// slice or the problem does not have the size of construction.
    pub(crate) fn value<P: PeriodicProblem>(
        &mut self,
        problem: &P,
        q: &[f64],
        lambda: f64,
        w: &[f64],
        v: &[f64],
        grad: Option<&mut [f64]>,
    ) -> f64 {
        let (nd, l) = (self.n_dof, self.l);
        let m = nd * l;
        let grad_ok = grad.as_ref().is_none_or(|g| g.len() == m);
        if [q, w, v].iter().any(|u| u.len() != m) || !grad_ok || problem.n_dof() != nd {
            if let Some(out) = grad {
                out.fill(f64::NAN);
            }
            return f64::NAN;
        }
        let Self {
            p,
            velocity,
            basis,
            thetas,
            xs,
            vs,
            wt,
            vt,
            vdt,
            moved,
            dg,
            at,
            plus,
            minus,
            steps,
            ..
        } = self;
        let ns = thetas.len();
        let omega = lambda / *p;
        let synth = |c: &[f64], row: &[f64]| c.iter().zip(row).map(|(a, b)| a * b).sum::<f64>();
        // Sample-major x(τᵢ), ẋ(τᵢ) of the orbit and the syntheses of w, v, v'.
        let samples = xs
            .chunks_exact_mut(nd)
            .zip(vs.chunks_exact_mut(nd))
            .zip(wt.chunks_exact_mut(nd))
            .zip(vt.chunks_exact_mut(nd).zip(vdt.chunks_exact_mut(nd)));
        for ((((x, xv), wi), (vi, vdi)), (cs, ds)) in samples.zip(basis_rows(basis, l)) {
            let dofs = q
                .chunks_exact(l)
                .zip(w.chunks_exact(l))
                .zip(v.chunks_exact(l));
            let outs = x.iter_mut().zip(xv).zip(wi).zip(vi.iter_mut().zip(vdi));
            for ((((x, xv), wk), (vk, vdk)), ((qd, wd), vd)) in outs.zip(dofs) {
                *x = synth(qd, cs);
                *xv = omega * synth(qd, ds);
                *wk = synth(wd, cs);
                *vk = synth(vd, cs);
                *vdk = synth(vd, ds);
            }
        }
        let tilde = Syntheses { wt, vt, vdt };
        let weight = 2.0 / ns as f64;
        psi(problem, (xs, vs), thetas, dg, &tilde, omega, at);
        let total = weight * at.iter().sum::<f64>();
        let Some(out) = grad else {
            return total;
        };
        out.fill(0.0);
        let scale = |u: &[f64]| u.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let (x_scale, v_scale) = (scale(xs), scale(vs));
        for (f, target) in out.chunks_exact_mut(l).enumerate() {
            for wrt_v in [false, true] {
                if wrt_v && !*velocity {
                    continue;
                }
                let (base, u_scale) = if wrt_v {
                    (&*vs, v_scale)
                } else {
                    (&*xs, x_scale)
                };
                // DOF f of every sample (`nd ≥ 1`).
                for (h, b) in steps.iter_mut().zip(base.iter().skip(f).step_by(nd)) {
                    *h = 1e-6 * b.abs().max(u_scale).max(f64::MIN_POSITIVE);
                }
                moved.copy_from_slice(base);
                for (sign, dst) in [(1.0, &mut *plus), (-1.0, &mut *minus)] {
                    let displaced = moved.iter_mut().skip(f).step_by(nd);
                    for ((mv, b), h) in displaced.zip(base.iter().skip(f).step_by(nd)).zip(&*steps)
                    {
                        *mv = b + sign * h;
                    }
                    let states: (&[f64], &[f64]) = if wrt_v { (xs, moved) } else { (moved, vs) };
                    psi(problem, states, thetas, dg, &tilde, omega, dst);
                }
                let factor = if wrt_v { weight * omega } else { weight };
                let differences = plus.iter().zip(&*minus).zip(&*steps);
                for (((pl, mi), h), (cs, ds)) in differences.zip(basis_rows(basis, l)) {
                    let d_psi = factor * (pl - mi) / (2.0 * h);
                    let row = if wrt_v { ds } else { cs };
                    target
                        .iter_mut()
                        .zip(row)
                        .for_each(|(o, c)| *o += d_psi * c);
                }
            }
        }
        total
    }
}

/// ψᵢ = w̃ᵀ(G_x ṽ + ω G_v ṽ') of every sample at the states `(x, ẋ)`, from one
/// batched `∂g` into `dg` (`2N·2n_dof²`; the caller checked `n_dof ≥ 1`).
fn psi<P: PeriodicProblem>(
    problem: &P,
    (x, xv): (&[f64], &[f64]),
    thetas: &[f64],
    dg: &mut [f64],
    tilde: &Syntheses,
    omega: f64,
    out: &mut [f64],
) {
    let nd = problem.n_dof().max(1);
    let n2 = nd * nd;
    problem.nonlinear_jacobian_samples(x, xv, thetas, dg);
    let syntheses = tilde
        .wt
        .chunks_exact(nd)
        .zip(tilde.vt.chunks_exact(nd))
        .zip(tilde.vdt.chunks_exact(nd));
    for ((o, block), ((wi, vi), vdi)) in out.iter_mut().zip(dg.chunks_exact(2 * n2)).zip(syntheses)
    {
        // `block` is `[G_x | G_v]`, each `n_dof²` row-major.
        let (gx, gv) = block.split_at(n2);
        let rows = gx.chunks_exact(nd).zip(gv.chunks_exact(nd)).zip(wi);
        *o = rows
            .map(|((gx_row, gv_row), wd)| {
                let along = gx_row.iter().zip(gv_row).zip(vi.iter().zip(vdi));
                wd * along
                    .map(|((gx, gv), (ve, vde))| gx * ve + omega * gv * vde)
                    .sum::<f64>()
            })
            .sum();
    }
}

/// `C_s(τ_i) = {1/2, cos kτ_i, sin kτ_i}` in rows `i < 2N` and its τ-derivative in
/// rows `2N + i` (`2·2N·(2n+1)`): the basis sampled on the AFT grid.
pub(super) fn quadrature_basis(n: usize, ns: usize) -> Vec<f64> {
    let l = 2 * n + 1;
    let mut basis = vec![0.0; 2 * ns * l];
    // k·τ_i = 2π·(k·i mod 2N)/2N: one sin/cos table of the 2N grid angles serves
    // every harmonic (and reduces the angle exactly).
    let table: Vec<(f64, f64)> = (0..ns)
        .map(|j| (std::f64::consts::PI * j as f64 / (ns / 2) as f64).sin_cos())
        .collect();
    let (values, derivatives) = basis.split_at_mut(ns * l);
    let rows = values
        .chunks_exact_mut(l)
        .zip(derivatives.chunks_exact_mut(l));
    for (i, (row, d_row)) in rows.enumerate() {
        let Some((a0, rest)) = row.split_first_mut() else {
            continue;
        };
        *a0 = 0.5;
        let (cos, sin) = rest.split_at_mut(n);
        let (_, d_rest) = d_row.split_at_mut(1);
        let (d_cos, d_sin) = d_rest.split_at_mut(n);
        let harmonics = cos.iter_mut().zip(sin).zip(d_cos.iter_mut().zip(d_sin));
        for (k, ((c, s), (dc, ds))) in (1..=n).zip(harmonics) {
            // `ns > 0` here (a row exists), so the remainder is a table index.
            let (sn, cs) = table
                .get((k * i) % ns)
                .copied()
                .unwrap_or((f64::NAN, f64::NAN));
            *c = cs;
            *s = sn;
            *dc = -(k as f64) * sn;
            *ds = k as f64 * cs;
        }
    }
    basis
}

/// `(C_s(τ_i), C_s'(τ_i))` for `i = 0..2N` from the [`quadrature_basis`] table
/// with `l = 2n + 1 ≥ 1` entries a row.
pub(super) fn basis_rows(basis: &[f64], l: usize) -> impl Iterator<Item = (&[f64], &[f64])> {
    let (values, derivatives) = basis.split_at(basis.len() / 2);
    values
        .chunks_exact(l.max(1))
        .zip(derivatives.chunks_exact(l.max(1)))
}
