//! Quasi-periodic responses by two-frequency harmonic balance (Schilder et
//! al.'s tori; Krack & Gross, *Harmonic Balance for Nonlinear Vibration
//! Problems*, ch. 5): the response of `M x″ + C x′ + K x + g(x, x′, θ) =
//! f(θ)` on an invariant torus,
//!
//! `x(t) = X(θ₁, θ₂)`, `θ₁ = (ω_f/p) t`, `θ₂ = Ω t`,
//! `X = a₀/2 + Σ_k a_k cos(k₁θ₁ + k₂θ₂) + b_k sin(k₁θ₁ + k₂θ₂)`,
//!
//! with the kept harmonics `k` of a [`Truncation`] (box or diamond), the
//! excitation phase `θ = pθ₁` and the second frequency Ω unknown. Harmonic
//! `k` oscillates at `ν_k = k₁ω_f/p + k₂Ω`, so the linear part of the
//! Galerkin residual (Eq. 61 on the torus) is that of the periodic case
//! with `kω` replaced by `ν_k`; `g` is sampled on an `N₁ × N₂` grid of the
//! torus and projected by 2-D FFTs (`torus/grid.rs`). A torus may be turned
//! along θ₂ (`X(θ₁, θ₂ + φ)` is a solution too): the phase condition
//! `⟨∂X_ref/∂θ₂, X⟩ = 0` against a reference torus closes the system
//! (unknowns: the coefficients and Ω; equations: the residual and the phase
//! condition).
//!
//! [`TorusBranch`] is that system as a [`Branch`] in a parameter λ of a
//! [`Family`] (ω_f, or any parameter of a model family): the engine's
//! stepper, correctors and fold locator follow it unchanged. Its exact
//! Jacobian is the 2-D Galerkin Jacobian: a product of two harmonics is a
//! sum of the harmonics `j ± k`, read from one 2-D FFT of each sampled
//! `∂g_d/∂x_e`, `∂g_d/∂v_e` (the 1-D construction of Eq. 56 in
//! `galerkin.rs` on the torus grid, aliasing included).
//!
//! `torus/start.rs` starts a torus at a located Neimark–Sacker point,
//! `torus/measure.rs` reads a torus (rotation number, amplitudes, the
//! Poincaré section, an error estimate, the stability of a one-DOF torus).
//!
//! A hysteretic `g` ([`PeriodicProblem::hysteretic`], the Jenkins element)
//! is refused: its state along the torus's trajectories is not a function of
//! the grid's samples taken row by row.

mod branch;
mod grid;
mod harmonics;
pub mod measure;
pub mod start;

pub use harmonics::{TorusHarmonics, Truncation};
pub use measure::{TorusMeasures, TorusReading};
pub use start::{torus_start, NeimarkSackerStart, TorusStart};

use crate::branches::family::Family;
use crate::error::HbError;
use crate::problem::PeriodicProblem;
use grid::TorusGrid;
use ivt_path::branch::Branch;
use rustfft::num_complex::Complex;

/// The size of a torus: its harmonics, its grid and the sub-harmonic order
/// of its first frequency.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct TorusOptions {
    /// The kept harmonics.
    pub truncation: Truncation,
    /// Grid points along θ₁ and θ₂ (0: [`Self::default_samples`]).
    pub samples: (usize, usize),
    /// `p`: θ₁ = (ω_f/p) t (1 for a torus born on a period-one orbit).
    pub subharmonic: usize,
}

impl Default for TorusOptions {
    /// The box `|k₁| ≤ 7`, `|k₂| ≤ 20` (the first frequency carries the
    /// harmonics of the forcing, the second those of the modulation), its
    /// default grid, `p = 1`.
    fn default() -> Self {
        Self {
            truncation: Truncation::Box { h1: 7, h2: 20 },
            samples: (0, 0),
            subharmonic: 1,
        }
    }
}

impl TorusOptions {
    /// The grid of a truncation whose largest `|k|` are `(e₁, e₂)`: the
    /// power of two at or above `4e + 4` along each axis (a cubic `g` of
    /// the kept harmonics reaches `3e`, aliased onto no kept one below
    /// `4e + 1`).
    pub fn default_samples(truncation: Truncation) -> (usize, usize) {
        let (e1, e2) = truncation.extent();
        let side = |e: usize| (4 * e + 4).next_power_of_two();
        (side(e1), side(e2))
    }

