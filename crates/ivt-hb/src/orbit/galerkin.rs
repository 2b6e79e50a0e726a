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
//!
//! The bilinear form `wᵀΦ_q v` of the fold test, sampled without assembling
//! `Φ_q`, is `form.rs`. A `jac` of the wrong size is not a panic: it is filled
//! with NaN, which the solvers report as [`crate::HbError::NonFinite`].

mod form;

pub(crate) use form::GalerkinForm;

use crate::orbit::aft::Aft;
use crate::orbit::ihb::HbResidual;
use crate::problem::PeriodicProblem;
use realfft::num_complex::Complex;

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
/// (`C_{−l} = C_l`, `S_{−l} = −S_l`), stored at `n + l`, and again in reverse
/// order (`l` at `2n − l`) so that a row reads both `C_{j+k}` and `C_{j−k}`
/// forward in `k`.
#[derive(Debug, Clone)]
struct CosSinSums {
    n: usize,
    cos: Vec<f64>,
    sin: Vec<f64>,
    cos_rev: Vec<f64>,
    sin_rev: Vec<f64>,
}

impl CosSinSums {
    fn new(n: usize) -> Self {
        let sums = vec![0.0; 3 * n + 1];
        Self {
            n,
            cos: sums.clone(),
            sin: sums.clone(),
            cos_rev: sums.clone(),
            sin_rev: sums,
        }
    }

    /// The sums of `samples` times `scale`, from one real FFT: `X_l = C_l − i S_l`
    /// for `l ≤ N`, and `X_l = conj(X_{2N−l})` beyond the Nyquist bin (NaN where
    /// the spectrum has no such bin: fewer than `2n` samples).
    fn fill(&mut self, aft: &mut Aft, samples: &[f64], scale: f64) {
        let spectrum = aft.spectrum(samples);
        let (n, ns) = (self.n, samples.len());
        let mid = n.min(self.cos.len()).min(self.sin.len());
        let (negative_cos, cos) = self.cos.split_at_mut(mid);
        let (negative_sin, sin) = self.sin.split_at_mut(mid);
        for (l, (c, s)) in cos.iter_mut().zip(sin.iter_mut()).enumerate() {
            let (bin, sign) = if 2 * l <= ns {
                (Some(l), -1.0)
            } else {
                (ns.checked_sub(l), 1.0)
            };
            let nan = Complex::new(f64::NAN, f64::NAN);
            let x = bin.and_then(|b| spectrum.get(b)).copied().unwrap_or(nan);
            *c = scale * x.re;
            *s = sign * scale * x.im;
        }
        // C_{−l} = C_l, S_{−l} = −S_l for l = 1..n, stored at n − l.
        let mirrored = negative_cos
            .iter_mut()
            .rev()
            .zip(negative_sin.iter_mut().rev());
        for ((c_neg, s_neg), (c, s)) in mirrored.zip(cos.iter().zip(sin.iter()).skip(1)) {
            *c_neg = *c;
            *s_neg = -*s;
        }
        for (rev, sums) in [
            (&mut self.cos_rev, &self.cos),
            (&mut self.sin_rev, &self.sin),
        ] {
            rev.iter_mut()
                .zip(sums.iter().rev())
                .for_each(|(r, v)| *r = *v);
        }
    }

    /// Adds to `row` (columns `a_0, a_1..a_n, b_1..b_n` of one DOF) the sums of the
    /// basis row `cos jτ` (weight ½ for j = 0), or `sin jτ` if `sin_row`, against
    /// `C_s` (`x`) or against the derivative columns `C_s' = {0, −k sin, k cos}`.
    /// With `(P_k, Q_k)` = the sums against `(cos kτ, sin kτ)`, the derivative
    /// columns get `(−k Q_k, k P_k)`, and `a_0` (weight ½) gets `½ P_0`.
    /// For `k = 1..n`, `C_{j+k}` is at `n + j + k` of the sums and `C_{j−k}` at
    /// `2n − j + k` of the reversed sums: two forward windows of `n` entries.
    /// NaN in `row` if `j > n` or `row` is not `2n + 1` long.
    fn add_row(&self, row: &mut [f64], j: usize, sin_row: bool, x: bool) {
        let n = self.n;
        let (plus, minus) = (Some(n + j), (2 * n).checked_sub(j));
        let windows = (
            window(&self.cos, plus, n),
            window(&self.sin, plus, n),
            window(&self.cos_rev, minus, n),
            window(&self.sin_rev, minus, n),
        );
        let centre = (self.cos.get(n + j), self.sin.get(n + j));
        let (
            (Some(cos_plus), Some(sin_plus), Some(cos_minus), Some(sin_minus)),
            (Some(&c0), Some(&s0)),
        ) = (windows, centre)
        else {
            return row.fill(f64::NAN);
        };
        if row.len() != 2 * n + 1 || j > n {
            return row.fill(f64::NAN);
        }
        let cj = if j == 0 { 0.5 } else { 1.0 };
        let sums = |cm: f64, cp: f64, sm: f64, sp: f64| {
            if sin_row {
                (sp + sm, cm - cp)
            } else {
                (cj * (cm + cp), cj * (sp - sm))
            }
        };
        let (head, tail) = row.split_at_mut(n + 1);
        let Some((a0, head)) = head.split_first_mut() else {
            return;
        };
        if x {
            // k = 0: C_{j−0} = C_{j+0}.
            *a0 += 0.5 * sums(c0, c0, s0, s0).0;
        }
        let columns = head.iter_mut().zip(tail.iter_mut());
        let pairs = cos_minus
            .iter()
            .zip(cos_plus)
            .zip(sin_minus.iter().zip(sin_plus));
        let mut kf = 0.0;
        for ((a, b), ((&cm, &cp), (&sm, &sp))) in columns.zip(pairs) {
            kf += 1.0;
            let (p, q) = sums(cm, cp, sm, sp);
            if x {
                *a += p;
                *b += q;
            } else {
                *a -= kf * q;
                *b += kf * p;
            }
        }
    }
}

