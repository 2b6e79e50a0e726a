//! What a torus says: its rotation number, the mean and maximum of `|x_d|`
//! over it, its Poincaré section at the forcing phase `θ₁ = 0`, the normal
//! Lyapunov exponent of a one-DOF torus, and the error of all of these
//! against a wider truncation.
//!
//! - **Rotation number** `ρ = Ω/ω₁` reduced to `[0, ½]` (`ω₁ = ω_f/p`): the
//!   torus with Ω, −Ω and `Ω + jω₁` is the same, and `ρ` so reduced is the
//!   fraction of a turn the stroboscopic map (one response period) turns
//!   the section by, in either sense.
//! - **Mean of `|x_d|`** over the torus (the time average along a
//!   trajectory, by ergodicity of an irrational rotation): `|x_d|` has kinks
//!   where `x_d` changes sign, so it is not sampled: along each line
//!   `θ₂ = const` the series in θ₁ is integrated exactly between its roots
//!   (its antiderivative), and the lines' integrals, smooth in θ₂, are
//!   averaged by the trapezoidal rule.
//! - **Maximum of `|x_d|`**: the largest samples of a fine grid, each
//!   refined by Newton on `∇x_d = 0`.
//! - **Normal exponent** (one DOF only): along a quasi-periodic torus of
//!   `x″ = (f − C x′ − K x − g)/M` one Lyapunov exponent is zero (the
//!   direction along the torus) and the two sum to the time average of the
//!   divergence, `⟨−(C + ∂g/∂v)/M⟩`: the other is that average, exact from
//!   the grid. Negative: the torus attracts. With more DOFs the exponents
//!   are not computed (`None`).
//! - **Error estimate**: one Newton step of the same torus in a truncation
//!   [`WIDER`] orders wider, from the torus padded with zeros (to second
//!   order the distance to the wider truncation's solution): [`SAFETY`]
//!   times its change of each quantity.

use super::grid::eval_torus;
use super::{TorusBranch, TorusHarmonics, TorusOptions};
use crate::branches::family::Family;
use crate::error::HbError;
use crate::orbit::aft::eval_series;
use crate::problem::PeriodicProblem;
use ivt_num::LuWorkspace;
use ivt_path::branch::Branch;
use std::f64::consts::PI;

/// Orders the error estimate's truncation is wider than the torus's.
pub const WIDER: usize = 4;

/// The error estimate is this multiple of the change to the wider
/// truncation: the wider torus is itself in error, by a fraction of the
/// change where the coefficients decay geometrically (on the Van der Pol
/// torus of `tests/torus.rs` the box |k₁| ≤ 3, |k₂| ≤ 8 errs by up to 1.3×
/// its change, measured).
pub const SAFETY: f64 = 2.0;

/// The quantities of one torus (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TorusMeasures {
    /// `Ω/ω₁` reduced to `[0, ½]`.
    pub rotation_number: f64,
    /// Mean of `|x_d|` over the torus.
    pub amplitude_mean: f64,
    /// Maximum of `|x_d|` over the torus.
    pub amplitude_max: f64,
}

/// A torus read: its measures, their error estimates, the section and the
/// normal exponent.
#[derive(Debug, Clone, PartialEq)]
pub struct TorusReading {
    /// The measures.
    pub measures: TorusMeasures,
    /// Their estimated errors (the change to the wider truncation), `None`
    /// when not estimated.
    pub errors: Option<TorusMeasures>,
    /// The normal Lyapunov exponent (one DOF), `None` otherwise.
    pub normal_exponent: Option<f64>,
}

/// `ρ = Ω/ω₁` reduced to `[0, ½]`.
pub fn rotation_number(omega2: f64, omega1: f64) -> f64 {
    let r = (omega2 / omega1).rem_euclid(1.0);
    r.min(1.0 - r)
}