    /// The grid: `samples` where given, else [`Self::default_samples`].
    pub fn grid(&self) -> (usize, usize) {
        let (d1, d2) = Self::default_samples(self.truncation);
        let pick = |given: usize, default: usize| if given == 0 { default } else { given };
        (pick(self.samples.0, d1), pick(self.samples.1, d2))
    }
}

/// The excitation's projection at the λ it was computed for.
#[derive(Debug, Clone)]
struct Projected {
    lambda: f64,
    coeffs: Vec<f64>,
}

/// The two-frequency HB system of a [`Family`] as a [`Branch`] in λ (see the
/// module docs). Unknowns `[X of DOF 0, …, X of DOF n−1, Ω]`, each DOF's
/// block `[a₀, a_1..a_H, b_1..b_H]` over [`TorusHarmonics`]; equations the
/// Galerkin residual per DOF and harmonic, then the phase condition.
pub struct TorusBranch<F: Family> {
    family: F,
    options: TorusOptions,
    harmonics: TorusHarmonics,
    grid: TorusGrid,
    n_dof: usize,
    velocity: bool,
    /// The excitation phase `pθ₁` of every grid sample.
    thetas: Vec<f64>,
    xs: Vec<f64>,
    vs: Vec<f64>,
    gs: Vec<f64>,
    dg: Vec<f64>,
    column: Vec<f64>,
    rg: Vec<f64>,
    excitation: Option<Projected>,
    /// `∂X_ref/∂θ₂` in coefficient form, unit length (the phase row).
    phase: Vec<f64>,
}

impl<F: Family> TorusBranch<F> {
    /// Plans the torus system of `family` with `options` (grids and
    /// buffers), its phase condition against the torus `reference` (its
    /// coefficients, `n_dof·(2H + 1)`).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for a truncation without a second
    /// frequency, a grid too coarse or too large, `p = 0`, too many
    /// unknowns, a hysteretic `g`, a `reference` of the wrong size or one
    /// without content along θ₂.
    pub fn new(
        family: F,
        options: &TorusOptions,
        lambda0: f64,
        reference: &[f64],
    ) -> Result<Self, HbError> {
        if !lambda0.is_finite() {
            return Err(HbError::InvalidInput("λ must be finite".into()));
        }
        if options.subharmonic == 0 {
            return Err(HbError::InvalidInput(
                "sub-harmonic order p must be ≥ 1".into(),
            ));
        }
        let harmonics = TorusHarmonics::new(options.truncation)?;
        let (problem, _) = family.at(lambda0);
        let n_dof = problem.n_dof();
        if problem.hysteretic() {
            return Err(HbError::InvalidInput(
                "a torus cannot carry a hysteretic element (its state along the \
                 torus's trajectories is not modelled): use a memoryless law"
                    .into(),
            ));
        }
        if let Some(why) = crate::limits::unknowns_error(n_dof, harmonics.len()) {
            return Err(HbError::InvalidInput(format!("torus: {why}")));
        }
        for (name, mat) in [
            ("M", problem.mass()),
            ("C", problem.damping()),
            ("K", problem.stiffness()),
        ] {
            if n_dof == 0 || mat.len() != n_dof * n_dof || !mat.iter().all(|v| v.is_finite()) {
                return Err(HbError::InvalidInput(format!(
                    "{name} must be a finite {n_dof}×{n_dof} matrix (n_dof ≥ 1)"
                )));
            }
        }
        let (n1, n2) = options.grid();
        let grid = TorusGrid::new(&harmonics, n1, n2)?;
        let ns = grid.len();
        let p = options.subharmonic as f64;
        let thetas = (0..ns).map(|s| p * grid.angles(s).0).collect();
        let l = harmonics.coeff_len();
        let mut branch = Self {
            velocity: problem.velocity_dependent(),
            family,
            options: *options,
            harmonics,
            grid,
            n_dof,
            thetas,
            xs: vec![0.0; ns * n_dof],
            vs: vec![0.0; ns * n_dof],
            gs: vec![0.0; ns * n_dof],
            dg: vec![0.0; 2 * ns * n_dof * n_dof],
            column: vec![0.0; ns],
            rg: vec![0.0; l],
            excitation: None,
            phase: vec![0.0; n_dof * l],
        };
        branch.set_reference(reference)?;
        Ok(branch)
    }

