//! The condensed harmonic-balance residual in ω_f as a [`Branch`]: the glue
//! between [`super::Receptances`] and the path machinery (the continuation
//! and the fold locator see it in scaled unknowns, `scaled.rs`).
//!
//! Unknowns `q`: the harmonics of the nonlinear DOFs `S` only, in the layout of
//! [`ivt_hb::HbResidual`] (`s` blocks `[a0, a1..an, b1..bn]`). The residual is
//!
//! `R_h(q, ω_f) = X_h − u_h(ω) + H_h(ω) G_h(q, ω_f)` per harmonic h
//!
//! (complex, split into the rows of `a_h` and `b_h`; `X_0 = a0/2`), where `G` is
//! the local problem's own HB residual (Eq. 61: its `g` on the DOFs `S`, plus
//! any `M`, `C`, `K`, `f` it carries there) and `H_h`, `u_h` the receptance and
//! linear response of the sparse structure at `S`. Its Jacobian is
//! `I + H ∂G/∂q` with the local Galerkin Jacobian (Eq. 56), and `∂R/∂ω_f` is
//! exact (`∂H/∂ω_f` from transposed solves).

use super::dynamic::Structure;
use super::receptance::{Coupling, Receptances};
use faer::{c64, Mat};
use ivt_hb::orbit::galerkin::GalerkinJacobian;
use ivt_hb::orbit::ihb::{HbOptions, HbResidual};
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::HbError;
use ivt_path::branch::{bilinear_form, Branch};

/// The condensed HB problem of a sparse structure with a local nonlinearity.
pub struct CondensedBranch<P: PeriodicProblem> {
    structure: Structure,
    coupling: Coupling,
    local: P,
    hb: HbOptions,
    res: HbResidual,
    galerkin: GalerkinJacobian,
    /// The receptances of the last exact evaluation.
    cache: Option<Receptances>,
    /// Their Taylor model at another ω_f ([`Receptances::taylor`]), serving
    /// the path callbacks there.
    model: Option<Receptances>,
    /// The last failure to build receptances (reported by the drivers).
    failure: Option<HbError>,
    scratch: Vec<f64>,
    /// The structure's own relative receptance error (a reduced model's
    /// certified estimate; 0 for the whole structure), added to
    /// [`Self::data_error`].
    model_error: f64,
}

impl<P: PeriodicProblem> CondensedBranch<P> {
    /// The structure with the nonlinear DOFs `dofs` (the local problem's DOF
    /// `i` is the structure's `dofs[i]`) and the load
    /// `f(θ) = load_cos cos θ + load_sin sin θ` (θ = ω_f t; vectors of
    /// `n_dof`, `load_sin` may be empty for zero).
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for DOFs out of range or repeated, loads of the
    /// wrong length or not finite, or invalid HB sizes.
    pub fn new(
        structure: Structure,
        dofs: Vec<usize>,
        load_cos: &[f64],
        load_sin: &[f64],
        local: P,
        hb: &HbOptions,
    ) -> Result<Self, HbError> {
        let n = structure.n_dof();
        let mut sorted = dofs.clone();
        sorted.sort_unstable();
        sorted.dedup();
        if dofs.is_empty() || sorted.len() != dofs.len() || sorted.last().is_some_and(|&d| d >= n) {
            return Err(HbError::InvalidInput(format!(
                "nonlinear DOFs must be distinct indices below n_dof = {n}"
            )));
        }
        if local.n_dof() != dofs.len() {
            return Err(HbError::InvalidInput(format!(
                "the local problem has {} DOFs for {} nonlinear DOFs",
                local.n_dof(),
                dofs.len()
            )));
        }
        let sin_ok = load_sin.is_empty() || load_sin.len() == n;
        if load_cos.len() != n || !sin_ok {
            return Err(HbError::InvalidInput(format!(
                "load vectors must have n_dof = {n} entries"
            )));
        }
        if !load_cos.iter().chain(load_sin).all(|v| v.is_finite()) {
            return Err(HbError::InvalidInput("load vectors must be finite".into()));
        }
        let load = (0..n)
            .map(|i| {
                let cos = load_cos.get(i).copied().unwrap_or(0.0);
                c64::new(cos, -load_sin.get(i).copied().unwrap_or(0.0))
            })
            .collect();
        let res = HbResidual::new(&local, hb)?;
        let galerkin = GalerkinJacobian::new(&res);
        let m = res.len();
        Ok(Self {
            structure,
            coupling: Coupling {
                dofs,
                load,
                load_harmonic: hb.subharmonic,
            },
            local,
            hb: hb.clone(),
            res,
            galerkin,
            cache: None,
            model: None,
            failure: None,
            scratch: vec![0.0; m],
            model_error: 0.0,
        })
    }

