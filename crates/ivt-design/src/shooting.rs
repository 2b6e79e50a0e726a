//! The independent reference for the steady state: Eq. 162 integrated in θ,
//!
//! ```text
//! J ω ω' = Γ − ½ J_θ ω² − F_m ω,   t' = 1/ω,   Γ = G r + f1 − f2 r,
//! ```
//!
//! with the order-6 Runge–Kutta of [`ivt_num::RK6`] on the smooth pieces between
//! the gear corners. For a fixed r, the periodic ω̄(θ) is the fixed point of the
//! map ω(0) ↦ ω(2π) (unique and attracting by Theorem 2); its period in time is
//! T = ∫₀^{2π} dθ/ω, so the time mean of ω is ω_a = 2π/T (the quantity the
//! controller measures, §4.3). The design point r̄ solves `ω_a(r̄) = ω0`.
//! Both conditions are solved together by Newton ([`ivt_num::newton()`]) on
//! (ω(0), r), with the exact Jacobian from the variational equations
//! integrated alongside.

use super::pieces::{pieces, rk6, steps_for, Rk6};
use super::{averaged_r, check_plant, IvtError, OperatingPoint};
use core::f64::consts::PI;
use ivt_kin::plant::PlantParams;
use ivt_kin::variant::f_on_segment;
use ivt_num::{newton, NewtonOptions, NewtonSystem, NewtonWorkspace, SolveError};

/// Accuracy and iteration limits of the shooting route.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShootingOptions {
    /// RK6 steps per gear segment (π/2 of θ). 48 gives ~1e-12 relative in r̄
    /// on the thesis grid (see the convergence test).
    pub steps_per_segment: usize,
    /// Relative tolerance on the Newton update of (ω(0), r).
    pub tol: f64,
    /// Newton iteration limit.
    pub max_iter: usize,
}

impl Default for ShootingOptions {
    fn default() -> Self {
        Self {
            steps_per_segment: 48,
            tol: 1e-13,
            max_iter: 40,
        }
    }
}

/// A periodic steady state of Eq. 162 for one constant r.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeriodicOrbit {
    /// The eccentricity r \[m\].
    pub r: f64,
    /// ω̄(0) \[rad/s\].
    pub omega_start: f64,
    /// Time for one revolution of θ, T = ∫ dθ/ω̄ \[s\].
    pub period: f64,
    /// Smallest ω̄ on the integration nodes \[rad/s\].
    pub omega_min: f64,
    /// Largest ω̄ on the integration nodes \[rad/s\].
    pub omega_max: f64,
}

impl PeriodicOrbit {
    /// Time mean of ω̄, ω_a = 2π/T \[rad/s\] (§4.3).
    pub fn omega_a(&self) -> f64 {
        2.0 * PI / self.period
    }
}

/// Right-hand side of Eq. 162 plus its variational equations.
/// State: [ω, t, ∂ω/∂ω(0), ∂ω/∂r, ∂t/∂ω(0), ∂t/∂r].
struct Variational<'a> {
    plant: &'a PlantParams,
    v_m: f64,
    t_u: f64,
    r: f64,
    seg: i64,
}

impl Variational<'_> {
    fn rhs(&self, theta: f64, y: &[f64], dy: &mut [f64]) {
        let (f, ft) = f_on_segment(theta, self.seg);
        let p = self
            .plant
            .terms_with_f(theta, f, ft, self.r, self.v_m, self.t_u);
        // y = [ω, t, ∂ω/∂ω0, ∂ω/∂r, ∂t/∂ω0, ∂t/∂r]
        let (Some(&[w, _, s_w, s_r, _, _]), Some(out)) =
            (y.first_chunk::<6>(), dy.first_chunk_mut::<6>())
        else {
            dy.fill(f64::NAN);
            return;
        };
        let inv_w = 1.0 / w;
        let drive = p.drive(self.r);
        let num = drive * inv_w - 0.5 * p.j_theta * w - p.f_m;
        let dw = num / p.j;
        // ∂(ω')/∂ω and ∂(ω')/∂r (J depends on r through J_r).
        let f_w = (-drive * inv_w * inv_w - 0.5 * p.j_theta) / p.j;
        let f_r = ((p.g - p.f2) * inv_w - 0.5 * p.j_theta_r * w - dw * p.j_r) / p.j;
        *out = [
            dw,
            inv_w,
            f_w * s_w,
            f_w * s_r + f_r,
            -s_w * inv_w * inv_w,
            -s_r * inv_w * inv_w,
        ];
    }
}