    /// [`Self::new`] with a provisional reference (the harmonic `(0, 1)` of
    /// DOF 0), to be replaced by [`Self::set_reference`].
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn planned(family: F, options: &TorusOptions, lambda0: f64) -> Result<Self, HbError> {
        let harmonics = TorusHarmonics::new(options.truncation)?;
        let n_dof = family.at(lambda0).0.n_dof();
        let mut reference = vec![0.0; n_dof * harmonics.coeff_len()];
        if let Some(x) = harmonics
            .index(0, 1)
            .and_then(|(i, _)| reference.get_mut(1 + i))
        {
            *x = 1.0;
        }
        Self::new(family, options, lambda0, &reference)
    }

    /// The options.
    pub fn options(&self) -> &TorusOptions {
        &self.options
    }

    /// The kept harmonics.
    pub fn harmonics(&self) -> &TorusHarmonics {
        &self.harmonics
    }

    /// The family.
    pub fn family(&self) -> &F {
        &self.family
    }

    /// Number of DOFs.
    pub fn n_dof(&self) -> usize {
        self.n_dof
    }

    /// Coefficients of the whole torus, `n_dof·(2H + 1)` (Ω excluded).
    pub fn coeff_len(&self) -> usize {
        self.n_dof * self.harmonics.coeff_len()
    }

    /// The torus `coeffs` of another harmonic set `from` (same DOFs) in this
    /// branch's harmonics: the common harmonics copied, the others zero.
    pub fn embed(&self, from: &TorusHarmonics, coeffs: &[f64]) -> Vec<f64> {
        let (lf, h, hf) = (from.coeff_len(), self.harmonics.len(), from.len());
        let l = self.harmonics.coeff_len();
        let mut out = vec![0.0; self.coeff_len()];
        for (to, narrow) in out.chunks_exact_mut(l).zip(coeffs.chunks_exact(lf)) {
            if let (Some(t0), Some(n0)) = (to.first_mut(), narrow.first()) {
                *t0 = *n0;
            }
            for (i, k) in from.iter().enumerate() {
                if let Some((j, _)) = self.harmonics.index(k.0, k.1) {
                    for (src, dst) in [(1 + i, 1 + j), (1 + hf + i, 1 + h + j)] {
                        if let (Some(v), Some(t)) = (narrow.get(src), to.get_mut(dst)) {
                            *t = *v;
                        }
                    }
                }
            }
        }
        out
    }

    /// The phase condition's reference: `⟨∂X_ref/∂θ₂, X⟩ = 0` from now on.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for a reference of the wrong size or
    /// without content along θ₂.
    pub fn set_reference(&mut self, reference: &[f64]) -> Result<(), HbError> {
        let l = self.harmonics.coeff_len();
        if reference.len() != self.coeff_len() {
            return Err(HbError::InvalidInput(format!(
                "the torus reference must have {} coefficients, got {}",
                self.coeff_len(),
                reference.len()
            )));
        }
        let h = self.harmonics.len();
        for (row, x) in self
            .phase
            .chunks_exact_mut(l)
            .zip(reference.chunks_exact(l))
        {
            row.fill(0.0);
            let (Some((_, r)), Some((_, xr))) = (row.split_first_mut(), x.split_first()) else {
                continue;
            };
            let (ra, rb) = r.split_at_mut(h);
            let (xa, xb) = xr.split_at(h);
            // ∂/∂θ₂ (a cos + b sin)(k·θ) = k₂ (b cos − a sin).
            for ((k, (pa, pb)), (a, b)) in self
                .harmonics
                .iter()
                .zip(ra.iter_mut().zip(rb.iter_mut()))
                .zip(xa.iter().zip(xb))
            {
                let k2 = k.1 as f64;
                *pa = k2 * b;
                *pb = -k2 * a;
            }
        }
        let norm = ivt_num::vector::norm2(&self.phase);
        if !(norm.is_finite() && norm > 0.0) {
            return Err(HbError::InvalidInput(
                "the torus reference has no content along θ₂ (a periodic orbit)".into(),
            ));
        }
        self.phase.iter_mut().for_each(|v| *v /= norm);
        Ok(())
    }

