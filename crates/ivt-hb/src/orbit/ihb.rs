//! Shared pieces of both IHB variants: options, the AFT residual of Eq. 52/55/61
//! for a [`PeriodicProblem`], the linear Jacobian Eq. 60, and the solution type.
//!
//! Unknowns: `q = [dof 0: a0, a1..an, b1..bn | dof 1: … ]` (length `n_dof·(2n+1)`)
//! for `x(τ)`, τ = ωt, ω = ω_f/p. The residual is the Galerkin projection (Eq. 55)
//!
//! `r = (1/π)∫ C_s [ω² M x'' + ω C x' + K x + s·g(x, ω x', pτ) − f(pτ)] dτ`,
//!
//! with the linear part applied exactly in the frequency domain and `g` by AFT
//! (Eq. 62–65); `s ∈ [0, 1]` scales the nonlinearity for parameter stepping (§3.2.2).
//!
//! Slice lengths are the callers' contract: a vector of the wrong length gives a
//! NaN output (reported by the solvers as [`HbError::NonFinite`]), not a panic.

pub(crate) use crate::error::HbError;
use crate::orbit::aft::{split_series, split_series_mut, Aft};
use crate::orbit::peak::series_peak;
use crate::problem::PeriodicProblem;
use ivt_num::{BlockDiagonal, BroydenOptions, BroydenStats};

/// Options of the IHB solvers.
///
/// Convergence: `‖r‖₂ ≤ atol + rtol·S` with `atol = broyden.tol`, the residual
/// `r` of Eq. 61 (a force) and the force scale `S` = ‖f̂‖₂, the norm of the
/// excitation's Galerkin projection, or for an unforced problem the larger of
/// ‖L(ω)q₀‖₂ and ‖K q₀‖₂, the linear and elastic forces of the start
/// ([`HbResidual::force_scale`]). The defaults
/// (`atol = 0`, `rtol = 1e-9`; ‖r‖₂ ≤ 1e-10 for Fig. 28's F = 0.1) make the test
/// invariant under a change of length unit: `x = L·u` scales r and S alike.
#[derive(Debug, Clone, PartialEq)]
pub struct HbOptions {
    /// Harmonics n.
    pub harmonics: usize,
    /// Half the number of AFT samples, N (> n).
    pub n_half: usize,
    /// Sub-harmonic order p (Eq. 52): response period p·2π/ω_f.
    pub subharmonic: usize,
    /// Iteration options; `broyden.tol` is the absolute tolerance `atol` on ‖r‖₂
    /// (default 0) and `broyden.max_iter` the iteration limit (default 100).
    pub broyden: BroydenOptions,
    /// Relative tolerance on ‖r‖₂, relative to the force scale (default 1e-9).
    pub rtol: f64,
    /// Initial number of parameter steps in the nonlinearity (0: first try the
    /// full problem directly; on failure, or when > 0, step s = 0 → 1 adaptively
    /// starting from Δs = 1/max(steps, 8)).
    pub homotopy_steps: usize,
}

impl Default for HbOptions {
    fn default() -> Self {
        Self {
            harmonics: 20,
            n_half: 64,
            subharmonic: 1,
            broyden: BroydenOptions::default().with_tol(0.0),
            rtol: 1e-9,
            homotopy_steps: 0,
        }
    }
}

impl HbOptions {
    /// Options with n harmonics and 2N samples.
    pub fn new(harmonics: usize, n_half: usize) -> Self {
        Self {
            harmonics,
            n_half,
            ..Self::default()
        }
    }
    /// Same options with sub-harmonic order p.
    pub fn with_subharmonic(mut self, p: usize) -> Self {
        self.subharmonic = p;
        self
    }
    /// Same options with a purely absolute tolerance: ‖r‖₂ ≤ `tol` (`rtol = 0`).
    pub fn with_tol(self, tol: f64) -> Self {
        self.with_tolerances(0.0, tol)
    }
    /// Same options with ‖r‖₂ ≤ `atol + rtol·S` (see the type's docs).
    pub fn with_tolerances(mut self, rtol: f64, atol: f64) -> Self {
        self.rtol = rtol;
        self.broyden.tol = atol;
        self
    }
    /// Same options with another iteration limit.
    pub fn with_max_iter(mut self, max_iter: usize) -> Self {
        self.broyden.max_iter = max_iter;
        self
    }
    /// The residual tolerance `atol + rtol·S` for the force scale `S`.
    pub fn residual_tol(&self, force_scale: f64) -> f64 {
        self.broyden.tol + self.rtol * force_scale
    }
}