/// One revolution θ ∈ [0, 2π] from ω(0) = `omega_start` at constant r:
/// returns the final state [ω, t, ∂ω/∂ω0, ∂ω/∂r, ∂t/∂ω0, ∂t/∂r] and (min, max) ω.
fn revolution(
    plant: &PlantParams,
    v_m: f64,
    t_u: f64,
    r: f64,
    omega_start: f64,
    steps_per_segment: usize,
    rk: &mut Rk6,
) -> Result<([f64; 6], f64, f64), IvtError> {
    let mut y = [omega_start, 0.0, 1.0, 0.0, 0.0, 0.0];
    let (mut lo, mut hi) = (omega_start, omega_start);
    for (a, b, seg) in pieces(0.0, 2.0 * PI) {
        let sys = Variational {
            plant,
            v_m,
            t_u,
            r,
            seg,
        };
        let n = steps_for(b - a, steps_per_segment);
        let h = (b - a) / n as f64;
        let mut rhs = |x: f64, y: &[f64], dy: &mut [f64]| sys.rhs(x, y, dy);
        for i in 0..n {
            let x = a + i as f64 * h;
            rk.step(&mut rhs, x, h, &mut y);
            if !(y[0].is_finite() && y[0] > 0.0) {
                return Err(IvtError::Stall {
                    theta: x + h,
                    omega: y[0],
                    r,
                });
            }
            lo = lo.min(y[0]);
            hi = hi.max(y[0]);
        }
    }
    Ok((y, lo, hi))
}

