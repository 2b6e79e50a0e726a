//! The uncondensed harmonic balance of the cantilever with its residual in
//! double-double: a reference for the condensed orbit that a plain double
//! solve cannot give at N = 20 (its residual floor ε‖K‖‖x‖ ≈ 2e-12 of the
//! force, amplified near the folds to a few 1e-9 in the coefficients).
//!
//! The equations are written out here, not taken from ivt-hb: for
//! `x_i(τ) = a_i0 + Σ_h a_ih cos hτ + b_ih sin hτ` (τ = ωt, DOF-major
//! `[a0, a1..an, b1..bn]` per DOF),
//!
//! `Σ_j (K_ij − (hω)² M_ij) a_jh + hω C_ij b_jh + G^c_ih = F^c_ih`,
//! `Σ_j (K_ij − (hω)² M_ij) b_jh − hω C_ij a_jh + G^s_ih = F^s_ih`,
//!
//! with `G` the Fourier coefficients of `k3 x_tip³` (exact on 64 samples
//! for n ≤ 10) and `F` the tip force `F cos τ`. The stored matrix entries
//! and the coefficients are doubles, so each product is exact in
//! double-double and only the sums round (≈ 1e-32): Newton refinement with
//! a difference Jacobian in double then converges to the solution of the
//! same stored equations the condensed solver uses, to about ε of its
//! coefficients.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use super::beam::{dense, FORCE, K3};
use super::dd::Dd;
use faer::linalg::solvers::Solve;
use faer::Mat;
use ivt_condense::models::{cantilever, BeamProperties};

/// The uncondensed cantilever: its stored dense matrices (row-major
/// `nd × nd`), the tip, the harmonics.
pub struct FullBeam {
    k: Vec<f64>,
    m: Vec<f64>,
    c: Vec<f64>,
    nd: usize,
    tip: usize,
    harmonics: usize,
}

const SAMPLES: usize = 64;

impl FullBeam {
    /// The `n_elements` beam of `common/beam.rs` (tip spring `K3`, force
    /// `FORCE`) with `harmonics` harmonics.
    pub fn new(n_elements: usize, harmonics: usize) -> Self {
        let b = cantilever(n_elements, &BeamProperties::default()).unwrap();
        Self {
            k: dense(&b.model.k),
            m: dense(&b.model.m),
            c: dense(&b.model.c),
            nd: b.model.n_dof(),
            tip: b.tip,
            harmonics,
        }
    }

    fn len(&self) -> usize {
        self.nd * (2 * self.harmonics + 1)
    }

    /// The tip spring's Fourier coefficients `[G0, Gc_1..n, Gs_1..n]`.
    fn spring(&self, x: &[f64]) -> Vec<f64> {
        let n = self.harmonics;
        let q = &x[self.tip * (2 * n + 1)..(self.tip + 1) * (2 * n + 1)];
        let mut g = vec![0.0; 2 * n + 1];
        for s in 0..SAMPLES {
            let tau = 2.0 * std::f64::consts::PI * s as f64 / SAMPLES as f64;
            let mut xt = q[0];
            for h in 1..=n {
                let (sn, cs) = (h as f64 * tau).sin_cos();
                xt += q[h] * cs + q[n + h] * sn;
            }
            let f = K3 * xt * xt * xt;
            g[0] += f / SAMPLES as f64;
            for h in 1..=n {
                let (sn, cs) = (h as f64 * tau).sin_cos();
                g[h] += 2.0 * f * cs / SAMPLES as f64;
                g[n + h] += 2.0 * f * sn / SAMPLES as f64;
            }
        }
        g
    }

    /// The residual in double-double, rounded to double at the end.
    pub fn residual(&self, x: &[f64], omega: f64) -> Vec<f64> {
        let (nd, n) = (self.nd, self.harmonics);
        let w = 2 * n + 1;
        let g = self.spring(x);
        let mut r = vec![0.0; self.len()];
        for i in 0..nd {
            for h in 0..=n {
                let hw = Dd::new(h as f64).mul(Dd::new(omega));
                let hw2 = hw.mul(hw);
                let (mut rc, mut rs) = (Dd::default(), Dd::default());
                for j in 0..nd {
                    let (kij, mij, cij) =
                        (self.k[i * nd + j], self.m[i * nd + j], self.c[i * nd + j]);
                    if kij == 0.0 && mij == 0.0 && cij == 0.0 {
                        continue;
                    }
                    let a = x[j * w + h];
                    let stiff = |v: f64| {
                        Dd::new(kij)
                            .mul(Dd::new(v))
                            .sub(hw2.mul(Dd::new(mij).mul(Dd::new(v))))
                    };
                    rc = rc.add(stiff(a));
                    if h > 0 {
                        let b = x[j * w + n + h];
                        rc = rc.add(hw.mul(Dd::new(cij).mul(Dd::new(b))));
                        rs = rs.add(stiff(b)).sub(hw.mul(Dd::new(cij).mul(Dd::new(a))));
                    }
                }
                if i == self.tip {
                    rc = rc.add(Dd::new(g[h]));
                    if h == 1 {
                        rc = rc.sub(Dd::new(FORCE));
                    }
                    if h > 0 {
                        rs = rs.add(Dd::new(g[n + h]));
                    }
                }
                r[i * w + h] = rc.to_f64();
                if h > 0 {
                    r[i * w + n + h] = rs.to_f64();
                }
            }
        }
        r
    }

    /// Newton from `x` with the residual in double-double and a central
    /// difference Jacobian (exact up to rounding for the cubic spring):
    /// returns the refined coefficients and `‖R‖∞/F` at them.
    pub fn refine(&self, mut x: Vec<f64>, omega: f64) -> (Vec<f64>, f64) {
        // Two rounds, the Jacobian taken again at the first round's result.
        for _ in 0..2 {
            x = self.newton(x, omega);
        }
        let r = self.residual(&x, omega);
        let worst = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        (x, worst / FORCE)
    }

    /// Chord Newton from `x` on the Jacobian at `x`.
    fn newton(&self, mut x: Vec<f64>, omega: f64) -> Vec<f64> {
        let len = self.len();
        let scale = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let mut jac = Mat::<f64>::zeros(len, len);
        for col in 0..len {
            let step = 1e-6 * scale;
            let mut xp = x.clone();
            xp[col] += step;
            let rp = self.residual(&xp, omega);
            xp[col] -= 2.0 * step;
            let rm = self.residual(&xp, omega);
            for row in 0..len {
                jac[(row, col)] = (rp[row] - rm[row]) / (2.0 * step);
            }
        }
        let lu = jac.partial_piv_lu();
        for _ in 0..8 {
            let r = self.residual(&x, omega);
            let rhs = Mat::<f64>::from_fn(len, 1, |i, _| r[i]);
            let dx = lu.solve(&rhs);
            let mut change = 0.0f64;
            for (i, v) in x.iter_mut().enumerate() {
                *v -= dx[(i, 0)];
                change = change.max(dx[(i, 0)].abs());
            }
            if change <= 1e-16 * scale {
                break;
            }
        }
        x
    }
}