/// A harmonic-balance solver for one problem and one size, reusable across
/// solves: the modified IHB ([`crate::ModifiedIhb`], Broyden on the AFT
/// residual) and the classic IHB ([`crate::ClassicIhb`], Newton with the
/// Galerkin Jacobian) behind one interface.
pub trait HbSolver {
    /// Solves at excitation frequency `omega_f` from `guess`, or from the linear
    /// solution (Eq. 59) when `None`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for a bad frequency or guess, [`HbError::Solve`]
    /// with the residual history when the iteration fails.
    fn solve(&mut self, omega_f: f64, guess: Option<&[f64]>) -> Result<HbSolution, HbError>;
    /// The options the solver was built with.
    fn options(&self) -> &HbOptions;
}

/// A converged periodic solution.
#[derive(Debug, Clone, PartialEq)]
pub struct HbSolution {
    /// Fourier coefficients, `n_dof` blocks of `[a0, a1..an, b1..bn]` in τ.
    pub coeffs: Vec<f64>,
    /// Excitation frequency ω_f.
    pub omega_f: f64,
    /// Harmonics n.
    pub harmonics: usize,
    /// Sub-harmonic order p.
    pub subharmonic: usize,
    /// Iteration statistics (summed over parameter steps).
    pub stats: BroydenStats,
}

impl HbSolution {
    /// Fundamental frequency of the response ω = ω_f/p (τ = ωt).
    pub fn omega(&self) -> f64 {
        self.omega_f / self.subharmonic as f64
    }
    /// Coefficients of DOF `d` (empty if there is no DOF `d`).
    pub fn dof(&self, d: usize) -> &[f64] {
        let l = 2 * self.harmonics + 1;
        self.coeffs.chunks_exact(l).nth(d).unwrap_or_default()
    }
    /// `x_d` at physical time `t` (NaN if there is no DOF `d`).
    pub fn x_at(&self, d: usize, t: f64) -> f64 {
        crate::orbit::aft::eval_series(self.dof(d), self.omega() * t, 0)
    }
    /// Amplitude `max_τ |x_d(τ)|` of DOF `d` (NaN if there is no DOF `d`),
    /// with x_d = a0/2 + Σ a_k cos kτ + b_k sin kτ: the largest of `M = 4(n+1)`
    /// equally spaced samples (four per period of the n-th harmonic), refined by
    /// up to 8 Newton steps on `x′(τ) = 0` from that sample. Cost: one inverse
    /// real FFT of length M (the samples) and O(n) per Newton step.
    ///
    /// Accuracy: the value reported is `|x(τ̂)|` at a τ̂ the search visited, the
    /// largest such value, so it never exceeds the true maximum and never falls
    /// below the largest sample: `0 ≤ max|x| − A ≤ ½(π/M)²·Σ k²·hypot(a_k, b_k)`.
    /// When the largest sample lies in the basin of the global maximum, A is that
    /// maximum to rounding: within 1e-14 relative of a brute-force search (10⁵
    /// points, then 2·10⁴ around the best) for Fig. 28's orbit and for random
    /// series up to n = 40 (the `series_peak_*` tests of `peak.rs`). The 512 samples used before
    /// were low by 8.2e-6 relative on Fig. 28's orbit. NaN for non-finite
    /// coefficients.
    pub fn amplitude(&self, d: usize) -> f64 {
        series_peak(self.dof(d))
    }
}

