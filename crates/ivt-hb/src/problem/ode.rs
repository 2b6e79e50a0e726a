//! A plain fixed-step classical Runge–Kutta integration: the independent time-domain
//! reference for the HB tests and the Mathieu–Duffing check (it shares no code with
//! the harmonic-balance path).

use crate::problem::PeriodicProblem;
use ivt_num::{ExplicitRk, RK4};

/// Integrates `y' = f(t, y)` with `steps` classical RK4 steps of size `dt`
/// from `t0`, in place (the one stepper of [`ivt_num`]).
pub fn rk4<F: FnMut(f64, &[f64], &mut [f64])>(
    mut f: F,
    t0: f64,
    y: &mut [f64],
    dt: f64,
    steps: usize,
) {
    ExplicitRk::with_dim(&RK4, y.len()).fixed_steps(&mut f, t0, dt, steps, y);
}

/// First-order form `y = [x, ẋ]` of a [`PeriodicProblem`] in physical time with
/// excitation frequency `omega_f`: `M ẍ = f(ω_f t) − C ẋ − K x − g(x, ẋ, ω_f t)`.
///
/// A singular mass matrix, a problem whose `C` or `K` is not `n_dof×n_dof` or a
/// state that is not `2·n_dof` long gives NaN derivatives (the integration then
/// ends in NaN, never in a wrong number).
pub fn first_order<P: PeriodicProblem>(
    problem: &P,
    omega_f: f64,
) -> impl FnMut(f64, &[f64], &mut [f64]) + '_ {
    let nd = problem.n_dof();
    let minv = ivt_num::lu::inverse(problem.mass(), nd).unwrap_or_else(|| vec![f64::NAN; nd * nd]);
    let (mut g, mut f, mut acc) = (vec![0.0; nd], vec![0.0; nd], vec![0.0; nd]);
    move |t, y, dy| {
        let (c, k) = (problem.damping(), problem.stiffness());
        let n2 = nd * nd;
        if nd == 0 || y.len() != 2 * nd || dy.len() != 2 * nd || c.len() != n2 || k.len() != n2 {
            return dy.fill(f64::NAN);
        }
        let (x, v) = y.split_at(nd);
        let theta = omega_f * t;
        problem.nonlinear(x, v, theta, &mut g);
        problem.excitation(theta, &mut f);
        let rows = c.chunks_exact(nd).zip(k.chunks_exact(nd));
        for ((a, (fi, gi)), (c_row, k_row)) in acc.iter_mut().zip(f.iter().zip(&g)).zip(rows) {
            let mut s = fi - gi;
            for ((cij, kij), (vj, xj)) in c_row.iter().zip(k_row).zip(v.iter().zip(x)) {
                s -= cij * vj + kij * xj;
            }
            *a = s;
        }
        let (dx, dv) = dy.split_at_mut(nd);
        dx.copy_from_slice(v);
        for (d, m_row) in dv.iter_mut().zip(minv.chunks_exact(nd)) {
            *d = m_row.iter().zip(&acc).map(|(m, a)| m * a).sum();
        }
    }
}