    /// The excitation's Galerkin projection at λ (cached per λ): `f(pθ₁)`
    /// moves only the harmonics `(k₁, 0)`.
    fn excitation(&mut self, problem: &F::Problem, lambda: f64) -> &[f64] {
        let stale = self.excitation.as_ref().is_none_or(|e| e.lambda != lambda);
        if stale {
            let (n1, _) = self.grid.dims();
            let (nd, l, h) = (self.n_dof, self.harmonics.coeff_len(), self.harmonics.len());
            let p = self.options.subharmonic as f64;
            let mut coeffs = vec![0.0; nd * l];
            let mut f = vec![0.0; nd];
            let tau = 2.0 * std::f64::consts::PI;
            for i in 0..n1 {
                let theta1 = tau * i as f64 / n1 as f64;
                problem.excitation(p * theta1, &mut f);
                for (block, fd) in coeffs.chunks_exact_mut(l).zip(&f) {
                    if let Some(mean) = block.first_mut() {
                        *mean += fd / n1 as f64;
                    }
                    for (idx, (k1, k2)) in self.harmonics.iter().enumerate() {
                        if k2 != 0 {
                            continue;
                        }
                        let (s, c) = (k1 as f64 * theta1).sin_cos();
                        if let Some(a) = block.get_mut(1 + idx) {
                            *a += 2.0 * fd * c / n1 as f64;
                        }
                        if let Some(b) = block.get_mut(1 + h + idx) {
                            *b += 2.0 * fd * s / n1 as f64;
                        }
                    }
                }
            }
            self.excitation = Some(Projected { lambda, coeffs });
        }
        self.excitation
            .as_ref()
            .map_or(&[], |e| e.coeffs.as_slice())
    }

    /// The frequency ν_k of every kept harmonic for `ω₁ = ω_f/p` and Ω.
    fn frequencies(&self, omega1: f64, omega2: f64) -> Vec<f64> {
        self.harmonics
            .iter()
            .map(|(k1, k2)| k1 as f64 * omega1 + k2 as f64 * omega2)
            .collect()
    }

    /// Samples `x` (and `v` when asked) of every DOF of the torus `coeffs`,
    /// sample-major, for `v = ω₁ ∂X/∂θ₁ + Ω ∂X/∂θ₂`.
    fn synthesize_states(&mut self, coeffs: &[f64], omega1: f64, omega2: f64, velocity: bool) {
        let (nd, l) = (self.n_dof, self.harmonics.coeff_len());
        for (d, block) in coeffs.chunks_exact(l).enumerate().take(nd) {
            self.grid
                .synthesize(&self.harmonics, block, None, &mut self.column);
            scatter(&self.column, nd, d, &mut self.xs);
            if velocity {
                self.grid.synthesize(
                    &self.harmonics,
                    block,
                    Some((omega1, omega2)),
                    &mut self.column,
                );
                scatter(&self.column, nd, d, &mut self.vs);
            }
        }
        if !velocity {
            self.vs.fill(0.0);
        }
    }

    /// `r = L(ν) X` for the matrices of `problem` (per harmonic the 1-D
    /// block of Eq. 60 at `ν_k`), into `r` (`n_dof·L`).
    fn apply_linear(&self, problem: &F::Problem, coeffs: &[f64], nu: &[f64], r: &mut [f64]) {
        let (nd, l, h) = (self.n_dof, self.harmonics.coeff_len(), self.harmonics.len());
        let (m, c, k) = (problem.mass(), problem.damping(), problem.stiffness());
        r.fill(0.0);
        for (d, rd) in r.chunks_exact_mut(l).enumerate() {
            for (e, xe) in coeffs.chunks_exact(l).enumerate() {
                let at = |a: &[f64]| a.get(d * nd + e).copied().unwrap_or(f64::NAN);
                let (mde, cde, kde) = (at(m), at(c), at(k));
                let (Some((r0, rr)), Some((x0, xr))) = (rd.split_first_mut(), xe.split_first())
                else {
                    continue;
                };
                *r0 += 0.5 * kde * x0;
                let (ra, rb) = rr.split_at_mut(h);
                let (xa, xb) = xr.split_at(h);
                for (((ra, rb), (a, b)), &w) in ra
                    .iter_mut()
                    .zip(rb.iter_mut())
                    .zip(xa.iter().zip(xb))
                    .zip(nu)
                {
                    let stiff = kde - w * w * mde;
                    let damp = w * cde;
                    *ra += stiff * a + damp * b;
                    *rb += stiff * b - damp * a;
                }
            }
        }
    }

