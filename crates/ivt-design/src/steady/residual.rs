//! The balanced residual of the modified IHB (Eq. 152–155): the trig tables
//! and projection on `C̃_s` at the quadrature nodes, the nodes of the
//! piecewise Gauss quadrature between corner crossings, the sampled residual
//! R_p with its exact Jacobian (moving-end terms included), and the
//! [`System`]/[`NewtonSystem`] the solvers of [`super::IhbSolver`] drive.

use super::{IhbSolver, OperatingPoint, Quadrature};
use core::f64::consts::PI;
use ivt_kin::plant::PlantParams;
use ivt_kin::variant::{f_on_segment, f_on_segment_from_trig, segment_of};
use ivt_num::broyden::System;
use ivt_num::NewtonSystem;
use std::convert::Infallible;

impl IhbSolver {
    /// Trig tables and projection matrix for the current nodes and weights.
    pub(super) fn fill_tables(&mut self) {
        let n = self.opts.harmonics;
        // Column j of the (2n+1) × samples projection is contiguous.
        let columns = self.project.as_mut_slice().chunks_exact_mut(2 * n + 1);
        let rows = (self.cos.chunks_exact_mut(n.max(1))).zip(self.sin.chunks_exact_mut(n.max(1)));
        let nodes = self.weight.iter().zip(&self.tau);
        for ((column, (cos_j, sin_j)), (&w, &tau)) in columns.zip(rows).zip(nodes) {
            let Some((mean, harmonics)) = column.split_first_mut() else {
                continue;
            };
            let Some((p_cos, p_sin)) = harmonics.split_at_mut_checked(n) else {
                continue;
            };
            *mean = w / (2.0 * PI);
            let (s1, c1) = tau.sin_cos();
            let (mut s, mut c) = (s1, c1);
            let table = cos_j.iter_mut().zip(sin_j.iter_mut());
            for (k, ((cj, sj), (pc, ps))) in (1..).zip(table.zip(p_cos.iter_mut().zip(p_sin))) {
                if k > 1 && k % 8 == 1 {
                    // Refresh the recurrence now and then against drift.
                    (s, c) = (k as f64 * tau).sin_cos();
                }
                *cj = c;
                *sj = s;
                *pc = w * c / PI;
                *ps = w * s / PI;
                (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
            }
        }
    }

    /// τ where θ(τ) = τ + θ₁(τ) equals `theta` (Newton; θ(τ) is monotone).
    fn tau_of_theta(q: &[f64], theta: f64) -> f64 {
        let mut tau = theta;
        for _ in 0..60 {
            let (v, d) = theta1_of(q, tau);
            let step = (tau + v - theta) / (1.0 + d).max(1e-3);
            tau -= step;
            // Quadratic convergence: one more step after 1e-9 reaches round-off.
            if step.abs() < 1e-9 {
                let (v, d) = theta1_of(q, tau);
                tau -= (tau + v - theta) / (1.0 + d).max(1e-3);
                break;
            }
        }
        tau
    }

    /// Place Gauss nodes on the four smooth pieces between corner crossings.
    /// Returns the crossing τ's (for the moving-end Jacobian terms).
    fn place_piecewise_nodes(&mut self, q: &[f64]) -> [f64; 5] {
        use core::f64::consts::{FRAC_PI_2, FRAC_PI_4};
        let mut ends = [0.0; 5];
        for (k, e) in ends.iter_mut().enumerate() {
            *e = Self::tau_of_theta(q, FRAC_PI_4 + k as f64 * FRAC_PI_2);
        }
        // `samples` = 4 × the Gauss nodes per piece (IhbOptions::sample_count).
        let g = self.gauss.0.len().max(1);
        let pieces = ends.iter().zip(ends.iter().skip(1));
        let slots = self
            .tau
            .chunks_exact_mut(g)
            .zip(self.weight.chunks_exact_mut(g));
        let rule = self.gauss.0.iter().zip(&self.gauss.1);
        for ((&a, &b), (taus, weights)) in pieces.zip(slots) {
            let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
            for ((t, w), (x, gw)) in taus.iter_mut().zip(weights.iter_mut()).zip(rule.clone()) {
                *t = mid + half * x;
                *w = half * gw;
            }
        }
        self.fill_tables();
        ends
    }

    /// Sampled residual (and, if `jac`, its derivatives) at x = {r, q_p}.
    fn sample(&mut self, plant: &PlantParams, op: &OperatingPoint, x: &[f64], jac: bool) {
        let n = self.opts.harmonics;
        let Some((&r, q)) = x.split_first() else {
            self.res.fill(f64::NAN); // no unknowns: nothing to sample
            return;
        };
        let w0 = op.omega0;
        let (q_cos, q_sin) = q.split_at(q.len() / 2);
        let corners = match self.opts.quadrature {
            Quadrature::PiecewiseGauss => Some(self.place_piecewise_nodes(q)),
            Quadrature::Uniform => None,
        };
        let (jc, jd) = (plant.j_c(), plant.j_d());
        let (gg, a, b, c) = (
            plant.gravity_gain(),
            plant.motor_gain(),
            plant.load_gain(),
            plant.motor_damping(),
        );
        let ks = || (1..=n).map(|k| k as f64);
        let tables = (self.cos.chunks_exact(n.max(1))).zip(self.sin.chunks_exact(n.max(1)));
        let outputs = self.res.iter_mut().zip(self.dres.row_iter_mut());
        for ((&tau, (cs, sn)), (res, mut drow)) in self.tau.iter().zip(tables).zip(outputs) {
            let (mut t1, mut t1d, mut t1dd) = (0.0, 0.0, 0.0);
            let harmonics = q_cos.iter().zip(q_sin).zip(cs.iter().zip(sn));
            for (kk, ((qc, qs), (ck, sk))) in ks().zip(harmonics) {
                t1 += qc * ck + qs * sk;
                t1d += kk * (qs * ck - qc * sk);
                t1dd -= kk * kk * (qc * ck + qs * sk);
            }
            let theta = tau + t1;
            let seg = segment_of(theta);
            let (st, ct) = theta.sin_cos();
            let (f, ft) = f_on_segment_from_trig(st, ct, seg);
            let p = plant.terms_with_trig(st, ct, f, ft, r, op.v_m, op.t_u);
            let s = 1.0 + t1d;
            *res = w0 * w0 * (p.j * t1dd + 0.5 * p.j_theta * s * s) + w0 * p.f_m * s - p.drive(r);
            if jac {
                // ∂/∂θ of the coefficients on one smooth segment (f_θθ = −f there).
                let j_tt = 2.0 * (jc * r * r + jd) * (ft * ft - f * f);
                let fm_t = 2.0 * c * f * ft;
                let drive_t = gg * (ct - st) * r + a * ft * op.v_m - b * ft * op.t_u * r;
                let r_theta =
                    w0 * w0 * (p.j_theta * t1dd + 0.5 * j_tt * s * s) + w0 * fm_t * s - drive_t;
                let r_s = w0 * w0 * p.j_theta * s + w0 * p.f_m;
                let r_ss = w0 * w0 * p.j;
                // Row j of dres: ∂/∂r, then ∂/∂q_ck (k = 1..n), then ∂/∂q_sk.
                let mut entries = drow.iter_mut();
                if let Some(d_r) = entries.next() {
                    *d_r = w0 * w0 * (p.j_r * t1dd + 0.5 * p.j_theta_r * s * s) - (p.g - p.f2);
                }
                let trig = || cs.iter().zip(sn);
                for ((e, kk), (ck, sk)) in entries.by_ref().take(n).zip(ks()).zip(trig()) {
                    *e = (r_theta - kk * kk * r_ss) * ck - kk * r_s * sk;
                }
                for ((e, kk), (ck, sk)) in entries.zip(ks()).zip(trig()) {
                    *e = (r_theta - kk * kk * r_ss) * sk + kk * r_s * ck;
                }
            }
        }
        self.jump_jac.fill(0.0);
        if let (true, Some(ends)) = (jac, corners) {
            // d/dx Σ_pieces ∫ w R dτ gains w(τ_c) (R⁻ − R⁺) dτ_c/dx at each corner
            // crossing τ_c; only J_θ jumps there, so R⁻ − R⁺ = ½ ω0² ΔJ_θ (1+θ₁')².
            for &tc in ends.iter().skip(1) {
                let (t1, t1d) = theta1_of(q, tc);
                let (theta_c, s) = (tc + t1, 1.0 + t1d);
                let left = segment_of(theta_c - 1e-9);
                let right = segment_of(theta_c + 1e-9);
                let jt = |seg: i64| {
                    let (f, ft) = f_on_segment(theta_c, seg);
                    plant
                        .terms_with_f(theta_c, f, ft, r, op.v_m, op.t_u)
                        .j_theta
                };
                let jump = 0.5 * w0 * w0 * (jt(left) - jt(right)) * s * s;
                self.add_corner_crossing(tc, jump, s);
            }
        }
    }

    /// The moving-end term of one corner crossing τ_c into `jump_jac`:
    /// row weights w(τ_c)·jump/(1 + θ₁') of the projection, times
    /// dτ_c/dq = −∂θ₁/∂q (τ_c) / (1 + θ₁'(τ_c)); dτ_c/dr = 0.
    fn add_corner_crossing(&mut self, tc: f64, jump: f64, s: f64) {
        let n = self.opts.harmonics;
        let (s1, c1) = tc.sin_cos();
        let (mut sr, mut cr) = (s1, c1);
        for t in self.trig_c.iter_mut() {
            *t = (sr, cr); // (sin kτ_c, cos kτ_c), k = 1..n
            (sr, cr) = (sr * c1 + cr * s1, cr * c1 - sr * s1);
        }
        let Some((w_mean, w_harm)) = self.jump_row.split_first_mut() else {
            return;
        };
        *w_mean = 1.0 / (2.0 * PI) * jump / s;
        let (w_cos, w_sin) = w_harm.split_at_mut(w_harm.len() / 2);
        for ((wc, ws), &(sk, ck)) in w_cos.iter_mut().zip(w_sin.iter_mut()).zip(&self.trig_c) {
            *wc = ck / PI * jump / s;
            *ws = sk / PI * jump / s;
        }
        // Columns 1..n (q_ck) and n+1..2n (q_sk) of the column-major matrix.
        let mut columns = self
            .jump_jac
            .as_mut_slice()
            .chunks_exact_mut(2 * n + 1)
            .skip(1);
        for (column, &(_, ck)) in columns.by_ref().take(n).zip(&self.trig_c) {
            for (j, w) in column.iter_mut().zip(&self.jump_row) {
                *j -= w * ck;
            }
        }
        for (column, &(sk, _)) in columns.zip(&self.trig_c) {
            for (j, w) in column.iter_mut().zip(&self.jump_row) {
                *j -= w * sk;
            }
        }
    }
}

/// The harmonic-balanced residual R_p with its exact Jacobian: a [`System`]
/// for the Broyden solver (the Jacobian (re)seeds it) and a [`NewtonSystem`].
pub(super) struct BalancedResidual<'a> {
    pub(super) solver: &'a mut IhbSolver,
    pub(super) plant: &'a PlantParams,
    pub(super) op: &'a OperatingPoint,
}