/// The periodic ω̄(θ) of Eq. 162 for a given constant r (open loop): Newton on
/// ω(0) with the exact ∂ω(2π)/∂ω(0). Used to evaluate any open-loop law.
///
/// # Errors
/// Bad inputs, a stall (ω ≤ 0), or no convergence (with the residual history).
pub fn periodic_at_r(
    plant: &PlantParams,
    v_m: f64,
    t_u: f64,
    r: f64,
    omega_guess: f64,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, IvtError> {
    check_plant(plant)?;
    OperatingPoint {
        v_m,
        t_u,
        omega0: omega_guess,
    }
    .validate()?;
    let mut map = ReturnMap::new(plant, v_m, t_u, Unknowns::OmegaStart { r }, opts);
    let mut x = [omega_guess];
    solve(&mut map, &mut x, opts, "periodic orbit (shooting in θ)")?;
    let (y, lo, hi) = map.last;
    Ok(PeriodicOrbit {
        r,
        omega_start: x[0],
        period: y[1],
        omega_min: lo,
        omega_max: hi,
    })
}

/// ω̄ at the angles θ_k = 2πk/`samples` (k = 0 … samples−1) over one
/// revolution of the orbit at constant r that starts at ω̄(0) = `omega_start`
/// (e.g. [`PeriodicOrbit::omega_start`]): Eq. 162 integrated by RK6 on the
/// smooth pieces, every step ending on a sample angle or a gear corner, at
/// least `steps_per_segment` steps per π/2. This is how the simulator's
/// encoder samples ω (pulse angles 2πk/PPR), without the 1/n convergence of
/// a truncated Fourier series at the kinks of ω̄(θ).
///
/// # Errors
/// Bad inputs, `samples` = 0, or a stall (ω ≤ 0).
pub fn omega_at_angles(
    plant: &PlantParams,
    v_m: f64,
    t_u: f64,
    r: f64,
    omega_start: f64,
    samples: usize,
    steps_per_segment: usize,
) -> Result<Vec<f64>, IvtError> {
    check_plant(plant)?;
    OperatingPoint {
        v_m,
        t_u,
        omega0: omega_start,
    }
    .validate()?;
    if samples == 0 {
        return Err(IvtError::EmptyGrid("samples"));
    }
    let dtheta = 2.0 * PI / samples as f64;
    let mut rk = rk6(1);
    let mut y = [omega_start];
    let mut out = Vec::with_capacity(samples);
    out.push(omega_start);
    for k in 0..samples - 1 {
        let (a0, b0) = (k as f64 * dtheta, (k + 1) as f64 * dtheta);
        for (a, b, seg) in pieces(a0, b0) {
            let mut rhs = |theta: f64, y: &[f64], dy: &mut [f64]| {
                let (f, ft) = f_on_segment(theta, seg);
                let p = plant.terms_with_f(theta, f, ft, r, v_m, t_u);
                if let (Some(dw), Some(&w)) = (dy.first_mut(), y.first()) {
                    *dw = (p.drive(r) / w - 0.5 * p.j_theta * w - p.f_m) / p.j;
                }
            };
            rk.integrate(&mut rhs, a, b, steps_for(b - a, steps_per_segment), &mut y);
            if !(y[0].is_finite() && y[0] > 0.0) {
                return Err(IvtError::Stall {
                    theta: b,
                    omega: y[0],
                    r,
                });
            }
        }
        out.push(y[0]);
    }
    Ok(out)
}

/// The design point by shooting: (r̄, ω̄(0)) with ω̄ periodic and time mean ω0.
/// `r_seed` defaults to the averaged power balance ([`averaged_r`]).
///
/// # Errors
/// Bad inputs, a stall, or no convergence (with the residual history).
pub fn shoot_steady_state(
    plant: &PlantParams,
    op: &OperatingPoint,
    r_seed: Option<f64>,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, IvtError> {
    check_plant(plant)?;
    op.validate()?;
    let unknowns = Unknowns::OmegaStartAndR {
        omega0: op.omega0,
        t_target: 2.0 * PI / op.omega0,
    };
    let mut map = ReturnMap::new(plant, op.v_m, op.t_u, unknowns, opts);
    let mut x = [op.omega0, r_seed.unwrap_or_else(|| averaged_r(plant, op))];
    solve(&mut map, &mut x, opts, "steady state (shooting in θ)")?;
    let (y, lo, hi) = map.last;
    Ok(PeriodicOrbit {
        r: x[1],
        omega_start: x[0],
        period: y[1],
        omega_min: lo,
        omega_max: hi,
    })
}

/// The unknowns of a shooting problem.
#[derive(Clone, Copy)]
enum Unknowns {
    /// ω(0) at a fixed r: residual ω(2π) − ω(0).
    OmegaStart { r: f64 },
    /// (ω(0), r): residuals (ω(2π) − ω(0))/ω0 and (T − 2π/ω0)/(2π/ω0), each
    /// relative so that the line search weighs them alike.
    OmegaStartAndR { omega0: f64, t_target: f64 },
}

/// The return map of one revolution as a Newton system; the Jacobian comes
/// from the variational equations of the last revolution, which is kept
/// (with its ω extremes) for the caller.
struct ReturnMap<'a> {
    plant: &'a PlantParams,
    v_m: f64,
    t_u: f64,
    unknowns: Unknowns,
    steps_per_segment: usize,
    rk: Rk6,
    last: ([f64; 6], f64, f64),
}

impl<'a> ReturnMap<'a> {
    fn new(
        plant: &'a PlantParams,
        v_m: f64,
        t_u: f64,
        unknowns: Unknowns,
        opts: &ShootingOptions,
    ) -> Self {
        Self {
            plant,
            v_m,
            t_u,
            unknowns,
            steps_per_segment: opts.steps_per_segment,
            rk: rk6(6),
            last: ([f64::NAN; 6], f64::NAN, f64::NAN),
        }
    }
}

impl NewtonSystem for ReturnMap<'_> {
    type Error = IvtError;
    /// A trial with ω(0) ≤ 0 is outside the domain (NaN residual: the step
    /// is halved); a revolution that stalls is an error.
    fn residual(&mut self, x: &[f64], res: &mut [f64]) -> Result<(), IvtError> {
        // x = [ω(0)] or [ω(0), r]; too short a trial is outside the domain too.
        let (omega_start, r) = match (self.unknowns, x) {
            (Unknowns::OmegaStart { r }, &[w, ..]) => (w, r),
            (Unknowns::OmegaStartAndR { .. }, &[w, r, ..]) => (w, r),
            _ => (f64::NAN, f64::NAN),
        };
        if omega_start.is_nan() || omega_start <= 0.0 {
            res.fill(f64::NAN);
            return Ok(());
        }
        let (v_m, t_u, steps) = (self.v_m, self.t_u, self.steps_per_segment);
        self.last = revolution(self.plant, v_m, t_u, r, omega_start, steps, &mut self.rk)?;
        let y = &self.last.0;
        match (self.unknowns, res) {
            (Unknowns::OmegaStartAndR { omega0, t_target }, [r0, r1, ..]) => {
                *r0 = (y[0] - omega_start) / omega0;
                *r1 = (y[1] - t_target) / t_target;
            }
            (_, res) => res.fill(y[0] - omega_start),
        }
        Ok(())
    }

    /// `[[S_ω − 1, S_r], [T_ω, T_r]]` (scaled as the residual) from the
    /// variational state of the last revolution, which ran at this `x`.
    fn jacobian(&mut self, _x: &[f64], jac: &mut [f64]) -> Result<(), IvtError> {
        let y = &self.last.0;
        match self.unknowns {
            Unknowns::OmegaStart { .. } => jac.fill(y[2] - 1.0),
            Unknowns::OmegaStartAndR { omega0, t_target } => {
                let entries = [
                    (y[2] - 1.0) / omega0,
                    y[3] / omega0,
                    y[4] / t_target,
                    y[5] / t_target,
                ];
                jac.iter_mut().zip(entries).for_each(|(j, e)| *j = e);
            }
        }
        Ok(())
    }
}

