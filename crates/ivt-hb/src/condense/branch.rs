//! The condensed harmonic-balance residual in ω_f as a [`Branch`]: the glue
//! between [`super::Receptances`] and the path machinery (the continuation
//! and the fold locator see it in scaled unknowns, `scaled.rs`).
//!
//! Unknowns `q`: the harmonics of the nonlinear DOFs `S` only, in the layout of
//! [`crate::HbResidual`] (`s` blocks `[a0, a1..an, b1..bn]`). The residual is
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
use crate::branch::Branch;
use crate::error::HbError;
use crate::galerkin::GalerkinJacobian;
use crate::ihb::{HbOptions, HbResidual};
use crate::problem::PeriodicProblem;
use faer::{c64, Mat};

/// The condensed HB problem of a sparse structure with a local nonlinearity.
pub struct CondensedBranch<P: PeriodicProblem> {
    structure: Structure,
    coupling: Coupling,
    local: P,
    hb: HbOptions,
    res: HbResidual,
    galerkin: GalerkinJacobian,
    cache: Option<Receptances>,
    /// The last failure to build receptances (reported by the drivers).
    failure: Option<HbError>,
    scratch: Vec<f64>,
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
            .map(|i| c64::new(load_cos[i], -load_sin.get(i).copied().unwrap_or(0.0)))
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
            failure: None,
            scratch: vec![0.0; m],
        })
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

    /// The receptances at ω_f (computed once per ω_f, cached).
    ///
    /// # Errors
    /// [`HbError::Singular`] when a dynamic stiffness or `H_SS` is singular.
    pub fn receptances(&mut self, omega_f: f64) -> Result<&Receptances, HbError> {
        self.ensure(omega_f)?;
        self.cached()
    }

    /// Computes the receptances at ω_f unless cached.
    fn ensure(&mut self, omega_f: f64) -> Result<(), HbError> {
        let fresh = self.cache.as_ref().is_some_and(|c| c.omega_f == omega_f);
        if !fresh {
            self.cache = None;
            let r = Receptances::new(&self.structure, &self.coupling, self.hb.harmonics, omega_f)?;
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
        let u = &rc.responses[p];
        for (d, &dof) in self.coupling.dofs.iter().enumerate() {
            q[d * l + p] = u[(dof, s)].re;
            q[d * l + n + p] = -u[(dof, s)].im;
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
                for h in 0..=n {
                    let u = &rc.responses[h];
                    let mut x = if h == p {
                        u[(j, s)]
                    } else {
                        c64::new(0.0, 0.0)
                    };
                    for b in 0..s {
                        let g = if h == 0 {
                            c64::new(force[b * l], 0.0)
                        } else {
                            c64::new(force[b * l + h], -force[b * l + n + h])
                        };
                        x -= u[(j, b)] * g;
                    }
                    if h == 0 {
                        coeffs[0] = 2.0 * x.re;
                    } else {
                        coeffs[h] = x.re;
                        coeffs[n + h] = -x.im;
                    }
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
        let l = 2 * n + 1;
        let mut g = vec![c64::new(0.0, 0.0); s];
        let zero = c64::new(0.0, 0.0);
        for h in 0..=n {
            for (b, gb) in g.iter_mut().enumerate() {
                *gb = if h == 0 {
                    c64::new(out[b * l], 0.0)
                } else {
                    c64::new(out[b * l + h], -out[b * l + n + h])
                };
            }
            for d in 0..s {
                let mut z = response.map_or(zero, |u| -u[h][(d, 0)]);
                if let Some(q) = q {
                    z += if h == 0 {
                        c64::new(0.5 * q[d * l], 0.0)
                    } else {
                        c64::new(q[d * l + h], -q[d * l + n + h])
                    };
                }
                for (b, gb) in g.iter().enumerate() {
                    z += receptance[h][(d, b)] * gb;
                }
                if h == 0 {
                    out[d * l] = z.re;
                } else {
                    out[d * l + h] = z.re;
                    out[d * l + n + h] = -z.im;
                }
            }
        }
    }

    /// `jac = I_X + H·jac` (row-major `m×m`), `jac` holding `∂G/∂q` on entry.
    fn condense_jacobian(&self, rc: &Receptances, jac: &mut [f64]) {
        let (s, n) = (self.coupling.dofs.len(), self.hb.harmonics);
        let l = 2 * n + 1;
        let m = s * l;
        let mut rows = vec![0.0; 2 * s * m];
        for h in 0..=n {
            // The rows of G_h (a then b for each local DOF) before overwriting.
            for b in 0..s {
                let (ra, rb) = (b * l + h, b * l + n + h);
                rows[b * m..(b + 1) * m].copy_from_slice(&jac[ra * m..(ra + 1) * m]);
                if h > 0 {
                    rows[(s + b) * m..(s + b + 1) * m].copy_from_slice(&jac[rb * m..(rb + 1) * m]);
                }
            }
            for d in 0..s {
                let (ra, rb) = (d * l + h, d * l + n + h);
                for c in 0..m {
                    let (mut re, mut im) = (0.0, 0.0);
                    for b in 0..s {
                        let z = rc.receptance[h][(d, b)];
                        let ja = rows[b * m + c];
                        if h == 0 {
                            re += z.re * ja;
                        } else {
                            let jb = rows[(s + b) * m + c];
                            // H (J_a − i J_b): real part, and minus the imaginary part.
                            re += z.re * ja + z.im * jb;
                            im += z.re * jb - z.im * ja;
                        }
                    }
                    jac[ra * m + c] = re;
                    if h > 0 {
                        jac[rb * m + c] = im;
                    }
                }
                if h == 0 {
                    jac[ra * m + ra] += 0.5;
                } else {
                    jac[ra * m + ra] += 1.0;
                    jac[rb * m + rb] += 1.0;
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
        match self.ensure(omega_f) {
            Ok(()) => {
                let rc = self.cache.take();
                if let Some(rc) = rc.as_ref() {
                    f(self, rc, out);
                }
                self.cache = rc;
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
        self.with_receptances(lambda, jac, |b, rc, j| b.condense_jacobian(rc, j));
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
