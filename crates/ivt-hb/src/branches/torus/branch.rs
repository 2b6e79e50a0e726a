//! The torus family as a [`Branch`] of the path engine: the residual of
//! the two-frequency harmonic balance on the torus grid, its phase row, and
//! the Jacobian.

use super::*;

impl<F: Family> Branch for TorusBranch<F> {
    fn len(&self) -> usize {
        self.coeff_len() + 1
    }

    fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]) {
        let (Some((coeffs, omega2)), Some((phase, rb))) = (self.split(q), r.split_last_mut())
        else {
            return r.fill(f64::NAN);
        };
        self.balance(coeffs, omega2, lambda, rb);
        *phase = self.phase.iter().zip(coeffs).map(|(a, b)| a * b).sum();
    }

    /// The exact 2-D Galerkin Jacobian (module docs), the Ω column (the
    /// linear part's `∂ν_k/∂Ω = k₂` and `Σ_e ∂g_d/∂v_e ∂X_e/∂θ₂`) and the
    /// phase row.
    fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]) {
        let m = self.len();
        let Some((coeffs, omega2)) = self.split(q) else {
            return jac.fill(f64::NAN);
        };
        if jac.len() != m * m {
            return jac.fill(f64::NAN);
        }
        let coeffs = coeffs.to_vec();
        let (nd, l, h) = (self.n_dof, self.harmonics.coeff_len(), self.harmonics.len());
        let (problem, omega_f) = self.family.at(lambda);
        let omega1 = omega_f / self.options.subharmonic as f64;
        let nu = self.frequencies(omega1, omega2);
        jac.fill(0.0);
        // The linear part, column by column of each DOF block (unit vectors).
        let (mm, cc, kk) = (problem.mass(), problem.damping(), problem.stiffness());
        for d in 0..nd {
            for e in 0..nd {
                let at = |a: &[f64]| a.get(d * nd + e).copied().unwrap_or(f64::NAN);
                let (mde, cde, kde) = (at(mm), at(cc), at(kk));
                let mut set = |row: usize, col: usize, v: f64| {
                    if let Some(x) = jac.get_mut((d * l + row) * m + e * l + col) {
                        *x += v;
                    }
                };
                set(0, 0, 0.5 * kde);
                for (i, &w) in nu.iter().enumerate() {
                    let stiff = kde - w * w * mde;
                    let damp = w * cde;
                    set(1 + i, 1 + i, stiff);
                    set(1 + i, 1 + h + i, damp);
                    set(1 + h + i, 1 + i, -damp);
                    set(1 + h + i, 1 + h + i, stiff);
                }
            }
        }
        // The nonlinear part.
        self.synthesize_states(&coeffs, omega1, omega2, true);
        problem.nonlinear_jacobian_samples(&self.xs, &self.vs, &self.thetas, &mut self.dg);
        let n2 = nd * nd;
        for d in 0..nd {
            for e in 0..nd {
                for (offset, velocity) in [(0, false), (n2, true)] {
                    if velocity && !self.velocity {
                        continue;
                    }
                    let entry = self.dg.iter().skip(offset + d * nd + e).step_by(2 * n2);
                    self.column.iter_mut().zip(entry).for_each(|(c, g)| *c = *g);
                    if self.column.iter().all(|&g| g == 0.0) {
                        continue;
                    }
                    let Some(rows) = jac.get_mut(d * l * m..(d + 1) * l * m) else {
                        continue;
                    };
                    let nu_v = velocity.then_some(nu.as_slice());
                    self.add_sums(nu_v, rows, m, e * l);
                }
            }
        }
        // The Ω column: linear part, then Σ_e ∂g_d/∂v_e · ∂X_e/∂θ₂.
        let col = m - 1;
        for d in 0..nd {
            for e in 0..nd {
                let at = |a: &[f64]| a.get(d * nd + e).copied().unwrap_or(f64::NAN);
                let (mde, cde) = (at(mm), at(cc));
                let Some(xe) = coeffs.get(e * l..(e + 1) * l) else {
                    continue;
                };
                for (i, ((k, &w), (&a, &b))) in self
                    .harmonics
                    .iter()
                    .zip(&nu)
                    .zip(xe.iter().skip(1).zip(xe.iter().skip(1 + h)))
                    .enumerate()
                {
                    let k2 = k.1 as f64;
                    let stiff = -2.0 * w * k2 * mde;
                    let damp = k2 * cde;
                    if let Some(x) = jac.get_mut((d * l + 1 + i) * m + col) {
                        *x += stiff * a + damp * b;
                    }
                    if let Some(x) = jac.get_mut((d * l + 1 + h + i) * m + col) {
                        *x += stiff * b - damp * a;
                    }
                }
            }
        }
        if self.velocity {
            // ∂X_e/∂θ₂ samples of every DOF (into xs), then the products.
            for (e, block) in coeffs.chunks_exact(l).enumerate() {
                self.grid
                    .synthesize(&self.harmonics, block, Some((0.0, 1.0)), &mut self.column);
                scatter(&self.column, nd, e, &mut self.xs);
            }
            for d in 0..nd {
                for (s, c) in self.column.iter_mut().enumerate() {
                    let dg = self
                        .dg
                        .get(s * 2 * n2 + n2 + d * nd..s * 2 * n2 + n2 + (d + 1) * nd);
                    let dx = self.xs.get(s * nd..(s + 1) * nd);
                    *c = match (dg, dx) {
                        (Some(dg), Some(dx)) => dg.iter().zip(dx).map(|(a, b)| a * b).sum(),
                        _ => f64::NAN,
                    };
                }
                self.grid
                    .galerkin(&self.harmonics, &self.column, &mut self.rg);
                for (i, v) in self.rg.iter().enumerate() {
                    if let Some(x) = jac.get_mut((d * l + i) * m + col) {
                        *x += v;
                    }
                }
            }
        }
        // The phase row.
        if let Some(row) = jac.get_mut((m - 1) * m..m * m - 1) {
            row.copy_from_slice(&self.phase);
        }
    }
}