/// The series in θ₁ of the torus `coeffs` on the line `θ₂ = theta2`:
/// `[a₀, a₁..a_E, b₁..b_E]` with `E` the largest `|k₁|`.
fn line_series(harmonics: &TorusHarmonics, coeffs: &[f64], theta2: f64) -> Vec<f64> {
    let e = harmonics.truncation().extent().0;
    let h = harmonics.len();
    let mut out = vec![0.0; 2 * e + 1];
    let Some((&a0, rest)) = coeffs.split_first().filter(|(_, r)| r.len() == 2 * h) else {
        out.fill(f64::NAN);
        return out;
    };
    let (cos, sin) = rest.split_at(h);
    if let Some(o) = out.first_mut() {
        *o = a0;
    }
    for ((k1, k2), (&a, &b)) in harmonics.iter().zip(cos.iter().zip(sin)) {
        let (s, c) = (k2 as f64 * theta2).sin_cos();
        let m = k1.unsigned_abs() as usize;
        let (ca, sa) = match k1 {
            0 => {
                if let Some(o) = out.first_mut() {
                    *o += 2.0 * (a * c + b * s);
                }
                continue;
            }
            k if k > 0 => (a * c + b * s, b * c - a * s),
            _ => (a * c + b * s, a * s - b * c),
        };
        if let Some(o) = out.get_mut(m) {
            *o += ca;
        }
        if let Some(o) = out.get_mut(e + m) {
            *o += sa;
        }
    }
    out
}

/// `∫₀^θ u dθ` of a series `[a₀, a.., b..]` (its antiderivative, 0 at 0).
fn antiderivative(series: &[f64], theta: f64) -> f64 {
    let Some((&a0, rest)) = series.split_first() else {
        return f64::NAN;
    };
    let (cos, sin) = rest.split_at(rest.len() / 2);
    let mut s = 0.5 * a0 * theta;
    for (k, (&a, &b)) in cos.iter().zip(sin).enumerate() {
        let k = (k + 1) as f64;
        s += a / k * (k * theta).sin() + b / k * (1.0 - (k * theta).cos());
    }
    s
}