/// Newton on the return map ([`ivt_num::newton()`]): stops when every update
/// is below `tol` relative (r: relative to max(|r|, 1e-6 m)); a step
/// without descent is taken (the map contracts, Theorem 2).
fn solve(
    map: &mut ReturnMap<'_>,
    x: &mut [f64],
    opts: &ShootingOptions,
    method: &'static str,
) -> Result<(), IvtError> {
    let nopts = NewtonOptions {
        ftol: 0.0,
        rtol: opts.tol,
        atol: opts.tol * 1e-6,
        max_iter: opts.max_iter,
        accept_no_descent: true,
        ..NewtonOptions::default()
    };
    let mut ws = NewtonWorkspace::new(x.len());
    match newton(map, x, &mut ws, &nopts) {
        Ok(_) => Ok(()),
        Err(SolveError::Eval(e)) => Err(e),
        Err(e) => Err(IvtError::NoConvergence {
            method,
            iterations: e.history().len().saturating_sub(1),
            history: e.history().to_vec(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sampled revolution does not depend on the sample grid (RK6 with
    /// ≥ 48 steps per segment: ~1e-12), its time mean matches the orbit's
    /// period, and its extremes are those of `periodic_at_r`'s 192 nodes up
    /// to the grids' sampling (the minimum lies between corners: 1.2e-4
    /// relative apart here, the finer 1200-point grid finding the lower one).
    #[test]
    fn sampled_revolution_matches_the_orbit() {
        let plant = PlantParams::printed();
        let opts = ShootingOptions::default();
        let orbit = periodic_at_r(&plant, 8.4, 6.0, 0.006, 10.0, &opts).unwrap();
        let w = omega_at_angles(&plant, 8.4, 6.0, 0.006, orbit.omega_start, 1200, 48).unwrap();
        assert_eq!(w.len(), 1200);
        let coarse = omega_at_angles(&plant, 8.4, 6.0, 0.006, orbit.omega_start, 600, 48).unwrap();
        assert!((coarse[300] - w[600]).abs() < 1e-10 * w[600]);
        // Time mean from the samples (trapezoid on dt = dθ/ω, second order in
        // dθ away from the kinks) vs the exact period: 1e-5.
        let t: f64 = w.iter().map(|x| 2.0 * PI / 1200.0 / x).sum();
        assert!(
            (t / orbit.period - 1.0).abs() < 1e-5,
            "{t} vs {}",
            orbit.period
        );
        let lo = w.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = w.iter().cloned().fold(0.0, f64::max);
        assert!(lo <= orbit.omega_min && (orbit.omega_min - lo) < 3e-4 * lo);
        assert!(
            (hi - orbit.omega_max).abs() < 3e-4 * hi,
            "{hi} {}",
            orbit.omega_max
        );
        assert!(omega_at_angles(&plant, 8.4, 6.0, 0.006, 10.0, 0, 48).is_err());
    }

    /// With r fixed at the shooting r̄, the open-loop orbit has ω_a = ω0: the
    /// two entry points agree (same integrator, different unknowns).
    #[test]
    fn fixed_r_orbit_has_target_mean() {
        let plant = PlantParams::printed();
        let op = OperatingPoint::at_100_rpm(9.0, 4.0);
        let opts = ShootingOptions::default();
        let s = shoot_steady_state(&plant, &op, None, &opts).unwrap();
        let o = periodic_at_r(&plant, 9.0, 4.0, s.r, 10.0, &opts).unwrap();
        assert!((o.omega_a() - op.omega0).abs() < 1e-10 * op.omega0);
        assert!((o.omega_start - s.omega_start).abs() < 1e-9 * op.omega0);
    }

    /// r̄ converges as the step shrinks (order 6 on smooth pieces): 24 vs 48
    /// vs 96 steps per segment, differences fall by ≥ 30× (2⁶ = 64 ideal), and
    /// the default 48 is within 1e-9 relative of 96.
    #[test]
    fn step_convergence() {
        let plant = PlantParams::printed();
        let op = OperatingPoint::at_100_rpm(9.0, 5.0);
        let r = |n| {
            let o = ShootingOptions {
                steps_per_segment: n,
                ..Default::default()
            };
            shoot_steady_state(&plant, &op, None, &o).unwrap().r
        };
        let (a, b, c) = (r(24), r(48), r(96));
        let (d1, d2) = ((a - b).abs(), (b - c).abs());
        assert!(d2 < 1e-11 * c.abs() || d1 / d2 > 30.0, "{d1:e} {d2:e}");
        assert!(d2 < 1e-9 * c.abs(), "{d2:e}");
    }
}
