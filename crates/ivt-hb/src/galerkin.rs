//! The exact Galerkin Jacobian of the HB residual (Eq. 56),
//!
//! `Φ_q = L(ω) + s·(1/π)∫ C_s (G_x C_sᵀ + ω G_v C_s'ᵀ) dτ`,  `C_s = {1/2, cos kτ, sin kτ}`,
//!
//! with the integral taken as the 2N-point sum of the AFT grid `τ_i = 2πi/2N`. Every
//! entry of a DOF block is a sum `Σ_i g(τ_i) c_j(τ_i) c_k(τ_i)` of one sampled
//! derivative `g = ∂g_d/∂x_e` (or `ω ∂g_d/∂v_e`) against a product of two basis
//! functions, and a product of two harmonics is a sum of the harmonics `j ± k`:
//!
//! `Σ g cos j cos k = ½(C_{j−k} + C_{j+k})`, `Σ g sin j sin k = ½(C_{j−k} − C_{j+k})`,
//! `Σ g cos j sin k = ½(S_{j+k} − S_{j−k})`, `Σ g sin j cos k = ½(S_{j+k} + S_{j−k})`,
//!
//! with `C_l = Σ_i g(τ_i) cos lτ_i`, `S_l = Σ_i g(τ_i) sin lτ_i` for `l = 0..2n` (one
//! real FFT of the 2N samples; `l > N` read from bin `2N − l`). This is the same
//! discrete sum, aliasing included, so the assembly equals the quadrature to
//! rounding in O(2N log 2N + (2n+1)²) per block instead of O(2N·(2n+1)²).

use crate::aft::Aft;
use crate::ihb::HbResidual;
use crate::problem::PeriodicProblem;

/// The exact Galerkin Jacobian `Φ_q` (Eq. 56) of the residual at nonlinearity
/// scale `s`, with its scratch: the classic IHB's Newton matrix, the modified
/// IHB's refresh when Broyden stalls, the fold locator's and exact continuation's
/// Jacobian. Allocation-free after construction when the problem supplies an
/// analytic Jacobian (central differences allocate their scratch).
#[derive(Debug, Clone)]
pub struct GalerkinJacobian {
    /// `[∂g/∂x | ∂g/∂v]` at every sample (`2N·2n_dof²`).
    dg: Vec<f64>,
    /// One block's 2N samples.
    column: Vec<f64>,
    /// `C_l`, `S_l` (`l = −n..2n`) of `∂g_d/∂x_e` and of `ω ∂g_d/∂v_e`, times `s/2N`.
    x_sums: CosSinSums,
    v_sums: CosSinSums,
}

/// `C_l = Σ_i g(τ_i) cos lτ_i` and `S_l = Σ_i g(τ_i) sin lτ_i` for `l = −n..2n`
/// (`C_{−l} = C_l`, `S_{−l} = −S_l`), stored at `n + l`.
#[derive(Debug, Clone)]
struct CosSinSums {
    n: usize,
    cos: Vec<f64>,
    sin: Vec<f64>,
}

impl CosSinSums {
    fn new(n: usize) -> Self {
        Self {
            n,
            cos: vec![0.0; 3 * n + 1],
            sin: vec![0.0; 3 * n + 1],
        }
    }

    /// The sums of `samples` times `scale`, from one real FFT: `X_l = C_l − i S_l`
    /// for `l ≤ N`, and `X_l = conj(X_{2N−l})` beyond the Nyquist bin.
    fn fill(&mut self, aft: &mut Aft, samples: &[f64], scale: f64) {
        let spectrum = aft.spectrum(samples);
        let (n, ns) = (self.n, samples.len());
        for l in 0..=2 * n {
            let (x, sign) = if 2 * l <= ns {
                (spectrum[l], -1.0)
            } else {
                (spectrum[ns - l], 1.0)
            };
            self.cos[n + l] = scale * x.re;
            self.sin[n + l] = sign * scale * x.im;
        }
        for l in 1..=n {
            self.cos[n - l] = self.cos[n + l];
            self.sin[n - l] = -self.sin[n + l];
        }
    }