/// The root of the series in `[lo, hi]` (a sign change): bisection
/// safeguarding Newton, to rounding.
fn root(series: &[f64], mut lo: f64, mut hi: f64) -> f64 {
    let f_lo = eval_series(series, lo, 0);
    let mut x = 0.5 * (lo + hi);
    for _ in 0..100 {
        let f = eval_series(series, x, 0);
        if f == 0.0 {
            return x;
        }
        if (f > 0.0) == (f_lo > 0.0) {
            lo = x;
        } else {
            hi = x;
        }
        let slope = eval_series(series, x, 1);
        let newton = x - f / slope;
        x = if newton > lo && newton < hi && slope != 0.0 {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo < 1e-15 * (1.0 + hi.abs()) || (newton - x).abs() < 1e-16 {
            break;
        }
    }
    x
}

/// `(1/2π)∫₀^{2π} |u| dθ` of a series, exactly between its roots.
fn line_mean_abs(series: &[f64], samples: usize) -> f64 {
    let tau = 2.0 * PI;
    let grid: Vec<f64> = (0..=samples)
        .map(|i| tau * i as f64 / samples as f64)
        .collect();
    let values: Vec<f64> = grid.iter().map(|&t| eval_series(series, t, 0)).collect();
    let mut cuts = vec![0.0];
    for (w, v) in grid.windows(2).zip(values.windows(2)) {
        if let ([a, b], [fa, fb]) = (w, v) {
            if fa * fb < 0.0 {
                cuts.push(root(series, *a, *b));
            }
        }
    }
    cuts.push(tau);
    let total: f64 = cuts
        .windows(2)
        .map(|w| match w {
            [a, b] => (antiderivative(series, *b) - antiderivative(series, *a)).abs(),
            _ => 0.0,
        })
        .sum();
    total / tau
}

/// Mean and maximum of `|x|` over the torus of the series `coeffs` (one
/// DOF), on `lines` lines of θ₂ and `samples` points per line (both ≥ 8
/// times the largest `|k|` along their axis).
pub fn amplitude_mean_max(harmonics: &TorusHarmonics, coeffs: &[f64]) -> (f64, f64) {
    let (e1, e2) = harmonics.truncation().extent();
    let samples = (8 * e1).max(64);
    let lines = (8 * e2).max(64);
    let tau = 2.0 * PI;
    let mut mean = 0.0;
    let mut best: Vec<(f64, (f64, f64))> = Vec::new();
    for j in 0..lines {
        let theta2 = tau * j as f64 / lines as f64;
        let series = line_series(harmonics, coeffs, theta2);
        mean += line_mean_abs(&series, samples);
        for i in 0..samples {
            let theta1 = tau * i as f64 / samples as f64;
            let x = eval_series(&series, theta1, 0).abs();
            best.push((x, (theta1, theta2)));
        }
    }
    best.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut max = best.first().map_or(f64::NAN, |b| b.0);
    for &(_, start) in best.iter().take(8) {
        max = max.max(refine_max(harmonics, coeffs, start));
    }
    (mean / lines as f64, max)
}

/// `|x|` at the stationary point of `x` reached by Newton on `∇x = 0` from
/// `start` (the start's `|x|` if Newton leaves its neighbourhood).
fn refine_max(harmonics: &TorusHarmonics, coeffs: &[f64], start: (f64, f64)) -> f64 {
    let (mut t1, mut t2) = start;
    let x0 = eval_torus(harmonics, coeffs, start).0.abs();
    for _ in 0..20 {
        let (_, g, h) = eval_torus(harmonics, coeffs, (t1, t2));
        let det = h[0] * h[2] - h[1] * h[1];
        if det == 0.0 || !det.is_finite() {
            break;
        }
        let d1 = (h[2] * g[0] - h[1] * g[1]) / det;
        let d2 = (h[0] * g[1] - h[1] * g[0]) / det;
        t1 -= d1;
        t2 -= d2;
        if (t1 - start.0).abs() + (t2 - start.1).abs() > 0.5 {
            return x0;
        }
        if d1.abs() + d2.abs() < 1e-14 {
            break;
        }
    }
    eval_torus(harmonics, coeffs, (t1, t2)).0.abs().max(x0)
}

/// The Poincaré section `θ₁ = 0` of DOF `d`'s series: `(x, v)` at `points`
/// values of θ₂, `v = ω₁∂X/∂θ₁ + Ω∂X/∂θ₂`.
pub fn section(
    harmonics: &TorusHarmonics,
    coeffs: &[f64],
    (omega1, omega2): (f64, f64),
    points: usize,
) -> (Vec<f64>, Vec<f64>) {
    (0..points)
        .map(|j| {
            let theta2 = 2.0 * PI * j as f64 / points.max(1) as f64;
            let (x, g, _) = eval_torus(harmonics, coeffs, (0.0, theta2));
            (x, omega1 * g[0] + omega2 * g[1])
        })
        .unzip()
}

impl<F: Family> TorusBranch<F> {
    /// The measures of the torus `q` (coefficients then Ω) at λ, for DOF `d`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for a `q` of the wrong size or a DOF past
    /// the model.
    pub fn measures(&self, q: &[f64], lambda: f64, d: usize) -> Result<TorusMeasures, HbError> {
        let (coeffs, omega2) = self
            .split(q)
            .ok_or_else(|| HbError::InvalidInput("torus unknowns of the wrong size".into()))?;
        let l = self.harmonics.coeff_len();
        let block = coeffs
            .get(d * l..(d + 1) * l)
            .ok_or_else(|| HbError::InvalidInput(format!("no DOF {d} in the model")))?;
        let omega1 = self.family.at(lambda).1 / self.options.subharmonic as f64;
        let (amplitude_mean, amplitude_max) = amplitude_mean_max(&self.harmonics, block);
        Ok(TorusMeasures {
            rotation_number: rotation_number(omega2, omega1),
            amplitude_mean,
            amplitude_max,
        })
    }

    /// The frequencies `(ω₁, Ω)` of the torus `q` at λ.
    pub fn frequencies_at(&self, q: &[f64], lambda: f64) -> (f64, f64) {
        let omega1 = self.family.at(lambda).1 / self.options.subharmonic as f64;
        (omega1, q.last().copied().unwrap_or(f64::NAN))
    }

    /// The coefficients of DOF `d` of the torus `q` (empty past the model).
    pub fn dof_coeffs<'q>(&self, q: &'q [f64], d: usize) -> &'q [f64] {
        let l = self.harmonics.coeff_len();
        q.get(d * l..(d + 1) * l).unwrap_or_default()
    }

    /// The normal Lyapunov exponent of a one-DOF torus (module docs);
    /// `None` with more DOFs or a wrong size.
    pub fn normal_exponent(&mut self, q: &[f64], lambda: f64) -> Option<f64> {
        if self.n_dof != 1 {
            return None;
        }
        let (coeffs, omega2) = self.split(q)?;
        let coeffs = coeffs.to_vec();
        let (problem, omega_f) = self.family.at(lambda);
        let omega1 = omega_f / self.options.subharmonic as f64;
        self.synthesize_states(&coeffs, omega1, omega2, true);
        problem.nonlinear_jacobian_samples(&self.xs, &self.vs, &self.thetas, &mut self.dg);
        let (m, c) = (problem.mass().first()?, problem.damping().first()?);
        let ns = self.grid.len() as f64;
        let dg_v: f64 = self
            .dg
            .chunks_exact(2)
            .map(|s| s.get(1).copied().unwrap_or(f64::NAN))
            .sum();
        Some(-(c + dg_v / ns) / m)
    }

    /// Measures, error estimates (when `estimate`) and the normal exponent
    /// of the torus `q` at λ for DOF `d`.
    ///
    /// # Errors
    /// As [`Self::measures`]; the wider truncation's planning.
    pub fn read(
        &mut self,
        q: &[f64],
        lambda: f64,
        d: usize,
        estimate: bool,
    ) -> Result<TorusReading, HbError> {
        let measures = self.measures(q, lambda, d)?;
        let errors = if estimate {
            let (wide, q_wide) = self.wider_step(q, lambda)?;
            let other = wide.measures(&q_wide, lambda, d)?;
            let change = |a: f64, b: f64| SAFETY * (a - b).abs();
            Some(TorusMeasures {
                rotation_number: change(other.rotation_number, measures.rotation_number),
                amplitude_mean: change(other.amplitude_mean, measures.amplitude_mean),
                amplitude_max: change(other.amplitude_max, measures.amplitude_max),
            })
        } else {
            None
        };
        Ok(TorusReading {
            measures,
            errors,
            normal_exponent: self.normal_exponent(q, lambda),
        })
    }

    /// One Newton step of the torus `q` in the truncation [`WIDER`] orders
    /// wider (module docs).
    fn wider_step(&self, q: &[f64], lambda: f64) -> Result<(Wider<'_, F>, Vec<f64>), HbError> {
        let (coeffs, omega2) = self
            .split(q)
            .ok_or_else(|| HbError::InvalidInput("torus unknowns of the wrong size".into()))?;
        let options = TorusOptions {
            truncation: self.options.truncation.widened(WIDER),
            samples: (0, 0),
            ..self.options
        };
        let family: Box<dyn Fn(f64) -> (F::Problem, f64) + '_> =
            Box::new(|lam| self.family.at(lam));
        let mut wide = TorusBranch::planned(family, &options, lambda)?;
        let padded = wide.embed(&self.harmonics, coeffs);
        wide.set_reference(&padded)?;
        let mut x = padded;
        x.push(omega2);
        let m = wide.len();
        let (mut r, mut jac) = (vec![0.0; m], vec![0.0; m * m]);
        wide.residual(&x, lambda, &mut r);
        wide.jacobian(&x, lambda, &mut jac);
        let mut lu = LuWorkspace::new(m);
        if !lu.factor_row_major(&jac) {
            return Err(HbError::InvalidInput(
                "the wider truncation's Jacobian is singular at this torus".into(),
            ));
        }
        lu.solve(&mut r);
        x.iter_mut().zip(&r).for_each(|(xi, ri)| *xi -= ri);
        Ok((wide, x))
    }
}

/// The torus system of the error estimate's wider truncation.
type Wider<'f, F> = TorusBranch<Box<dyn Fn(f64) -> (<F as Family>::Problem, f64) + 'f>>;
