//! The invariant subspace of the string's responses and the STHB system
//! restricted to it: the block structure of the Jacobian in modes × harmonics.
//!
//! The forcing `y0 sin πx cos t` and the cubic `k_d w_x² w_xx` of Eq. 103 are
//! equivariant under the half-period shift with a sign change,
//! `w(x, t) → −w(x, t + π)`, and, for the fixed–fixed string, under the
//! reflection `x → 1 − x` (`sin nπx` is even about `x = ½` for odd `n`, odd
//! for even `n`). The sampled balance keeps both: the `M_s` time samples are
//! shifted into each other by `π` when `M_s` is even, and the grid
//! `x_k = k/N_s` is symmetric. So the branch traced from rest has only odd
//! harmonics and (fixed–fixed) only the odd modes `n = 1, 3, 5…`; the residual
//! maps that subspace into itself, and the exact Jacobian at such a response
//! commutes with both symmetries, hence is block diagonal between the
//! subspace and its complement. Newton, tangents and folds of the branch need
//! only the subspace's block: a quarter of the unknowns of the fixed string
//! (1/64 of a dense LU's work), half of the spring's, the same iterates. The
//! other blocks matter only to stability, which keeps the full `S(t)` of the
//! embedded response (monodromy, Hill).

use faer::{Mat, MatMut};
use ivt_num::vector::dot;

use super::toeplitz::add_real_toeplitz_odd;
use super::{Boundary, StringHb};
use ivt_path::branch::Branch;

/// Marks a full index outside the subspace.
const OUTSIDE: usize = usize::MAX;

/// The kept harmonic slots and coordinates of [`StringHb`]'s unknowns.
pub(super) struct Subspace {
    /// Coordinates kept (odd modes of the fixed string, all of the spring's).
    coords: Vec<usize>,
    /// Only the odd harmonics are kept (`M_s` even).
    odd_harmonics: bool,
    /// Full index of each reduced unknown, in order.
    full_index: Vec<usize>,
    /// Reduced index of each full unknown, [`OUTSIDE`] if not kept.
    position: Vec<usize>,
}

impl Subspace {
    /// The invariant subspace of `hb`'s responses (see the module docs).
    pub(super) fn of(hb: &StringHb) -> Self {
        let p = hb.params();
        let nq = hb.coords();
        let coords: Vec<usize> = match p.boundary {
            // Mode n = j + 1 odd.
            Boundary::Fixed => (0..nq).step_by(2).collect(),
            Boundary::Spring { .. } => (0..nq).collect(),
        };
        let odd_harmonics = p.ms.is_multiple_of(2);
        let slots: Vec<usize> = if odd_harmonics {
            // cos kt at 2k − 1, sin kt at 2k, k odd: reduced positions k − 1, k.
            (1..=p.harmonics)
                .step_by(2)
                .flat_map(|k| [2 * k - 1, 2 * k])
                .collect()
        } else {
            (0..=2 * p.harmonics).collect()
        };
        let full_index: Vec<usize> = slots
            .iter()
            .flat_map(|&h| coords.iter().map(move |&c| hb.index(h, c)))
            .collect();
        let mut position = vec![OUTSIDE; hb.dim()];
        // Every `hb.index(h, c)` of a slot and coordinate is below `dim`.
        for (r, &f) in full_index.iter().enumerate() {
            if let Some(p) = position.get_mut(f) {
                *p = r;
            }
        }
        Self {
            coords,
            odd_harmonics,
            full_index,
            position,
        }
    }

    /// Number of reduced unknowns.
    pub(super) fn dim(&self) -> usize {
        self.full_index.len()
    }

    /// The full vector of the reduced `reduced` (zeros outside) into `full`.
    pub(super) fn embed(&self, reduced: &[f64], full: &mut [f64]) {
        full.fill(0.0);
        for (&f, v) in self.full_index.iter().zip(reduced) {
            if let Some(x) = full.get_mut(f) {
                *x = *v;
            }
        }
    }