    /// `(C_{j−k}, C_{j+k}, S_{j−k}, S_{j+k})`.
    fn pair(&self, j: usize, k: usize) -> (f64, f64, f64, f64) {
        let (minus, plus) = (self.n + j - k, self.n + j + k);
        (
            self.cos[minus],
            self.cos[plus],
            self.sin[minus],
            self.sin[plus],
        )
    }

    /// Adds to `row` (columns `a_0, a_1..a_n, b_1..b_n` of one DOF) the sums of the
    /// basis row `cos jτ` (weight ½ for j = 0), or `sin jτ` if `sin_row`, against
    /// `C_s` (`x`) or against the derivative columns `C_s' = {0, −k sin, k cos}`.
    /// With `(P_k, Q_k)` = the sums against `(cos kτ, sin kτ)`, the derivative
    /// columns get `(−k Q_k, k P_k)`, and `a_0` (weight ½) gets `½ P_0`.
    fn add_row(&self, row: &mut [f64], j: usize, sin_row: bool, x: bool) {
        let cj = if j == 0 { 0.5 } else { 1.0 };
        let sums = |k: usize| {
            let (cm, cp, sm, sp) = self.pair(j, k);
            if sin_row {
                (sp + sm, cm - cp)
            } else {
                (cj * (cm + cp), cj * (sp - sm))
            }
        };
        let (head, tail) = row.split_at_mut(self.n + 1);
        if x {
            head[0] += 0.5 * sums(0).0;
        }
        for (i, (a, b)) in head[1..].iter_mut().zip(tail.iter_mut()).enumerate() {
            let k = i + 1;
            let (p, q) = sums(k);
            if x {
                *a += p;
                *b += q;
            } else {
                let kf = k as f64;
                *a -= kf * q;
                *b += kf * p;
            }
        }
    }
}

impl GalerkinJacobian {
    /// `[∂g/∂x | ∂g/∂v]` at the 2N samples of the last [`Self::assemble`]
    /// (`2N·2n_dof²`, the layout of
    /// [`PeriodicProblem::nonlinear_jacobian_samples`]).
    pub(crate) fn samples(&self) -> &[f64] {
        &self.dg
    }

    /// Scratch for `res`'s size and `n_dof` of the problem it evaluates.
    pub fn new(res: &HbResidual) -> Self {
        let (nd, n, ns) = (res.n_dof(), res.harmonics(), res.n_samples());
        Self {
            dg: vec![0.0; 2 * ns * nd * nd],
            column: vec![0.0; ns],
            x_sums: CosSinSums::new(n),
            v_sums: CosSinSums::new(n),
        }
    }

    /// Writes `Φ_q(q)` (row-major `m×m`, DOF-major unknowns) into `jac`: `L(ω)`,
    /// then `s·(1/π)∫ C_s (G_x C_sᵀ + ω G_v C_s'ᵀ) dτ` added per DOF block `(d, e)`
    /// from one FFT of `∂g_d/∂x_e` and, for a velocity-dependent problem, one of
    /// `ω ∂g_d/∂v_e`; identically zero samples are skipped.
    pub fn assemble<P: PeriodicProblem>(
        &mut self,
        res: &mut HbResidual,
        problem: &P,
        q: &[f64],
        omega_f: f64,
        s: f64,
        jac: &mut [f64],
    ) {
        res.linear_matrix(problem, omega_f / res.subharmonic() as f64, jac);
        if s == 0.0 {
            return;
        }
        let (nd, n) = (res.n_dof(), res.harmonics());
        let l = 2 * n + 1;
        let len = nd * l;
        let n2 = nd * nd;
        let omega = omega_f / res.subharmonic() as f64;
        let velocity = res.velocity_dependent();
        res.jacobian_samples(problem, q, omega, &mut self.dg);
        // (1/π)·(2π/2N)·½: the sums' weight with the ½ of the product formulas.
        let w = s / self.column.len() as f64;
        for d in 0..nd {
            for e in 0..nd {
                let gather = |offset: usize, column: &mut [f64]| {
                    let samples = self.dg.chunks_exact(2 * n2);
                    for (c, block) in column.iter_mut().zip(samples) {
                        *c = block[offset + d * nd + e];
                    }
                    column.iter().any(|&g| g != 0.0)
                };
                let has_x = gather(0, &mut self.column);
                if has_x {
                    self.x_sums.fill(res.aft_mut(), &self.column, w);
                }
                let has_v = velocity && gather(n2, &mut self.column);
                if has_v {
                    self.v_sums.fill(res.aft_mut(), &self.column, w * omega);
                }
                for a in 0..l {
                    let start = (d * l + a) * len + e * l;
                    let row = &mut jac[start..start + l];
                    let parts = [(has_x, &self.x_sums, true), (has_v, &self.v_sums, false)];
                    for (_, sums, x) in parts.into_iter().filter(|part| part.0) {
                        let (j, sin_row) = if a <= n { (a, false) } else { (a - n, true) };
                        sums.add_row(row, j, sin_row, x);
                    }
                }
            }
        }
    }
}