    /// The torus residual (without the phase row) of `coeffs`, Ω at λ.
    fn balance(&mut self, coeffs: &[f64], omega2: f64, lambda: f64, r: &mut [f64]) {
        let (problem, omega_f) = self.family.at(lambda);
        let omega1 = omega_f / self.options.subharmonic as f64;
        let nu = self.frequencies(omega1, omega2);
        self.apply_linear(&problem, coeffs, &nu, r);
        let exc = self.excitation(&problem, lambda).to_vec();
        for (ri, ei) in r.iter_mut().zip(&exc) {
            *ri -= ei;
        }
        self.synthesize_states(coeffs, omega1, omega2, self.velocity);
        problem.nonlinear_samples(&self.xs, &self.vs, &self.thetas, &mut self.gs);
        let (nd, l) = (self.n_dof, self.harmonics.coeff_len());
        for (d, rd) in r.chunks_exact_mut(l).enumerate() {
            gather(&self.gs, nd, d, &mut self.column);
            self.grid
                .galerkin(&self.harmonics, &self.column, &mut self.rg);
            rd.iter_mut().zip(&self.rg).for_each(|(ri, gi)| *ri += gi);
        }
    }

    /// `(coefficients, Ω)` of the unknowns `q` (`None` for a wrong size).
    fn split<'q>(&self, q: &'q [f64]) -> Option<(&'q [f64], f64)> {
        let (&omega2, coeffs) = q.split_last()?;
        (coeffs.len() == self.coeff_len()).then_some((coeffs, omega2))
    }

    /// The Galerkin sums of one sampled `G` (`∂g_d/∂x_e` or `∂g_d/∂v_e`) into
    /// the coefficient block `block` (rows of `stride`, starting at column
    /// `col0`): `(1/N)·` the product formulas of the module docs, the
    /// velocity columns multiplied by `−ν_k` (cosine) and `ν_k` (sine).
    fn add_sums(&mut self, velocity: Option<&[f64]>, rows: &mut [f64], stride: usize, col0: usize) {
        let h = self.harmonics.len();
        let n = self.grid.len() as f64;
        let bins: Vec<(i64, i64)> = self.harmonics.iter().collect();
        let spectrum: Vec<Complex<f64>> = self.grid.spectrum(&self.column).to_vec();
        let grid = &self.grid;
        // C_l = Re S(l), S_l = −Im S(l).
        let cs = |l1: i64, l2: i64| {
            let s = spectrum
                .get(grid.bin(l1, l2))
                .copied()
                .unwrap_or(Complex::new(f64::NAN, 0.0));
            (s.re / n, -s.im / n)
        };
        // Basis index r: 0 the mean, 1..=h cosines, h+1..=2h sines.
        let kind = |r: usize| -> (u8, (i64, i64)) {
            match r {
                0 => (0, (0, 0)),
                r if r <= h => (1, bins.get(r - 1).copied().unwrap_or((0, 0))),
                r => (2, bins.get(r - 1 - h).copied().unwrap_or((0, 0))),
            }
        };
        // Σ G c_j c_k / (N/2) for basis kinds (0 mean ½, 1 cos, 2 sin).
        let value = |(rk, j): (u8, (i64, i64)), (ck, k): (u8, (i64, i64))| -> f64 {
            let minus = cs(j.0 - k.0, j.1 - k.1);
            let plus = cs(j.0 + k.0, j.1 + k.1);
            match (rk, ck) {
                (0, 0) => 0.5 * cs(0, 0).0,
                (0, 1) => cs(k.0, k.1).0,
                (0, 2) => cs(k.0, k.1).1,
                (1, 0) => cs(j.0, j.1).0,
                (2, 0) => cs(j.0, j.1).1,
                (1, 1) => minus.0 + plus.0,
                (1, 2) => plus.1 - minus.1,
                (2, 1) => plus.1 + minus.1,
                _ => minus.0 - plus.0,
            }
        };
        let l = 2 * h + 1;
        for (r, row) in rows.chunks_exact_mut(stride).enumerate().take(l) {
            let rk = kind(r);
            let Some(cols) = row.get_mut(col0..col0 + l) else {
                continue;
            };
            for (c, entry) in cols.iter_mut().enumerate() {
                let ck = kind(c);
                *entry += match velocity {
                    None => value(rk, ck),
                    Some(nu) => match ck.0 {
                        0 => 0.0,
                        1 => -nu.get(c - 1).copied().unwrap_or(f64::NAN) * value(rk, (2, ck.1)),
                        _ => nu.get(c - 1 - h).copied().unwrap_or(f64::NAN) * value(rk, (1, ck.1)),
                    },
                };
            }
        }
    }
}