    /// The branch of a structure whose receptances are off by `error`
    /// (relative) from the true structure's: a reduced model
    /// ([`super::reduce::ReducedModel`]). [`Self::data_error`] and so every
    /// point's `orbit_error` carry it.
    pub fn with_model_error(mut self, error: f64) -> Self {
        self.model_error = error.max(0.0);
        self
    }

    /// The HB options.
    pub fn options(&self) -> &HbOptions {
        &self.hb
    }

    /// The sparse structure.
    pub fn structure(&self) -> &Structure {
        &self.structure
    }

    /// The nonlinear DOFs `S`.
    pub fn dofs(&self) -> &[usize] {
        &self.coupling.dofs
    }

    /// The local problem.
    pub fn local(&self) -> &P {
        &self.local
    }

    /// The receptances at ω_f, exact (computed once per ω_f, cached).
    ///
    /// # Errors
    /// [`HbError::Singular`] when a dynamic stiffness or `H_SS` is singular.
    pub fn receptances(&mut self, omega_f: f64) -> Result<&Receptances, HbError> {
        self.ensure(omega_f)?;
        self.cached()
    }

    /// The receptances the path callbacks see at ω_f: the exact ones, or
    /// their Taylor model about the last exact evaluation when its estimated
    /// error is within [`super::receptance::MODEL_TOLERANCE`] (counted in
    /// its `solve_error`).
    fn modelled(&mut self, omega_f: f64) -> Result<&Receptances, HbError> {
        let at = |r: &Option<Receptances>| r.as_ref().is_some_and(|r| r.omega_f == omega_f);
        if !at(&self.cache) && !at(&self.model) {
            self.model = self.cache.as_ref().and_then(|c| c.taylor(omega_f));
        }
        if at(&self.model) {
            return self
                .model
                .as_ref()
                .ok_or_else(|| HbError::InvalidInput("receptance model missing".into()));
        }
        self.receptances(omega_f)
    }

    /// The estimated relative error of the receptances the path used at
    /// ω_f (exact or modelled).
    ///
    /// # Errors
    /// As [`Self::receptances`].
    pub fn solve_error(&mut self, omega_f: f64) -> Result<f64, HbError> {
        Ok(self.modelled(omega_f)?.solve_error)
    }

    /// Computes the receptances at ω_f unless cached.
    fn ensure(&mut self, omega_f: f64) -> Result<(), HbError> {
        let fresh = self.cache.as_ref().is_some_and(|c| c.omega_f == omega_f);
        if !fresh {
            self.model = None;
            let previous = self.cache.take();
            let r = Receptances::reusing(
                &self.structure,
                &self.coupling,
                self.hb.harmonics,
                omega_f,
                previous,
            )?;
            self.cache = Some(r);
        }
        Ok(())
    }

    /// The cached receptances.
    fn cached(&self) -> Result<&Receptances, HbError> {
        self.cache
            .as_ref()
            .ok_or_else(|| HbError::InvalidInput("receptances missing".into()))
    }

    /// The relative change of the receptances at ω_f from the rounding of
    /// the stored `M` and `C` ([`Receptances::data_error`]); where the path
    /// used a Taylor model at ω_f, the change at the model's exact base
    /// (within the model's radius, where the receptances move by less than
    /// 1e-5 relative: the same estimate to its first digits); plus the
    /// model's own error ([`Self::with_model_error`]).
    ///
    /// # Errors
    /// As [`Self::receptances`].
    pub fn data_error(&mut self, omega_f: f64) -> Result<f64, HbError> {
        let modelled = self.model.as_ref().is_some_and(|m| m.omega_f == omega_f);
        if !modelled {
            self.ensure(omega_f)?;
        }
        let rounding = self.cached()?.data_error(&self.structure, &self.coupling);
        Ok(rounding + self.model_error)
    }

    /// Takes the last receptance failure seen by the path callbacks (which
    /// cannot return errors and answer with a non-finite residual instead).
    pub fn take_failure(&mut self) -> Option<HbError> {
        self.failure.take()
    }

