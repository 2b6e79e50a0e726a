//! Brute-force shooting (no HB): every period-`T` orbit of a forced
//! `M x″ + C x′ + K x + g(x, θ) = f(θ)` (velocity-independent `g` with its
//! analytic `∂g/∂x`) that Newton on the period map `P(y) − y = 0` reaches
//! from many starting states, each with its Floquet multipliers (the
//! eigenvalues of `∂P/∂y`, from the variational equation integrated with the
//! state by fixed-step RK6).
#![allow(clippy::indexing_slicing)]

use ivt_hb::PeriodicProblem;
use ivt_num::{ExplicitRk, RK6};
use nalgebra::DMatrix;
use std::f64::consts::PI;

/// One orbit found by shooting.
#[derive(Debug, Clone)]
pub struct Shot {
    /// The state `[x, ẋ]` at t = 0.
    pub state: Vec<f64>,
    /// Moduli of the multipliers.
    pub multipliers: Vec<f64>,
    /// All multipliers inside the unit circle.
    pub stable: bool,
}

/// `P(y)` and `∂P/∂y` (row-major `2n × 2n`) over `periods` forcing periods
/// of ω, RK6 with `steps` steps per period.
pub fn period_map<P: PeriodicProblem>(
    problem: &P,
    omega: f64,
    y: &[f64],
    periods: usize,
    steps: usize,
) -> (Vec<f64>, Vec<f64>) {
    let n = problem.n_dof();
    let d = 2 * n;
    let minv = ivt_num::lu::inverse(problem.mass(), n).unwrap();
    let (c, k) = (problem.damping().to_vec(), problem.stiffness().to_vec());
    let (mut g, mut f, mut dg, mut acc) = (
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; 2 * n * n],
        vec![0.0; n],
    );
    let (mut stiff, mut damp) = (vec![0.0; n * n], vec![0.0; n * n]);
    let mut rhs = |t: f64, z: &[f64], dz: &mut [f64]| {
        let (x, v) = (&z[..n], &z[n..d]);
        let theta = omega * t;
        problem.nonlinear(x, v, theta, &mut g);
        problem.excitation(theta, &mut f);
        problem.nonlinear_jacobian(x, v, theta, &mut dg);
        for i in 0..n {
            acc[i] = f[i]
                - g[i]
                - (0..n)
                    .map(|j| c[i * n + j] * v[j] + k[i * n + j] * x[j])
                    .sum::<f64>();
        }
        for i in 0..n {
            dz[i] = v[i];
            dz[n + i] = (0..n).map(|j| minv[i * n + j] * acc[j]).sum();
        }
        // M⁻¹(K + g_x) and M⁻¹(C + g_v).
        for i in 0..n {
            for j in 0..n {
                let (mut sx, mut sv) = (0.0, 0.0);
                for l in 0..n {
                    sx += minv[i * n + l] * (k[l * n + j] + dg[l * n + j]);
                    sv += minv[i * n + l] * (c[l * n + j] + dg[n * n + l * n + j]);
                }
                stiff[i * n + j] = sx;
                damp[i * n + j] = sv;
            }
        }
        // Φ′ = [[Φ_v], [−M⁻¹(K + g_x)Φ_x − M⁻¹(C + g_v)Φ_v]] (Φ rows: x then v).
        let (phi, dphi) = (&z[d..], &mut dz[d..]);
        for i in 0..n {
            for col in 0..d {
                dphi[i * d + col] = phi[(n + i) * d + col];
                let mut s = 0.0;
                for j in 0..n {
                    s -= stiff[i * n + j] * phi[j * d + col]
                        + damp[i * n + j] * phi[(n + j) * d + col];
                }
                dphi[(n + i) * d + col] = s;
            }
        }
    };
    let mut z = vec![0.0; d + d * d];
    z[..d].copy_from_slice(y);
    for i in 0..d {
        z[d + i * d + i] = 1.0;
    }
    let h = 2.0 * PI / omega / steps as f64;
    let mut rk = ExplicitRk::with_dim(&RK6, z.len());
    rk.fixed_steps(&mut rhs, 0.0, h, periods * steps, &mut z);
    (z[..d].to_vec(), z[d..].to_vec())
}