/// Checks sizes and parameters common to both solvers.
pub(crate) fn validate<P: PeriodicProblem>(problem: &P, opts: &HbOptions) -> Result<(), HbError> {
    let n = problem.n_dof();
    if n == 0 {
        return Err(HbError::InvalidInput("n_dof must be positive".into()));
    }
    if opts.subharmonic == 0 {
        return Err(HbError::InvalidInput(
            "sub-harmonic order p must be ≥ 1".into(),
        ));
    }
    if let Some(why) = crate::limits::unknowns_error(n, opts.harmonics) {
        return Err(HbError::InvalidInput(why));
    }
    if let Some(why) = crate::limits::samples_error(opts.n_half) {
        return Err(HbError::InvalidInput(why));
    }
    if opts.harmonics < opts.subharmonic {
        return Err(HbError::InvalidInput(format!(
            "n = {} harmonics cannot hold the excitation harmonic p = {}",
            opts.harmonics, opts.subharmonic
        )));
    }
    for (name, mat) in [
        ("M", problem.mass()),
        ("C", problem.damping()),
        ("K", problem.stiffness()),
    ] {
        if mat.len() != n * n {
            return Err(HbError::InvalidInput(format!("{name} must be {n}×{n}")));
        }
        if !mat.iter().all(|v| v.is_finite()) {
            return Err(HbError::InvalidInput(format!(
                "{name} has non-finite entries"
            )));
        }
    }
    let (atol, rtol) = (opts.broyden.tol, opts.rtol);
    if !(atol.is_finite() && rtol.is_finite() && atol >= 0.0 && rtol >= 0.0 && atol + rtol > 0.0) {
        return Err(HbError::InvalidInput(format!(
            "tolerances must be finite, ≥ 0 and not both 0, got rtol = {rtol:?}, atol = {atol:?}"
        )));
    }
    if opts.broyden.max_iter == 0 {
        return Err(HbError::InvalidInput("max_iter must be ≥ 1".into()));
    }
    Ok(())
}

pub(crate) fn validate_omega(omega_f: f64) -> Result<(), HbError> {
    if !omega_f.is_finite() || omega_f <= 0.0 {
        return Err(HbError::InvalidInput(format!(
            "excitation frequency must be positive and finite, got {omega_f:?}"
        )));
    }
    Ok(())
}

/// The AFT residual evaluator with all buffers (allocation-free `eval`).
#[derive(Debug, Clone)]
pub struct HbResidual {
    aft: Aft,
    n_dof: usize,
    n: usize,
    p: usize,
    velocity: bool,
    /// `x`, `v = dx/dt` and `g` at the 2N samples, sample-major (`2N×n_dof`, the
    /// layout of [`PeriodicProblem::nonlinear_samples`]).
    xs: Vec<f64>,
    vs: Vec<f64>,
    gs: Vec<f64>,
    /// One DOF's 2N samples (scratch of the sample-major transforms).
    column: Vec<f64>,
    rg: Vec<f64>,
    exc: Vec<f64>,
    /// Excitation phase θ = pτ of each sample.
    thetas: Vec<f64>,
}

impl HbResidual {
    /// Plans the AFT and precomputes the Galerkin projection of the excitation.
    ///
    /// # Errors
    /// [`HbError`] for invalid sizes (N ≤ n, p = 0, …).
    pub fn new<P: PeriodicProblem>(problem: &P, opts: &HbOptions) -> Result<Self, HbError> {
        validate(problem, opts)?;
        let aft = Aft::new(opts.harmonics, opts.n_half)?;
        let nd = problem.n_dof();
        let ns = aft.n_samples();
        let l = aft.coeff_len();
        let mut s = Self {
            n_dof: nd,
            n: opts.harmonics,
            p: opts.subharmonic,
            velocity: problem.velocity_dependent(),
            xs: vec![0.0; nd * ns],
            vs: vec![0.0; nd * ns],
            gs: vec![0.0; nd * ns],
            column: vec![0.0; ns],
            rg: vec![0.0; l],
            exc: vec![0.0; nd * l],
            thetas: (0..ns)
                .map(|i| opts.subharmonic as f64 * aft.tau(i))
                .collect(),
            aft,
        };
        // nd ≥ 1 and l ≥ 1 (validated).
        for (g, &theta) in s.gs.chunks_exact_mut(nd).zip(&s.thetas) {
            problem.excitation(theta, g);
        }
        if !s.gs.iter().all(|v| v.is_finite()) {
            return Err(HbError::InvalidInput("excitation is not finite".into()));
        }
        for (d, exc) in s.exc.chunks_exact_mut(l).enumerate() {
            s.aft.galerkin_state(&s.gs, nd, d, exc, &mut s.column);
        }
        Ok(s)
    }