    /// The linear response `q` of the nonlinear DOFs at ω_f (`g` = 0): the
    /// start of a curve.
    ///
    /// # Errors
    /// As [`Self::receptances`].
    pub fn linear_guess(&mut self, omega_f: f64) -> Result<Vec<f64>, HbError> {
        let (s, n, p) = (
            self.coupling.dofs.len(),
            self.hb.harmonics,
            self.hb.subharmonic,
        );
        let l = 2 * n + 1;
        self.ensure(omega_f)?;
        let rc = self.cached()?;
        let mut q = vec![0.0; s * l];
        if let Some(u) = rc.responses.get(p) {
            for (d, &dof) in self.coupling.dofs.iter().enumerate() {
                put_harmonic(&mut q, n, d, p, u[(dof, s)]);
            }
        }
        Ok(q)
    }

    /// The coefficients `[a0, a1..an, b1..bn]` of every DOF in `dofs` of the
    /// full structure for the condensed orbit `q` at ω_f:
    /// `X_j = U_F,j − U_S,j G` per harmonic, `G` the local force.
    ///
    /// # Errors
    /// As [`Self::receptances`]; [`HbError::InvalidInput`] for a DOF out of range.
    pub fn recover(
        &mut self,
        q: &[f64],
        omega_f: f64,
        dofs: &[usize],
    ) -> Result<Vec<Vec<f64>>, HbError> {
        let (s, n) = (self.coupling.dofs.len(), self.hb.harmonics);
        if let Some(&bad) = dofs.iter().find(|&&d| d >= self.structure.n_dof()) {
            return Err(HbError::InvalidInput(format!("DOF {bad} is out of range")));
        }
        if dofs.is_empty() {
            return Ok(Vec::new());
        }
        let l = 2 * n + 1;
        let mut force = std::mem::take(&mut self.scratch);
        self.res.eval(&self.local, q, omega_f, 1.0, &mut force);
        self.scratch = force;
        self.ensure(omega_f)?;
        let force = &self.scratch;
        let rc = self.cached()?;
        let p = self.coupling.load_harmonic;
        let out = dofs
            .iter()
            .map(|&j| {
                let mut coeffs = vec![0.0; l];
                for (h, u) in rc.responses.iter().enumerate().take(n + 1) {
                    let mut x = if h == p {
                        u[(j, s)]
                    } else {
                        c64::new(0.0, 0.0)
                    };
                    for b in 0..s {
                        x -= u[(j, b)] * harmonic(force, n, b, h);
                    }
                    // X_0 = a0/2.
                    let x = if h == 0 { 2.0 * x } else { x };
                    put_harmonic(&mut coeffs, n, 0, h, x);
                }
                coeffs
            })
            .collect();
        Ok(out)
    }

    /// `out = X(q) − u + H·out` per harmonic, `out` holding a local force
    /// (Galerkin coefficients) on entry; the `X(q)` term only with `q`, the
    /// `u` term only with `response`.
    fn combine(
        &self,
        receptance: &[Mat<c64>],
        response: Option<&[Mat<c64>]>,
        q: Option<&[f64]>,
        out: &mut [f64],
    ) {
        let (s, n) = (self.coupling.dofs.len(), self.hb.harmonics);
        let zero = c64::new(0.0, 0.0);
        for (h, hm) in receptance.iter().enumerate().take(n + 1) {
            let g: Vec<c64> = (0..s).map(|b| harmonic(out, n, b, h)).collect();
            for d in 0..s {
                let mut z = response.and_then(|u| u.get(h)).map_or(zero, |u| -u[(d, 0)]);
                if let Some(q) = q {
                    // X_0 = a0/2.
                    let x = harmonic(q, n, d, h);
                    z += if h == 0 { 0.5 * x } else { x };
                }
                for (b, gb) in g.iter().enumerate() {
                    z += hm[(d, b)] * gb;
                }
                put_harmonic(out, n, d, h, z);
            }
        }
    }