    /// The subspace's entries of `full` into `reduced` (NaN where `full` is
    /// short).
    pub(super) fn gather(&self, full: &[f64], reduced: &mut [f64]) {
        for (r, &f) in reduced.iter_mut().zip(&self.full_index) {
            *r = full.get(f).copied().unwrap_or(f64::NAN);
        }
    }
}

/// [`StringHb`] restricted to its invariant subspace, as a [`Branch`] in ω
/// (the path and the bordered fold system), with the
/// exact Jacobian's block of the subspace (Eq. 115–125) and exact derivatives
/// of the fold test function: `∂R/∂ω = ∂J_lin/∂ω a` (the balanced term does
/// not depend on ω), `∂(wᵀJv)/∂ω = wᵀ ∂J_lin/∂ω v`, and `∂(wᵀJv)/∂a` from
/// two Jacobians ([`Branch::jacobian_gradient`] below) instead of the
/// default's `2·dim` finite-difference Jacobians (minutes per fold at `N = 20`,
/// `M = 39`).
pub(super) struct ReducedString<'a> {
    pub(super) hb: &'a mut StringHb,
    pub(super) sub: Subspace,
    /// Jacobian assemblies.
    pub(super) jacobians: usize,
    full: Vec<f64>,
    full_r: Vec<f64>,
    /// The full Jacobian, only when the harmonics are not reduced (odd `M_s`).
    full_jac: Mat<f64>,
    /// Row-major `m × m` scratch of [`Self::jacobian_transpose_times`].
    jac: Vec<f64>,
    r: Vec<f64>,
}

impl<'a> ReducedString<'a> {
    /// The subspace of `hb` and the buffers.
    pub(super) fn new(hb: &'a mut StringHb) -> Self {
        let sub = Subspace::of(hb);
        let (n, m) = (hb.dim(), sub.dim());
        Self {
            full: vec![0.0; n],
            full_r: vec![0.0; n],
            full_jac: if sub.odd_harmonics {
                Mat::zeros(0, 0)
            } else {
                Mat::zeros(n, n)
            },
            jac: vec![0.0; m * m],
            r: vec![0.0; m],
            hb,
            sub,
            jacobians: 0,
        }
    }

    /// The subspace's block of `J` at the last linearization into `jac`.
    fn fill_jacobian(&mut self, omega: f64, mut jac: MatMut<'_, f64>) {
        if !self.sub.odd_harmonics {
            self.hb.fill_jacobian(omega, &mut self.full_jac);
            for (r, &fr) in self.sub.full_index.iter().enumerate() {
                for (c, &fc) in self.sub.full_index.iter().enumerate() {
                    jac[(r, c)] = self.full_jac[(fr, fc)];
                }
            }
            return;
        }
        jac.fill(0.0);
        let pos = &self.sub.position;
        let at = |k: usize| pos.get(k).copied().unwrap_or(OUTSIDE);
        self.hb.for_each_linear(omega, false, |r, c, v| {
            let (pr, pc) = (at(r), at(c));
            if pr != OUTSIDE && pc != OUTSIDE {
                jac[(pr, pc)] += v;
            }
        });
        add_real_toeplitz_odd(
            self.hb.s_spectrum(),
            self.hb.params().harmonics,
            -1.0,
            &self.sub.coords,
            jac,
        );
    }

    /// `J(a)ᵀ w` (reduced) into `out`.
    fn jacobian_transpose_times(&mut self, a: &[f64], omega: f64, w: &[f64], out: &mut [f64]) {
        let mut jac = std::mem::take(&mut self.jac);
        let mut r = std::mem::take(&mut self.r);
        self.residual_jacobian(a, omega, &mut r, &mut jac);
        out.fill(0.0);
        for (row, y) in jac.chunks_exact(out.len().max(1)).zip(w) {
            for (o, v) in out.iter_mut().zip(row) {
                *o += v * y;
            }
        }
        self.jac = jac;
        self.r = r;
    }
}