/// `column` (one DOF's samples) into DOF `d` of the sample-major `out`.
fn scatter(column: &[f64], nd: usize, d: usize, out: &mut [f64]) {
    for (o, c) in out.iter_mut().skip(d).step_by(nd.max(1)).zip(column) {
        *o = *c;
    }
}

/// DOF `d` of the sample-major `samples` into `column`.
fn gather(samples: &[f64], nd: usize, d: usize, column: &mut [f64]) {
    for (c, s) in column
        .iter_mut()
        .zip(samples.iter().skip(d).step_by(nd.max(1)))
    {
        *c = *s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::GeneralProblem;

    /// A forced Van der Pol oscillator with a cubic spring (velocity and
    /// displacement nonlinearity, two DOFs coupled).
    #[allow(clippy::type_complexity)] // a test fixture: the two closures of a GeneralProblem
    fn chain() -> GeneralProblem<impl Fn(&[f64], &[f64], f64, &mut [f64]), impl Fn(f64, &mut [f64])>
    {
        GeneralProblem::new(
            2,
            vec![1.0, 0.0, 0.0, 1.5],
            vec![-0.2, 0.01, 0.01, 0.05],
            vec![2.0, -1.0, -1.0, 2.0],
            |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| {
                g[0] = 0.2 * x[0] * x[0] * v[0] + 0.3 * x[0] * x[1] * x[1];
                g[1] = 0.5 * x[1].powi(3) + 0.1 * v[0] * x[1];
            },
            |t: f64, f: &mut [f64]| {
                f[0] = 0.3 * t.cos();
                f[1] = 0.1 * (2.0 * t).sin();
            },
        )
    }

    #[test]
    fn the_jacobian_is_the_difference_of_the_residual() {
        let problem = chain();
        let opts = TorusOptions {
            truncation: Truncation::Box { h1: 3, h2: 2 },
            ..TorusOptions::default()
        };
        let family = |w: f64| (&problem, w);
        let harmonics = TorusHarmonics::new(opts.truncation).unwrap();
        let l = harmonics.coeff_len();
        let coeffs: Vec<f64> = (0..2 * l)
            .map(|i| 0.4 * ((i as f64) * 1.3).sin() / (1.0 + 0.2 * i as f64))
            .collect();
        let mut branch = TorusBranch::new(family, &opts, 0.9, &coeffs).unwrap();
        let mut q = coeffs.clone();
        q.push(0.37);
        let m = branch.len();
        let mut jac = vec![0.0; m * m];
        branch.jacobian(&q, 0.9, &mut jac);
        let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
        let mut worst = 0.0f64;
        let scale = jac.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for j in 0..m {
            let h = 1e-6;
            let mut qp = q.clone();
            qp[j] += h;
            branch.residual(&qp, 0.9, &mut rp);
            qp[j] -= 2.0 * h;
            branch.residual(&qp, 0.9, &mut rm);
            for i in 0..m {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                worst = worst.max((fd - jac[i * m + j]).abs());
            }
        }
        assert!(worst < 1e-8 * scale, "{worst:e} of {scale:e}");
    }
}
