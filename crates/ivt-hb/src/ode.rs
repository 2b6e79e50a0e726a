//! A plain fixed-step classical Runge–Kutta integrator: the independent time-domain
//! reference for the HB tests and the Mathieu–Duffing check (it shares no code with
//! the harmonic-balance path).

use crate::floquet::small_inverse;
use crate::problem::PeriodicProblem;

/// Integrates `y' = f(t, y)` with `steps` RK4 steps of size `dt` from `t0`, in place.
pub fn rk4<F: FnMut(f64, &[f64], &mut [f64])>(
    mut f: F,
    t0: f64,
    y: &mut [f64],
    dt: f64,
    steps: usize,
) {
    let n = y.len();
    let (mut k1, mut k2, mut k3, mut k4, mut yt) = (
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
    );
    let mut t = t0;
    for _ in 0..steps {
        f(t, y, &mut k1);
        for i in 0..n {
            yt[i] = y[i] + 0.5 * dt * k1[i];
        }
        f(t + 0.5 * dt, &yt, &mut k2);
        for i in 0..n {
            yt[i] = y[i] + 0.5 * dt * k2[i];
        }
        f(t + 0.5 * dt, &yt, &mut k3);
        for i in 0..n {
            yt[i] = y[i] + dt * k3[i];
        }
        f(t + dt, &yt, &mut k4);
        for i in 0..n {
            y[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        t += dt;
    }
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
    let minv = small_inverse(problem.mass(), nd).expect("mass matrix must be invertible");
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