impl System for BalancedResidual<'_> {
    fn residual(&mut self, x: &[f64], r: &mut [f64]) {
        self.solver.sample(self.plant, self.op, x, false);
        let rb = &self.solver.project * &self.solver.res;
        r.iter_mut().zip(rb.iter()).for_each(|(r, v)| *r = *v);
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> bool {
        self.solver.sample(self.plant, self.op, x, true);
        let j = &self.solver.project * &self.solver.dres + &self.solver.jump_jac;
        // Row-major out of the column-major product.
        for (out, row) in jac.chunks_exact_mut(x.len().max(1)).zip(j.row_iter()) {
            out.iter_mut().zip(row.iter()).for_each(|(o, v)| *o = *v);
        }
        true
    }
}

impl NewtonSystem for BalancedResidual<'_> {
    type Error = Infallible;
    fn residual(&mut self, x: &[f64], r: &mut [f64]) -> Result<(), Infallible> {
        System::residual(self, x, r);
        Ok(())
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut [f64]) -> Result<(), Infallible> {
        System::jacobian(self, x, jac);
        Ok(())
    }
}

/// θ₁(τ) = C_sᵀ q_p and θ₁'(τ) = C_sᵀ D_p q_p (Eq. 152–153), one `sin_cos`
/// and the angle-addition recurrence (error grows like k·ε, negligible for
/// the n ≤ 500 used here).
pub(super) fn theta1_of(q: &[f64], tau: f64) -> (f64, f64) {
    let (q_cos, q_sin) = q.split_at(q.len() / 2);
    let (s1, c1) = tau.sin_cos();
    let (mut s, mut c) = (s1, c1);
    let (mut v, mut d) = (0.0, 0.0);
    for (k, (qc, qs)) in (1..).zip(q_cos.iter().zip(q_sin)) {
        v += qc * c + qs * s;
        d += k as f64 * (qs * c - qc * s);
        (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
    }
    (v, d)
}