/// `C_s(τ_i) = {1/2, cos kτ_i, sin kτ_i}` in rows `i < 2N` and its τ-derivative in
/// rows `2N + i` (`2·2N·(2n+1)`): the basis sampled on the AFT grid.
pub(crate) fn quadrature_basis(n: usize, ns: usize) -> Vec<f64> {
    let l = 2 * n + 1;
    let mut basis = vec![0.0; 2 * ns * l];
    // k·τ_i = 2π·(k·i mod 2N)/2N: one sin/cos table of the 2N grid angles serves
    // every harmonic (and reduces the angle exactly).
    let table: Vec<(f64, f64)> = (0..ns)
        .map(|j| (std::f64::consts::PI * j as f64 / (ns / 2) as f64).sin_cos())
        .collect();
    for i in 0..ns {
        basis[i * l] = 0.5;
        for k in 1..=n {
            let (sn, cs) = table[(k * i) % ns];
            basis[i * l + k] = cs;
            basis[i * l + n + k] = sn;
            basis[(ns + i) * l + k] = -(k as f64) * sn;
            basis[(ns + i) * l + n + k] = k as f64 * cs;
        }
    }
    basis
}

/// The nonlinear part of `wᵀΦ_q v` without assembling `Φ_q` (the fold test of
/// [`crate::FamilyBranch`]), and its gradient in `q`, with all scratch.
#[derive(Debug, Clone)]
pub(crate) struct GalerkinForm {
    n_dof: usize,
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
            n_dof: nd,
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
    /// problem's `nonlinear_jacobian_samples` is.
    pub(crate) fn value<P: PeriodicProblem>(
        &mut self,
        problem: &P,
        q: &[f64],
        lambda: f64,
        w: &[f64],
        v: &[f64],
        grad: Option<&mut [f64]>,
    ) -> f64 {
        let Self {
            n_dof: nd,
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
        } = self;
        let nd = *nd;
        let l = q.len() / nd;
        let ns = thetas.len();
        let omega = lambda / *p;
        let synth = |c: &[f64], row: &[f64]| c.iter().zip(row).map(|(a, b)| a * b).sum::<f64>();
        // Sample-major x(τᵢ), ẋ(τᵢ) of the orbit and the syntheses of w, v, v'.
        for i in 0..ns {
            let (cs, ds) = basis_rows(basis, l, ns, i);
            for d in 0..nd {
                let (k, dof) = (i * nd + d, d * l..(d + 1) * l);
                xs[k] = synth(&q[dof.clone()], cs);
                vs[k] = omega * synth(&q[dof.clone()], ds);
                wt[k] = synth(&w[dof.clone()], cs);
                vt[k] = synth(&v[dof.clone()], cs);
                vdt[k] = synth(&v[dof], ds);
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
        for f in 0..nd {
            for wrt_v in [false, true] {
                if wrt_v && !*velocity {
                    continue;
                }
                let (base, u_scale) = if wrt_v {
                    (&*vs, v_scale)
                } else {
                    (&*xs, x_scale)
                };
                for (i, h) in steps.iter_mut().enumerate() {
                    *h = 1e-6 * base[i * nd + f].abs().max(u_scale).max(f64::MIN_POSITIVE);
                }
                moved.copy_from_slice(base);
                for (sign, dst) in [(1.0, &mut *plus), (-1.0, &mut *minus)] {
                    for i in 0..ns {
                        moved[i * nd + f] = base[i * nd + f] + sign * steps[i];
                    }
                    let states: (&[f64], &[f64]) = if wrt_v { (xs, moved) } else { (moved, vs) };
                    psi(problem, states, thetas, dg, &tilde, omega, dst);
                }
                let factor = if wrt_v { weight * omega } else { weight };
                let target = &mut out[f * l..(f + 1) * l];
                for i in 0..ns {
                    let d_psi = factor * (plus[i] - minus[i]) / (2.0 * steps[i]);
                    let (cs, ds) = basis_rows(basis, l, ns, i);
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
/// batched `∂g` into `dg`.
fn psi<P: PeriodicProblem>(
    problem: &P,
    (x, xv): (&[f64], &[f64]),
    thetas: &[f64],
    dg: &mut [f64],
    tilde: &Syntheses,
    omega: f64,
    out: &mut [f64],
) {
    let nd = problem.n_dof();
    let n2 = nd * nd;
    problem.nonlinear_jacobian_samples(x, xv, thetas, dg);
    for (i, o) in out.iter_mut().enumerate() {
        let mut acc = 0.0;
        for d in 0..nd {
            for e in 0..nd {
                let (gx, gv) = (
                    dg[2 * i * n2 + d * nd + e],
                    dg[2 * i * n2 + n2 + d * nd + e],
                );
                acc += tilde.wt[i * nd + d]
                    * (gx * tilde.vt[i * nd + e] + omega * gv * tilde.vdt[i * nd + e]);
            }
        }
        *o = acc;
    }
}

/// `C_s(τ_i)` and `C_s'(τ_i)` from the quadrature table of `ns` samples.
fn basis_rows(basis: &[f64], l: usize, ns: usize, i: usize) -> (&[f64], &[f64]) {
    (
        &basis[i * l..(i + 1) * l],
        &basis[(ns + i) * l..(ns + i + 1) * l],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::{Element, ElementProblem, Harmonic, Law};
    use crate::fold::Branch;
    use crate::ihb::HbOptions;
    use crate::problem::{matrix_getters, Duffing, GeneralProblem, MathieuDuffing};
    use crate::FamilyBranch;
    use crate::ModifiedIhb;

    /// The direct O(2N·n_dof²·(2n+1)²) sum `(2s/2N) Σᵢ C_s(τᵢ)(G_x C_sᵀ + ω G_v C_s'ᵀ)`
    /// on the basis table: the oracle of the FFT assembly (nonlinear part only).
    fn quadrature(
        res: &mut HbResidual,
        problem: &impl PeriodicProblem,
        q: &[f64],
        omega_f: f64,
        s: f64,
    ) -> Vec<f64> {
        let (nd, n, ns) = (res.n_dof(), res.harmonics(), res.n_samples());
        let (l, n2) = (2 * n + 1, nd * nd);
        let len = nd * l;
        let omega = omega_f / res.subharmonic() as f64;
        let basis = quadrature_basis(n, ns);
        let mut dg = vec![0.0; 2 * ns * n2];
        res.jacobian_samples(problem, q, omega, &mut dg);
        let mut jac = vec![0.0; len * len];
        let w = 2.0 * s / ns as f64;
        for i in 0..ns {
            let (cs, ds) = basis_rows(&basis, l, ns, i);
            for d in 0..nd {
                for e in 0..nd {
                    let gx = w * dg[2 * i * n2 + d * nd + e];
                    let gv = w * omega * dg[2 * i * n2 + n2 + d * nd + e];
                    for a in 0..l {
                        for b in 0..l {
                            jac[(d * l + a) * len + e * l + b] += cs[a] * (gx * cs[b] + gv * ds[b]);
                        }
                    }
                }
            }
        }
        jac
    }

    /// Coefficients with a spread of harmonics (amplitude ~ 1/(k+1)), deterministic
    /// per `seed`.
    fn coefficients(nd: usize, n: usize, amplitude: f64, seed: u64) -> Vec<f64> {
        let mut state = 0x2545_f491_4f6c_dd1du64 ^ seed;
        (0..nd * (2 * n + 1))
            .map(|i| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
                let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                let slot = i % (2 * n + 1);
                let k = if slot > n { slot - n } else { slot };
                amplitude * u / (k as f64 + 1.0)
            })
            .collect()
    }

    /// `problem` with `M = C = K = 0`: its Galerkin Jacobian is the nonlinear part
    /// alone, exactly (`L(ω) = 0`).
    struct NonlinearPart<'a, P> {
        inner: &'a P,
        n: usize,
        m: Vec<f64>,
        c: Vec<f64>,
        k: Vec<f64>,
    }

    impl<P: PeriodicProblem> PeriodicProblem for NonlinearPart<'_, P> {
        matrix_getters!();
        fn nonlinear(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
            self.inner.nonlinear(x, v, theta, out);
        }
        fn velocity_dependent(&self) -> bool {
            self.inner.velocity_dependent()
        }
        fn nonlinear_jacobian_samples(&self, x: &[f64], v: &[f64], th: &[f64], dg: &mut [f64]) {
            self.inner.nonlinear_jacobian_samples(x, v, th, dg);
        }
    }

    /// max |FFT assembly − quadrature| / max |quadrature| of the nonlinear part.
    fn relative_gap(
        problem: &impl PeriodicProblem,
        opts: &HbOptions,
        q: &[f64],
        omega_f: f64,
        s: f64,
    ) -> f64 {
        let n = problem.n_dof();
        let problem = &NonlinearPart {
            inner: problem,
            n,
            m: vec![0.0; n * n],
            c: vec![0.0; n * n],
            k: vec![0.0; n * n],
        };
        let mut res = HbResidual::new(problem, opts).unwrap();
        let mut galerkin = GalerkinJacobian::new(&res);
        let m = res.len();
        let mut fast = vec![0.0; m * m];
        galerkin.assemble(&mut res, problem, q, omega_f, s, &mut fast);
        let slow = quadrature(&mut res, problem, q, omega_f, s);
        let max = |it: &mut dyn Iterator<Item = f64>| it.fold(0.0f64, |a, x| a.max(x.abs()));
        let scale = max(&mut slow.iter().copied());
        assert!(scale > 0.0, "the oracle must see a nonlinearity");
        max(&mut fast.iter().zip(&slow).map(|(a, b)| a - b)) / scale
    }

    /// A 2-DOF chain with a quadratic damper between the DOFs and a cubic spring
    /// to ground: velocity-dependent, with all four DOF blocks non-zero.
    fn damped_chain() -> ElementProblem {
        ElementProblem::new(
            2,
            [
                vec![1.0, 0.0, 0.0, 1.5],
                vec![0.02, 0.0, 0.0, 0.03],
                vec![2.0, -1.0, -1.0, 2.0],
            ],
            vec![
                Element {
                    a: 0,
                    b: None,
                    law: Law::CubicSpring { k3: 0.5 },
                },
                Element {
                    a: 0,
                    b: Some(1),
                    law: Law::QuadraticDamper { c2: 0.3 },
                },
            ],
            vec![Harmonic {
                dof: 0,
                amplitude: 0.1,
                phase: 0.0,
            }],
        )
        .unwrap()
    }

    // Tolerance 1e-12: both sides are the same 2N-point sum (aliasing included);
    // they differ only by the FFT's rounding, ~1e-15 relative for 2N ≤ 168.

    #[test]
    fn fft_assembly_equals_quadrature_for_duffing_at_its_orbit() {
        // Eq. 49 (Fig. 28 parameters) at the converged orbit of ω_f = 0.4.
        let duffing = Duffing::fig28();
        let opts = HbOptions::new(20, 64);
        let sol = ModifiedIhb::new(duffing.clone(), opts.clone())
            .unwrap()
            .solve(0.4, None)
            .unwrap();
        let gap = relative_gap(&duffing, &opts, &sol.coeffs, 0.4, 1.0);
        assert!(gap <= 1e-12, "{gap:e}");
    }

    #[test]
    fn fft_assembly_equals_quadrature_for_mathieu_duffing_theta_dependent_g() {
        // Eq. 81: g = −β sin θ·u + γu³ depends on the phase; period-2 orbit (p = 2).
        let md = MathieuDuffing::thesis(1.6);
        let opts = HbOptions::new(20, 84).with_subharmonic(2);
        let q = coefficients(1, 20, 1.2, 0);
        let gap = relative_gap(&md, &opts, &q, 2.0, 0.7);
        assert!(gap <= 1e-12, "{gap:e}");
    }

    #[test]
    fn fft_assembly_equals_quadrature_for_velocity_dependent_2dof() {
        // N = 84 and N = 64 (even), N = 21 (odd, 2N = 42 < 2n: the sums j + k > N
        // alias onto bin 2N − (j + k), as in the quadrature).
        let chain = damped_chain();
        let q = coefficients(2, 20, 0.8, 0);
        for n_half in [84, 64, 21] {
            let gap = relative_gap(&chain, &HbOptions::new(20, n_half), &q, 1.1, 1.0);
            assert!(gap <= 1e-12, "N = {n_half}: {gap:e}");
        }
    }

    #[test]
    fn fft_assembly_equals_quadrature_for_subharmonic_p3() {
        let duffing = Duffing::fig28();
        let q = coefficients(1, 20, 1.5, 0);
        for n_half in [64, 21] {
            let opts = HbOptions::new(20, n_half).with_subharmonic(3);
            let gap = relative_gap(&duffing, &opts, &q, 3.3, 0.6);
            assert!(gap <= 1e-12, "N = {n_half}: {gap:e}");
        }
    }

    #[test]
    fn fft_assembly_equals_quadrature_for_a_closure_with_central_differences() {
        // A user g without analytic Jacobian (∂g by central_difference_samples),
        // velocity-dependent in both DOFs.
        let problem = GeneralProblem::new(
            2,
            vec![1.0, 0.0, 0.0, 1.0],
            vec![0.0; 4],
            vec![1.0, 0.0, 0.0, 2.0],
            |x: &[f64], v: &[f64], theta: f64, g: &mut [f64]| {
                g[0] = x[0] * x[0] * v[1] + 0.2 * theta.cos() * x[1];
                g[1] = (x[0] - x[1]).powi(3) + 0.1 * v[0] * v[0];
            },
            |_theta: f64, f: &mut [f64]| f.fill(0.0),
        );
        let q = coefficients(2, 20, 0.7, 0);
        for n_half in [64, 21] {
            let gap = relative_gap(&problem, &HbOptions::new(20, n_half), &q, 0.9, 1.0);
            assert!(gap <= 1e-12, "N = {n_half}: {gap:e}");
        }
    }

    #[test]
    fn bilinear_form_equals_the_assembled_jacobian() {
        // wᵀJv of the fold test (grid synthesis, no J) and from the FFT assembly:
        // two routes through the same sum.
        let chain = damped_chain();
        let mut branch =
            FamilyBranch::new(|w: f64| (&chain, w), &HbOptions::new(20, 84), 1.2).unwrap();
        let m = branch.len();
        let (q, w, v) = (
            coefficients(2, 20, 0.8, 1),
            coefficients(2, 20, 1.0, 2),
            coefficients(2, 20, -0.6, 3),
        );
        let mut jac = vec![0.0; m * m];
        branch.jacobian(&q, 1.1, &mut jac);
        let (mut assembled, mut scale) = (0.0, 0.0);
        for (row, wi) in jac.chunks_exact(m).zip(&w) {
            for (a, vj) in row.iter().zip(&v) {
                assembled += wi * a * vj;
                scale += (wi * a * vj).abs();
            }
        }
        let value = branch.bilinear(&q, 1.1, &w, &v);
        assert!(
            (value - assembled).abs() <= 1e-12 * scale,
            "{value} vs {assembled}"
        );
    }
}