    /// Fills the sample-major `x` and `v = ω dx/dτ` of `q` (`v` only if `velocity`).
    fn synthesize_states(&mut self, q: &[f64], omega: f64, velocity: bool) {
        let nd = self.n_dof;
        self.aft
            .synthesize_states(q, nd, 0, 1.0, &mut self.xs, &mut self.column);
        if velocity {
            self.aft
                .synthesize_states(q, nd, 1, omega, &mut self.vs, &mut self.column);
        } else {
            self.vs.fill(0.0);
        }
    }

    /// The force scale `S` of the tolerance ([`HbOptions`]): ‖f̂‖₂, the Galerkin
    /// projection of the excitation, or if that is zero (an unforced problem)
    /// the larger of ‖L(ω)q₀‖₂ and ‖K q₀‖₂ at the start `q0` (‖L(0)q₀‖₂, the
    /// elastic force alone: at resonance, e.g. a limit cycle's guess at its
    /// linear frequency, the inertia cancels it in L(ω)q₀), written through
    /// `scratch` (`len()`).
    pub fn force_scale<P: PeriodicProblem>(
        &self,
        problem: &P,
        q0: &[f64],
        omega: f64,
        scratch: &mut [f64],
    ) -> f64 {
        let forcing = ivt_num::vector::norm2(&self.exc);
        if forcing > 0.0 {
            return forcing;
        }
        self.apply_linear(problem, q0, omega, scratch);
        let dynamic = ivt_num::vector::norm2(scratch);
        self.apply_linear(problem, q0, 0.0, scratch);
        dynamic.max(ivt_num::vector::norm2(scratch))
    }

    /// Number of unknowns `n_dof·(2n+1)`.
    pub fn len(&self) -> usize {
        self.n_dof * (2 * self.n + 1)
    }

    /// True if there are no unknowns (never for a valid problem).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Harmonics n.
    pub fn harmonics(&self) -> usize {
        self.n
    }

    /// Sub-harmonic order p.
    pub fn subharmonic(&self) -> usize {
        self.p
    }

    /// The AFT plans (2N samples).
    pub fn aft_mut(&mut self) -> &mut Aft {
        &mut self.aft
    }

    /// Galerkin projection of the excitation `f(pτ)`.
    pub fn excitation(&self) -> &[f64] {
        &self.exc
    }

    /// `r = L(ω) q` — the exact Galerkin projection of `ω²M x'' + ωC x' + K x`
    /// (NaN if `q`, `r` or the problem's matrices have the wrong size).
    pub fn apply_linear<P: PeriodicProblem>(
        &self,
        problem: &P,
        q: &[f64],
        omega: f64,
        r: &mut [f64],
    ) {
        let nd = self.n_dof;
        let l = 2 * self.n + 1;
        let (m, c, k) = (problem.mass(), problem.damping(), problem.stiffness());
        let len = nd * l;
        let sizes_ok = nd > 0
            && q.len() == len
            && r.len() == len
            && [m, c, k].iter().all(|a| a.len() == nd * nd);
        debug_assert!(sizes_ok, "apply_linear: sizes do not match the residual");
        if !sizes_ok {
            return r.fill(f64::NAN);
        }
        r.fill(0.0);
        let rows = k
            .chunks_exact(nd)
            .zip(m.chunks_exact(nd))
            .zip(c.chunks_exact(nd));
        for (rd, ((k_row, m_row), c_row)) in r.chunks_exact_mut(l).zip(rows) {
            let Some((r0, ra, rb)) = split_series_mut(rd) else {
                continue;
            };
            let couplings = k_row.iter().zip(m_row).zip(c_row);
            for (((&kde, &mde), &cde), qe) in couplings.zip(q.chunks_exact(l)) {
                let Some((a0, qa, qb)) = split_series(qe) else {
                    continue;
                };
                // The mean's Galerkin weight is 1/2 (Eq. 55).
                *r0 += 0.5 * kde * a0;
                let harmonics = ra.iter_mut().zip(rb.iter_mut()).zip(qa.iter().zip(qb));
                for (h, ((ra, rb), (&a, &b))) in harmonics.enumerate() {
                    let kw = (h + 1) as f64 * omega;
                    let stiff = kde - kw * kw * mde;
                    let damp = kw * cde;
                    *ra += stiff * a + damp * b;
                    *rb += stiff * b - damp * a;
                }
            }
        }
    }

