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
/// # Panics
/// If the mass matrix is singular.
pub fn first_order<P: PeriodicProblem>(
    problem: &P,
    omega_f: f64,
) -> impl FnMut(f64, &[f64], &mut [f64]) + '_ {
    let nd = problem.n_dof();
    let minv = ivt_num::lu::inverse(problem.mass(), nd).expect("mass matrix must be invertible");
    let (mut g, mut f, mut acc) = (vec![0.0; nd], vec![0.0; nd], vec![0.0; nd]);
    move |t, y, dy| {
        let (x, v) = y.split_at(nd);
        let theta = omega_f * t;
        problem.nonlinear(x, v, theta, &mut g);
        problem.excitation(theta, &mut f);
        let (c, k) = (problem.damping(), problem.stiffness());
        for i in 0..nd {
            let mut s = f[i] - g[i];
            for j in 0..nd {
                s -= c[i * nd + j] * v[j] + k[i * nd + j] * x[j];
            }
            acc[i] = s;
        }
        for i in 0..nd {
            dy[i] = v[i];
            dy[nd + i] = (0..nd).map(|j| minv[i * nd + j] * acc[j]).sum();
        }
    }
}
