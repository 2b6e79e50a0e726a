//! The backbone equations as a [`Branch`] in the prescribed amplitude.

use crate::branches::family::{FamilyBranch, Frequency};
use crate::problem::PeriodicProblem;
use ivt_path::branch::{path_lambda_step, Branch};

/// Adds the Galerkin projection of the unfolding damping `κ M ẋ` (τ = ωt) to
/// `r`: harmonic h gives `κhω M b_h` to the cosine rows and `−κhω M a_h` to the
/// sine rows (the damping part of Eq. 60 with `C = κM`).
fn add_unfolding(mass: &[f64], nd: usize, n: usize, q: &[f64], kappa_omega: f64, r: &mut [f64]) {
    let l = 2 * n + 1;
    for d in 0..nd {
        for e in 0..nd {
            let me = mass.get(d * nd + e).copied().unwrap_or(f64::NAN) * kappa_omega;
            for h in 1..=n {
                let s = h as f64 * me;
                let (a, b) = (e * l + h, e * l + n + h);
                let (qa, qb) = (q.get(a).copied(), q.get(b).copied());
                if let (Some(qa), Some(qb)) = (qa, qb) {
                    add(r, d * l + h, s * qb);
                    add(r, d * l + n + h, -s * qa);
                }
            }
        }
    }
}

/// `x[k] += v` (nothing for `k` out of range).
fn add(x: &mut [f64], k: usize, v: f64) {
    if let Some(e) = x.get_mut(k) {
        *e += v;
    }
}

/// The backbone equations `[R(q, ω) + κω D q; b₁; a₁ − λ] = 0` in the unknowns
/// `u = {q, ω, κ}` at `λ` = the prescribed `a₁`, with their exact Jacobian:
/// `∂R/∂q` is the Galerkin Jacobian (Eq. 56) of the frequency family at ω,
/// `∂R/∂ω` its ω-derivative ([`Frequency`]), and the unfolding `κω D q` is
/// linear in each unknown. `∂/∂λ` is `−e_{m+2}` exactly.
pub(super) struct BackboneSystem<'a, P: PeriodicProblem> {
    pub(super) branch: FamilyBranch<Frequency<'a, P>>,
    pub(super) mass: &'a [f64],
    pub(super) nd: usize,
    pub(super) n: usize,
    /// Indices of `a₁` and `b₁` of the reference DOF in `q`.
    pub(super) a1: usize,
    pub(super) b1: usize,
    /// `∂R/∂q` of the branch (row-major `m × m`), `∂R/∂ω`, and `D q` scratch (`m`).
    pub(super) jq: Vec<f64>,
    pub(super) column: Vec<f64>,
    pub(super) dq: Vec<f64>,
}

impl<'a, P: PeriodicProblem> BackboneSystem<'a, P> {
    /// The system of `problem` (harmonics `n`, HB residual planned at `omega0`).
    pub(super) fn new(
        branch: FamilyBranch<Frequency<'a, P>>,
        mass: &'a [f64],
        nd: usize,
        n: usize,
        (a1, b1): (usize, usize),
    ) -> Self {
        let zeros = |len: usize| vec![0.0; len];
        let m = branch.len();
        let (jq, column, dq) = (zeros(m * m), zeros(m), zeros(m));
        #[rustfmt::skip]
        let system = Self { branch, mass, nd, n, a1, b1, jq, column, dq };
        system
    }

    /// `D q` (the unfolding per unit κω) into `self.dq`.
    fn unfolding_of(&mut self, q: &[f64]) {
        self.dq.fill(0.0);
        add_unfolding(self.mass, self.nd, self.n, q, 1.0, &mut self.dq);
    }

    /// `u` as `(q, ω, κ)`; `None` for a wrong length.
    fn split<'u>(&self, u: &'u [f64]) -> Option<(&'u [f64], f64, f64)> {
        match u.split_at_checked(self.dq.len()) {
            Some((q, &[omega, kappa])) => Some((q, omega, kappa)),
            _ => None,
        }
    }
}

impl<P: PeriodicProblem> Branch for BackboneSystem<'_, P> {
    fn len(&self) -> usize {
        self.dq.len() + 2
    }
    fn residual(&mut self, u: &[f64], lambda: f64, r: &mut [f64]) {
        let m = self.dq.len();
        let (Some((q, omega, kappa)), Some((r_q, [r_b, r_a]))) =
            (self.split(u), r.split_at_mut_checked(m))
        else {
            r.fill(f64::NAN);
            return;
        };
        self.branch.residual(q, omega, r_q);
        add_unfolding(self.mass, self.nd, self.n, q, kappa * omega, r_q);
        *r_b = u.get(self.b1).copied().unwrap_or(f64::NAN);
        *r_a = u.get(self.a1).copied().unwrap_or(f64::NAN) - lambda;
    }
    fn jacobian(&mut self, u: &[f64], _lambda: f64, jac: &mut [f64]) {
        let (m, n) = (self.dq.len(), self.dq.len() + 2);
        jac.fill(0.0);
        let Some((q, omega, kappa)) = self.split(u) else {
            jac.fill(f64::NAN);
            return;
        };
        let mut jq = std::mem::take(&mut self.jq);
        let mut column = std::mem::take(&mut self.column);
        self.branch.jacobian(q, omega, &mut jq);
        self.branch
            .residual_lambda(q, omega, path_lambda_step(omega), &mut column);
        for (row, jq_row) in jac.chunks_exact_mut(n).zip(jq.chunks_exact(m.max(1))) {
            if let Some(left) = row.get_mut(..m) {
                left.copy_from_slice(jq_row);
            }
        }
        // ∂(κω D q)/∂q = κω D, column k the image of the unit vector e_k.
        let mut unit = vec![0.0; m];
        for k in 0..m {
            set(&mut unit, k, 1.0);
            self.unfolding_of(&unit);
            set(&mut unit, k, 0.0);
            for (row, d) in jac.chunks_exact_mut(n).zip(&self.dq) {
                add(row, k, kappa * omega * d);
            }
        }
        self.unfolding_of(q);
        for ((row, c), d) in jac.chunks_exact_mut(n).zip(&column).zip(&self.dq) {
            set(row, m, c + kappa * d);
            set(row, m + 1, omega * d);
        }
        self.jq = jq;
        self.column = column;
        set(jac, m * n + self.b1, 1.0);
        set(jac, (m + 1) * n + self.a1, 1.0);
    }
    fn residual_lambda(&mut self, _u: &[f64], _lambda: f64, _h: f64, r_lambda: &mut [f64]) {
        r_lambda.fill(0.0);
        if let Some(last) = r_lambda.last_mut() {
            *last = -1.0;
        }
    }
}

/// `x[k] = v` (nothing for `k` out of range).
fn set(x: &mut [f64], k: usize, v: f64) {
    if let Some(e) = x.get_mut(k) {
        *e = v;
    }
}