    /// The HB residual Eq. 61 at coefficients `q`, excitation frequency `omega_f`
    /// and nonlinearity scale `s`, into `r`. Allocation-free.
    pub fn eval<P: PeriodicProblem>(
        &mut self,
        problem: &P,
        q: &[f64],
        omega_f: f64,
        s: f64,
        r: &mut [f64],
    ) {
        let nd = self.n_dof;
        let l = 2 * self.n + 1;
        let omega = omega_f / self.p as f64;
        self.apply_linear(problem, q, omega, r);
        for (ri, ei) in r.iter_mut().zip(&self.exc) {
            *ri -= ei;
        }
        if s == 0.0 {
            return;
        }
        // g at all samples in one call, sample-major (`2N×n_dof`).
        self.synthesize_states(q, omega, self.velocity);
        problem.nonlinear_samples(&self.xs, &self.vs, &self.thetas, &mut self.gs);
        for (d, rd) in r.chunks_exact_mut(l).enumerate() {
            self.aft
                .galerkin_state(&self.gs, nd, d, &mut self.rg, &mut self.column);
            for (ri, gi) in rd.iter_mut().zip(&self.rg) {
                *ri += s * gi;
            }
        }
    }

    /// The linear Jacobian `B_{q,0} = L(ω)` of Eq. 60 (row-major, `len×len`),
    /// written straight into `b0`: harmonic k couples only `a_k`, `b_k` of all DOFs.
    /// Allocation-free (the classic Newton loop and the Broyden refresh call it).
    /// NaN if `b0` or the problem's matrices have the wrong size.
    pub fn linear_matrix<P: PeriodicProblem>(&self, problem: &P, omega: f64, b0: &mut [f64]) {
        let len = self.n_dof * (2 * self.n + 1);
        let sizes_ok = b0.len() == len * len;
        debug_assert!(sizes_ok, "linear_matrix: sizes do not match the residual");
        if !sizes_ok {
            return b0.fill(f64::NAN);
        }
        b0.fill(0.0);
        // The matrices once, not once per harmonic (a virtual call each for
        // a `dyn PeriodicProblem`).
        let mck = (problem.mass(), problem.damping(), problem.stiffness());
        for h in 0..=self.n {
            let set = |row: usize, col: usize, v: f64| {
                let (i, j) = (self.harmonic_unknown(h, row), self.harmonic_unknown(h, col));
                if let Some(x) = b0.get_mut(i * len + j) {
                    *x = v;
                }
            };
            if !self.harmonic_block(mck, omega, h, set) {
                return b0.fill(f64::NAN);
            }
        }
    }

    /// The inverse of [`Self::linear_matrix`] as its blocks, one per harmonic
    /// (inverted one by one): the Broyden solver's `H₀`. Returns `false` (and
    /// leaves `h0` incomplete) if a block is singular, e.g. at a linear
    /// resonance, or the problem's matrices have the wrong size.
    pub fn linear_inverse<P: PeriodicProblem>(
        &self,
        problem: &P,
        omega: f64,
        h0: &mut BlockDiagonal,
    ) -> bool {
        let nd = self.n_dof;
        h0.clear(nd * (2 * self.n + 1));
        let bs = 2 * nd;
        let mut blk = vec![0.0; bs * bs];
        let mut inv = vec![0.0; bs * bs];
        let mut idx = Vec::with_capacity(bs);
        let mut ok = true;
        let mck = (problem.mass(), problem.damping(), problem.stiffness());
        for h in 0..=self.n {
            let size = if h == 0 { nd } else { bs };
            let (Some(blk), Some(inv)) = (blk.get_mut(..size * size), inv.get_mut(..size * size))
            else {
                return false;
            };
            let set = |row: usize, col: usize, v: f64| {
                if let Some(x) = blk.get_mut(row * size + col) {
                    *x = v;
                }
            };
            if !self.harmonic_block(mck, omega, h, set) {
                return false;
            }
            idx.clear();
            idx.extend((0..size).map(|r| self.harmonic_unknown(h, r)));
            ok &= ivt_num::small::inverse(blk, size, inv) && h0.push_block(&idx, inv);
        }
        ok
    }