    /// `jac = I_X + H·jac` (row-major `m×m`), `jac` holding `∂G/∂q` on entry;
    /// without `identity`, `jac = H·jac` (`H` any per-harmonic family: the
    /// receptances or their ω_f-derivatives).
    ///
    /// `∂G/∂q` couples two nonlinear DOFs only where an element joins them,
    /// so its `(2n + 1)`-square blocks are mostly zero when many elements
    /// each act on their own DOF (a contact patch): the sum over the blocks
    /// of a column runs over its nonzero blocks only, `O(n·s·m·k)` for `k`
    /// nonzero blocks per column instead of `O(n·s²·m)` (zero blocks add
    /// nothing, so the result is the same).
    fn condense_jacobian(&self, receptance: &[Mat<c64>], identity: bool, jac: &mut [f64]) {
        let (s, n) = (self.coupling.dofs.len(), self.hb.harmonics);
        let l = 2 * n + 1;
        let m = s * l;
        // The blocks b with a nonzero block (b, e) of ∂G/∂q, per column block e.
        let coupled: Vec<Vec<usize>> = (0..s)
            .map(|e| {
                (0..s)
                    .filter(|&b| {
                        (b * l..(b + 1) * l).any(|row| {
                            jac.get(row * m + e * l..row * m + (e + 1) * l)
                                .is_some_and(|block| block.iter().any(|&v| v != 0.0))
                        })
                    })
                    .collect()
            })
            .collect();
        let mut rows = vec![0.0; 2 * s * m];
        let copy = |rows: &mut [f64], slot: usize, jac: &[f64], row: usize| {
            let dst = rows.get_mut(slot * m..(slot + 1) * m);
            if let (Some(dst), Some(src)) = (dst, jac.get(row * m..(row + 1) * m)) {
                dst.copy_from_slice(src);
            }
        };
        for (h, hm) in receptance.iter().enumerate().take(n + 1) {
            // The rows of G_h (a then b for each local DOF) before overwriting.
            for b in 0..s {
                copy(&mut rows, b, jac, b * l + h);
                if h > 0 {
                    copy(&mut rows, s + b, jac, b * l + n + h);
                }
            }
            let at = |i: usize| rows.get(i).copied().unwrap_or(0.0);
            for d in 0..s {
                let (ra, rb) = (d * l + h, d * l + n + h);
                for c in 0..m {
                    let (mut re, mut im) = (0.0, 0.0);
                    for &b in coupled.get(c / l).into_iter().flatten() {
                        let z = hm[(d, b)];
                        let ja = at(b * m + c);
                        if h == 0 {
                            re += z.re * ja;
                        } else {
                            let jb = at((s + b) * m + c);
                            // H (J_a − i J_b): real part, and minus the imaginary part.
                            re += z.re * ja + z.im * jb;
                            im += z.re * jb - z.im * ja;
                        }
                    }
                    if let Some(v) = jac.get_mut(ra * m + c) {
                        *v = re;
                    }
                    if let Some(v) = jac.get_mut(rb * m + c).filter(|_| h > 0) {
                        *v = im;
                    }
                }
                // X_0 = a0/2: the identity's first entry is ½.
                let diagonal = match (identity, h) {
                    (false, _) => [None, None],
                    (true, 0) => [Some((ra, 0.5)), None],
                    (true, _) => [Some((ra, 1.0)), Some((rb, 1.0))],
                };
                for (r, v) in diagonal.into_iter().flatten() {
                    if let Some(e) = jac.get_mut(r * m + r) {
                        *e += v;
                    }
                }
            }
        }
    }

    /// Runs `f` with the receptances at ω_f, or records the failure and
    /// fills `out` with NaN (the correctors then reject the step).
    fn with_receptances(
        &mut self,
        omega_f: f64,
        out: &mut [f64],
        f: impl FnOnce(&Self, &Receptances, &mut [f64]),
    ) {
        match self.modelled(omega_f).map(|_| ()) {
            Ok(()) => {
                let (exact, model) = (self.cache.take(), self.model.take());
                let at = [model.as_ref(), exact.as_ref()].into_iter().flatten();
                if let Some(rc) = at.into_iter().find(|r| r.omega_f == omega_f) {
                    f(self, rc, out);
                }
                (self.cache, self.model) = (exact, model);
            }
            Err(e) => {
                self.failure = Some(e);
                out.fill(f64::NAN);
            }
        }
    }

    /// `∂r_local/∂ω_f`: the local linear part's derivative (exact central
    /// difference of a quadratic in ω) and, for a velocity-dependent `g`, the
    /// central difference of the whole local residual.
    fn local_lambda_derivative(&mut self, q: &[f64], omega_f: f64, out: &mut [f64]) {
        let h = 1e-6 * omega_f.abs().max(1.0);
        let mut minus = std::mem::take(&mut self.scratch);
        if self.local.velocity_dependent() {
            self.res.eval(&self.local, q, omega_f + h, 1.0, out);
            self.res.eval(&self.local, q, omega_f - h, 1.0, &mut minus);
        } else {
            let p = self.hb.subharmonic as f64;
            self.res
                .apply_linear(&self.local, q, (omega_f + h) / p, out);
            self.res
                .apply_linear(&self.local, q, (omega_f - h) / p, &mut minus);
        }
        for (o, m) in out.iter_mut().zip(&minus) {
            *o = (*o - m) / (2.0 * h);
        }
        self.scratch = minus;
    }
}