/// Newton on `P(y) − y = 0` from `y` (steps halved while the residual
/// grows): the orbit's state, or `None` without convergence to 1e-11.
fn shoot<P: PeriodicProblem>(
    problem: &P,
    omega: f64,
    mut y: Vec<f64>,
    periods: usize,
    steps: usize,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let d = y.len();
    let residual = |y: &[f64]| -> (Vec<f64>, Vec<f64>, f64) {
        let (p, jac) = period_map(problem, omega, y, periods, steps);
        let r: Vec<f64> = p.iter().zip(y).map(|(a, b)| a - b).collect();
        let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        (r, jac, norm)
    };
    let (mut r, mut jac, mut norm) = residual(&y);
    for iteration in 0..30 {
        if !norm.is_finite() || y.iter().any(|v| v.abs() > 1e3) || (iteration >= 15 && norm > 1e-3)
        {
            return None;
        }
        if norm < 1e-11 {
            return Some((y, jac));
        }
        let mut a = DMatrix::from_row_slice(d, d, &jac);
        for i in 0..d {
            a[(i, i)] -= 1.0;
        }
        let step = a.lu().solve(&nalgebra::DVector::from_column_slice(&r))?;
        let mut scale = 1.0;
        loop {
            let trial: Vec<f64> = y
                .iter()
                .zip(step.iter())
                .map(|(a, b)| a - scale * b)
                .collect();
            let (r2, j2, n2) = residual(&trial);
            if n2 < norm || scale < 0.02 {
                (y, r, jac, norm) = (trial, r2, j2, n2);
                break;
            }
            scale *= 0.5;
        }
    }
    None
}

/// The `i`-th point of the Halton sequence in `d` dimensions (bases 2, 3, 5, 7, …).
fn halton(i: usize, d: usize) -> Vec<f64> {
    const PRIMES: [usize; 8] = [2, 3, 5, 7, 11, 13, 17, 19];
    PRIMES[..d]
        .iter()
        .map(|&b| {
            let (mut f, mut r, mut k) = (1.0, 0.0, i + 1);
            while k > 0 {
                f /= b as f64;
                r += f * (k % b) as f64;
                k /= b;
            }
            r
        })
        .collect()
}

/// Every period-`periods·T` orbit Newton reaches from `starts` states in the
/// boxes `|x_i| ≤ s`, `|ẋ_i| ≤ ω·s` (Halton points; `s` cycles through
/// `box_x`, `box_x/4` and `box_x/16`, so that small orbits get near starts
/// too), distinct to 1e-7.
pub fn all_orbits<P: PeriodicProblem>(
    problem: &P,
    omega: f64,
    box_x: f64,
    starts: usize,
    periods: usize,
) -> Vec<Shot> {
    let n = problem.n_dof();
    let steps = 200;
    let mut found: Vec<Shot> = Vec::new();
    for i in 0..starts {
        let u = halton(i, 2 * n);
        let y: Vec<f64> = u
            .iter()
            .enumerate()
            .map(|(j, s)| {
                (2.0 * s - 1.0) * box_x / [1.0, 4.0, 16.0][i % 3] * if j < n { 1.0 } else { omega }
            })
            .collect();
        let Some((y, jac)) = shoot(problem, omega, y, periods, steps) else {
            continue;
        };
        if found
            .iter()
            .any(|s| s.state.iter().zip(&y).all(|(a, b)| (a - b).abs() < 1e-7))
        {
            continue;
        }
        let d = 2 * n;
        let m = DMatrix::from_row_slice(d, d, &jac);
        let multipliers: Vec<f64> = m.complex_eigenvalues().iter().map(|z| z.norm()).collect();
        let stable = multipliers.iter().all(|r| *r < 1.0);
        found.push(Shot {
            state: y,
            multipliers,
            stable,
        });
    }
    found
}