impl Branch for ReducedString<'_> {
    fn len(&self) -> usize {
        self.sub.dim()
    }
    fn residual(&mut self, q: &[f64], lambda: f64, r: &mut [f64]) {
        self.sub.embed(q, &mut self.full);
        self.hb.residual(&self.full, lambda, &mut self.full_r);
        self.sub.gather(&self.full_r, r);
    }
    /// `J` alone costs the linearization that gives `R` too.
    fn jacobian(&mut self, q: &[f64], lambda: f64, jac: &mut [f64]) {
        let mut r = std::mem::take(&mut self.r);
        self.residual_jacobian(q, lambda, &mut r, jac);
        self.r = r;
    }
    fn residual_jacobian(&mut self, q: &[f64], lambda: f64, r: &mut [f64], jac: &mut [f64]) {
        self.jacobians += 1;
        self.sub.embed(q, &mut self.full);
        self.hb
            .residual_linearized(&self.full, lambda, &mut self.full_r);
        self.sub.gather(&self.full_r, r);
        let m = r.len();
        self.fill_jacobian(lambda, MatMut::from_row_major_slice_mut(jac, m, m));
    }
    /// Exact: `∂J_lin/∂ω a` (the balanced term does not depend on ω).
    fn residual_lambda(&mut self, q: &[f64], lambda: f64, _h: f64, out: &mut [f64]) {
        self.sub.embed(q, &mut self.full);
        self.hb
            .d_residual_d_omega(&self.full, lambda, &mut self.full_r);
        self.sub.gather(&self.full_r, out);
    }
    fn bilinear_lambda(&mut self, _q: &[f64], lambda: f64, _h: f64, w: &[f64], v: &[f64]) -> f64 {
        // ∂J/∂ω = ∂J_lin/∂ω, and ∂R/∂ω at `v` is ∂J_lin/∂ω v.
        let mut jv = std::mem::take(&mut self.r);
        self.residual_lambda(v, lambda, 0.0, &mut jv);
        let value = dot(w, &jv);
        self.r = jv;
        value
    }
    /// `∂/∂a (wᵀ J(a) v) = (J′(a)[v])ᵀ w` (the Hessians of `R` are symmetric).
    /// `J = J_lin − S_𝒯(a)` with `S_𝒯` quadratic in `a` (Eq. 122–125: the
    /// spectra of `w_x w_xx` and `w_x²`), so the central difference
    /// `(J(a + h v) − J(a − h v)) / 2h` is `J′(a)[v]` exactly for every `h`;
    /// `h` scales `v` to the size of `a`.
    fn jacobian_gradient(&mut self, q: &[f64], lambda: f64, w: &[f64], v: &[f64], out: &mut [f64]) {
        let size = |x: &[f64]| x.iter().fold(0.0f64, |m, y| m.max(y.abs()));
        let v_size = size(v);
        if v_size == 0.0 || !v_size.is_finite() {
            out.fill(0.0);
            return;
        }
        let h = size(q).max(1e-3) / v_size;
        let shifted =
            |sign: f64| -> Vec<f64> { q.iter().zip(v).map(|(a, b)| a + sign * h * b).collect() };
        let mut minus = vec![0.0; q.len()];
        self.jacobian_transpose_times(&shifted(-1.0), lambda, w, &mut minus);
        self.jacobian_transpose_times(&shifted(1.0), lambda, w, out);
        for (o, m) in out.iter_mut().zip(&minus) {
            *o = (*o - m) / (2.0 * h);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::StringParams;
    use ivt_path::branch::fd_jacobian_gradient;

    /// A response on the branch from rest at `omega` (in the subspace).
    fn solved(params: StringParams, omega: f64) -> (StringHb, Vec<f64>) {
        let mut hb = StringHb::new(params).unwrap();
        let mut a = vec![0.0; hb.dim()];
        hb.solve(omega, &mut a, 1e-12, 50).unwrap();
        (hb, a)
    }

    fn cases() -> Vec<StringParams> {
        let base = StringParams {
            kd: 30.0,
            modes: 6,
            harmonics: 5,
            ..Default::default()
        };
        vec![
            base.clone(),
            StringParams {
                boundary: Boundary::Spring { k0: 7.0 },
                ..base.clone()
            },
            // Odd M_s: the harmonics are not reduced.
            StringParams { ms: 15, ..base },
        ]
    }

    #[test]
    fn full_jacobian_is_block_diagonal_and_the_block_is_the_reduced_one() {
        for p in cases() {
            let (mut hb, a) = solved(p.clone(), 3.8);
            let n = hb.dim();
            let (mut r, mut full) = (vec![0.0; n], Mat::zeros(n, n));
            hb.residual_jacobian(&a, 3.8, &mut r, &mut full);
            let scale = (0..n)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .map(|(i, j)| full[(i, j)].abs())
                .fold(0.0, f64::max);
            let mut sys = ReducedString::new(&mut hb);
            let m = sys.sub.dim();
            let mut q = vec![0.0; m];
            sys.sub.gather(&a, &mut q);
            // The response lies in the subspace: nothing outside it.
            let outside: f64 = (0..n)
                .filter(|&i| sys.sub.position[i] == OUTSIDE)
                .map(|i| a[i].abs())
                .fold(0.0, f64::max);
            assert!(outside < 1e-14, "{p:?}: {outside:e} outside");
            let (mut rr, mut red) = (vec![0.0; m], vec![0.0; m * m]);
            sys.residual_jacobian(&q, 3.8, &mut rr, &mut red);
            let pos = &sys.sub.position;
            for i in 0..n {
                for j in 0..n {
                    let v = full[(i, j)];
                    let err = match (pos[i], pos[j]) {
                        (OUTSIDE, OUTSIDE) => 0.0,
                        (OUTSIDE, _) | (_, OUTSIDE) => v.abs(),
                        (ri, rj) => (red[ri * m + rj] - v).abs(),
                    };
                    assert!(err <= 1e-13 * scale, "{p:?} ({i}, {j}): {err:e}");
                }
            }
            for (ri, &fi) in sys.sub.full_index.iter().enumerate() {
                assert!((rr[ri] - r[fi]).abs() <= 1e-13 * scale);
            }
            let expected = match (p.boundary, p.ms % 2) {
                (Boundary::Fixed, 0) => 3 * 6,
                (Boundary::Spring { .. }, 0) => 6 * 7,
                _ => 11 * 3,
            };
            assert_eq!(m, expected, "{p:?}");
        }
    }

    #[test]
    fn exact_fold_derivatives_match_finite_differences() {
        for p in cases() {
            let (mut hb, a) = solved(p, 3.8);
            let mut sys = ReducedString::new(&mut hb);
            let m = sys.sub.dim();
            let mut q = vec![0.0; m];
            sys.sub.gather(&a, &mut q);
            let w: Vec<f64> = (0..m).map(|i| ((i * 7 + 3) % 11) as f64 - 5.0).collect();
            let v: Vec<f64> = (0..m).map(|i| ((i * 5 + 1) % 13) as f64 - 6.0).collect();
            let (mut exact, mut fd) = (vec![0.0; m], vec![0.0; m]);
            sys.jacobian_gradient(&q, 3.8, &w, &v, &mut exact);
            fd_jacobian_gradient(&mut sys, &q, 3.8, &w, &v, 1e-5, &mut fd);
            let scale = fd.iter().fold(0.0f64, |s, x| s.max(x.abs()));
            for (e, f) in exact.iter().zip(&fd) {
                assert!((e - f).abs() <= 1e-6 * scale, "{e} vs {f}");
            }
            // ∂(wᵀJv)/∂ω against the central difference of wᵀJv in ω.
            let h = 1e-4;
            let exact_w = sys.bilinear_lambda(&q, 3.8, h, &w, &v);
            let fd_w = ivt_path::branch::bilinear_lambda_difference(&mut sys, &q, 3.8, h, &w, &v);
            assert!((exact_w - fd_w).abs() <= 1e-6 * exact_w.abs().max(1.0));
        }
    }
}