    /// Index in the coefficient vector of row `r` of harmonic `h`'s block of
    /// Eq. 60: `a_h` of DOF `r` for `r < n_dof`, else `b_h` of DOF `r − n_dof`
    /// (harmonic 0: the `a_0` of each DOF).
    fn harmonic_unknown(&self, h: usize, r: usize) -> usize {
        let (nd, n) = (self.n_dof, self.n);
        let l = 2 * n + 1;
        if r < nd {
            r * l + h
        } else {
            (r - nd) * l + n + h
        }
    }

    /// The entries of harmonic `h`'s block of Eq. 60, passed to `set(row, col,
    /// value)` in the order of [`Self::harmonic_unknown`]: `½K` for h = 0, else
    /// `[[K − (hω)²M, hωC], [−hωC, K − (hω)²M]]`. Every entry of the block is set.
    /// `false` (nothing set) if the problem's matrices are not `n_dof×n_dof`.
    fn harmonic_block(
        &self,
        (m, c, k): (&[f64], &[f64], &[f64]),
        omega: f64,
        h: usize,
        mut set: impl FnMut(usize, usize, f64),
    ) -> bool {
        let nd = self.n_dof;
        if [m, c, k].iter().any(|a| a.len() != nd * nd) {
            return false;
        }
        let kw = h as f64 * omega;
        for (de, ((&kde, &mde), &cde)) in k.iter().zip(m).zip(c).enumerate() {
            let (d, e) = (de / nd, de % nd);
            if h == 0 {
                set(d, e, 0.5 * kde);
                continue;
            }
            let stiff = kde - kw * kw * mde;
            let damp = kw * cde;
            set(d, e, stiff);
            set(d, nd + e, damp);
            set(nd + d, e, -damp);
            set(nd + d, nd + e, stiff);
        }
        true
    }

    /// `∂g/∂x`, `∂g/∂v` of the orbit `q` at all samples, from one
    /// [`PeriodicProblem::nonlinear_jacobian_samples`] call into `dg` (`2N·2n_dof²`,
    /// per sample the blocks `[∂g/∂x | ∂g/∂v]`); `omega` = ω_f/p.
    pub(crate) fn jacobian_samples<P: PeriodicProblem>(
        &mut self,
        problem: &P,
        q: &[f64],
        omega: f64,
        dg: &mut [f64],
    ) {
        self.synthesize_states(q, omega, true);
        problem.nonlinear_jacobian_samples(&self.xs, &self.vs, &self.thetas, dg);
    }

    /// Number of DOFs.
    pub(crate) fn n_dof(&self) -> usize {
        self.n_dof
    }

    /// Number of AFT samples 2N.
    pub(crate) fn n_samples(&self) -> usize {
        self.aft.n_samples()
    }

    /// Whether `g` depends on the velocity (the problem's flag at construction).
    pub(crate) fn velocity_dependent(&self) -> bool {
        self.velocity
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_dof_is_nan_not_a_panic() {
        // x = cos τ: one DOF, one harmonic.
        let sol = HbSolution {
            coeffs: vec![0.0, 1.0, 0.0],
            omega_f: 1.0,
            harmonics: 1,
            subharmonic: 1,
            stats: BroydenStats::default(),
        };
        assert_eq!(sol.dof(0), [0.0, 1.0, 0.0]);
        assert!((sol.amplitude(0) - 1.0).abs() < 1e-12);
        assert!((sol.x_at(0, 0.5) - 0.5f64.cos()).abs() < 1e-15);
        assert!(sol.dof(1).is_empty() && sol.x_at(1, 0.0).is_nan() && sol.amplitude(1).is_nan());
    }
}