/// The complex harmonic `h` of block `d` of `v` (blocks `[a0, a1..an,
/// b1..bn]`): `a_h − i b_h`, `a0` for `h = 0` (0 past the end).
fn harmonic(v: &[f64], n: usize, d: usize, h: usize) -> c64 {
    let l = 2 * n + 1;
    let get = |i: usize| v.get(d * l + i).copied().unwrap_or(0.0);
    if h == 0 {
        c64::new(get(0), 0.0)
    } else {
        c64::new(get(h), -get(n + h))
    }
}

/// Stores `z` as harmonic `h` of block `d` of `v` ([`harmonic`]'s inverse;
/// `Re z` alone for `h = 0`).
fn put_harmonic(v: &mut [f64], n: usize, d: usize, h: usize, z: c64) {
    let l = 2 * n + 1;
    let parts = if h == 0 {
        [(0, z.re), (0, z.re)]
    } else {
        [(h, z.re), (n + h, -z.im)]
    };
    for (i, x) in parts {
        if let Some(e) = v.get_mut(d * l + i) {
            *e = x;
        }
    }
}

impl<P: PeriodicProblem> Branch for CondensedBranch<P> {
    fn len(&self) -> usize {
        self.res.len()
    }
    fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]) {
        self.res.eval(&self.local, q, lambda, 1.0, r);
        self.with_receptances(lambda, r, |b, rc, r| {
            b.combine(&rc.receptance, Some(&rc.response), Some(q), r)
        });
    }
    fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]) {
        self.galerkin
            .assemble(&mut self.res, &self.local, q, lambda, 1.0, jac);
        self.with_receptances(lambda, jac, |b, rc, j| {
            b.condense_jacobian(&rc.receptance, true, j)
        });
    }
    /// Exact in the receptances: `∂J/∂ω_f = H′ ∂G/∂q + H ∂²G/∂q∂ω_f` at
    /// the receptances of ω_f (no factorization at ω_f ± h, where the
    /// default difference of two Jacobians needed two sets: the N = 500
    /// beam's curve at 10 % steps took 0.96–1.07 s with it, 0.88–0.89 s
    /// with this, the folds the same to 12 digits; measured, not asserted,
    /// docs/guide/src/accuracy-speed.md). `∂²G/∂q∂ω_f` is the
    /// central difference of the local Galerkin Jacobian (Eq. 56) with step
    /// `1e-6·max(|ω_f|, 1)`: exact to rounding for a `g` of positions (the
    /// local linear part is quadratic in ω, `g`'s part cancels).
    fn bilinear_lambda(&mut self, q: &[f64], lambda: f64, _h: f64, w: &[f64], v: &[f64]) -> f64 {
        let m = self.res.len();
        let h = 1e-6 * lambda.abs().max(1.0);
        // [∂G/∂q; ∂²G/∂q∂ω_f], each m×m.
        let mut both = vec![0.0; 2 * m * m];
        let mut minus = vec![0.0; m * m];
        let (jg, djg) = both.split_at_mut(m * m);
        self.galerkin
            .assemble(&mut self.res, &self.local, q, lambda, 1.0, jg);
        self.galerkin
            .assemble(&mut self.res, &self.local, q, lambda + h, 1.0, djg);
        self.galerkin
            .assemble(&mut self.res, &self.local, q, lambda - h, 1.0, &mut minus);
        djg.iter_mut()
            .zip(&minus)
            .for_each(|(p, m)| *p = (*p - m) / (2.0 * h));
        self.with_receptances(lambda, &mut both, |b, rc, both| {
            let (jg, djg) = both.split_at_mut(m * m);
            b.condense_jacobian(&rc.d_receptance, false, jg);
            b.condense_jacobian(&rc.receptance, false, djg);
        });
        let (jg, djg) = both.split_at(m * m);
        bilinear_form(jg, w, v) + bilinear_form(djg, w, v)
    }
    /// Exact: `∂H/∂ω_f G − ∂u/∂ω_f + H ∂G/∂ω_f`.
    fn residual_lambda(&mut self, q: &[f64], lambda: f64, _h: f64, out: &mut [f64]) {
        let mut force = vec![0.0; out.len()];
        self.res.eval(&self.local, q, lambda, 1.0, &mut force);
        self.local_lambda_derivative(q, lambda, out);
        self.with_receptances(lambda, out, |b, rc, o| {
            b.combine(&rc.receptance, None, None, o);
            b.combine(&rc.d_receptance, Some(&rc.d_response), None, &mut force);
            o.iter_mut().zip(&force).for_each(|(a, c)| *a += c);
        });
    }
}

#[cfg(test)]
mod tests;