/// Entries `start + 1 ..= start + n` of `sums` (`None` past its end).
fn window(sums: &[f64], start: Option<usize>, n: usize) -> Option<&[f64]> {
    start.and_then(|s| sums.get(s + 1..=s + n))
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
    /// `ω ∂g_d/∂v_e`; identically zero samples are skipped. `jac` is NaN if it is
    /// not `m×m` or this scratch was made for another size of residual.
    pub fn assemble<P: PeriodicProblem>(
        &mut self,
        res: &mut HbResidual,
        problem: &P,
        q: &[f64],
        omega_f: f64,
        s: f64,
        jac: &mut [f64],
    ) {
        let (nd, n) = (res.n_dof(), res.harmonics());
        let l = 2 * n + 1;
        let len = nd * l;
        let n2 = nd * nd;
        let same_size = self.dg.len() == 2 * res.n_samples() * n2 && self.x_sums.n == n;
        if jac.len() != len * len || !same_size || n2 == 0 {
            return jac.fill(f64::NAN);
        }
        res.linear_matrix(problem, omega_f / res.subharmonic() as f64, jac);
        if s == 0.0 {
            return;
        }
        let omega = omega_f / res.subharmonic() as f64;
        let velocity = res.velocity_dependent();
        res.jacobian_samples(problem, q, omega, &mut self.dg);
        // (1/π)·(2π/2N)·½: the sums' weight with the ½ of the product formulas.
        let w = s / self.column.len() as f64;
        // Rows of DOF d (`l·len` entries each, `len ≥ 1`), then row a of the block.
        for (d, block_rows) in jac.chunks_exact_mut(l * len).enumerate() {
            for e in 0..nd {
                // Entry (d, e) of `[G_x | G_v]` at every sample (`2n_dof² ≥ 1` apart).
                let gather = |offset: usize, column: &mut [f64]| {
                    let entry = self.dg.iter().skip(offset + d * nd + e).step_by(2 * n2);
                    column.iter_mut().zip(entry).for_each(|(c, g)| *c = *g);
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
                let block = block_rows
                    .chunks_exact_mut(len)
                    .map(|r| r.get_mut(e * l..(e + 1) * l));
                for (a, row) in block.enumerate() {
                    let Some(row) = row else {
                        continue;
                    };
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

#[cfg(test)]
mod tests {
    use super::form::{basis_rows, quadrature_basis};
    use super::*;
    use crate::orbit::ihb::HbOptions;
    use crate::problem::elements::{Element, ElementProblem, Harmonic, Law};
    use crate::problem::{matrix_getters, Duffing, GeneralProblem, MathieuDuffing};
    use crate::FamilyBranch;
    use crate::ModifiedIhb;
    use ivt_path::branch::Branch;

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
        for (i, (cs, ds)) in basis_rows(&basis, l).enumerate() {
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
        // Vectors of the wrong length: NaN, not a panic.
        assert!(branch.bilinear(&q, 1.1, &w[1..], &v).is_nan());
        assert!(branch.bilinear(&q[1..], 1.1, &w, &v).is_nan());
        let mut grad = vec![0.0; m - 1];
        branch.jacobian_gradient(&q, 1.1, &w, &v, &mut grad);
        assert!(grad.iter().all(|g| g.is_nan()));
    }

    #[test]
    fn a_jacobian_of_the_wrong_size_or_scratch_of_another_residual_is_nan_not_a_panic() {
        let duffing = Duffing::fig28();
        let mut res = HbResidual::new(&duffing, &HbOptions::new(5, 16)).unwrap();
        let m = res.len();
        let q = vec![0.1; m];
        let mut galerkin = GalerkinJacobian::new(&res);
        let mut short = vec![0.0; m * m - 1];
        galerkin.assemble(&mut res, &duffing, &q, 1.0, 1.0, &mut short);
        assert!(short.iter().all(|v| v.is_nan()));
        // Scratch for 7 harmonics used on a 5-harmonic residual.
        let other = HbResidual::new(&duffing, &HbOptions::new(7, 16)).unwrap();
        let mut foreign = GalerkinJacobian::new(&other);
        let mut jac = vec![0.0; m * m];
        foreign.assemble(&mut res, &duffing, &q, 1.0, 1.0, &mut jac);
        assert!(jac.iter().all(|v| v.is_nan()));
        // The right sizes give finite entries.
        galerkin.assemble(&mut res, &duffing, &q, 1.0, 1.0, &mut jac);
        assert!(jac.iter().all(|v| v.is_finite()));
    }
}
