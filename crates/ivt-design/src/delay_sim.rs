//! Direct simulation of the nonlinear delay loop, Eq. 172 in θ:
//!
//! ```text
//! J ω' = Γ(r)/ω − ½ J_θ ω − F_m,   r' = k(2π/z − ω0) + k2(ω − ω_T),   z' = 1/ω − 1/ω_T
//! ```
//!
//! with ω_T = ω(θ − 2π) read from a history buffer. It is the independent
//! check of the Floquet analysis in [`super::delay`]: started on the periodic
//! steady state with a small offset in r, the deviation of ω_a = 2π/z from ω0
//! must contract per revolution by the predicted max |multiplier|.
//!
//! Classical RK4 ([`ivt_num::RK4`]) with a fixed step h = π/(2M) (M even),
//! so that every gear corner is a step end. The history holds ω at every half step (the RK4
//! stage points); the mid-step value is the cubic Hermite interpolant of the
//! step's end values and slopes (error O(h⁴), like the method).

use super::delay::{DelayStability, FeedbackGains};
use super::shooting::PeriodicOrbit;
use super::{check_plant, IvtError, OperatingPoint};
use core::f64::consts::{FRAC_PI_2, PI};
use ivt_kin::plant::PlantParams;
use ivt_kin::variant::{f_on_segment, segment_of};
use ivt_num::{ExplicitRk, RK4};

/// Discretization and length of the simulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelaySimOptions {
    /// RK4 steps per gear segment (π/2), even.
    pub steps_per_segment: usize,
    /// Revolutions of θ to simulate.
    pub revolutions: usize,
    /// Offset of r at θ = 0 \[m\] (small: the check is of the linearization).
    pub dr0: f64,
}

impl Default for DelaySimOptions {
    fn default() -> Self {
        Self {
            steps_per_segment: 64,
            revolutions: 200,
            dr0: 1e-6,
        }
    }
}

/// ω_a − ω0 at the end of each revolution, and the contraction measured from it.
#[derive(Clone, Debug, PartialEq)]
pub struct Contraction {
    /// ω_a − ω0 \[rad/s\] at θ = 2πk, k = 1 … revolutions.
    pub error: Vec<f64>,
    /// Per-revolution contraction of the differences d_k = error_{k+1} − error_k.
    /// With K the last revolution where |d_k| is still above 1e-8 of its peak
    /// (round-off floor) and q = K/4: the RMS of d over [K−q, K) divided by
    /// that over [K−2q, K−q), to the power 1/q (the RMS absorbs the
    /// oscillation of a complex pair).
    pub measured: f64,
}

struct Loop<'a> {
    plant: &'a PlantParams,
    op: OperatingPoint,
    gains: FeedbackGains,
}

impl Loop<'_> {
    fn omega_dot(&self, seg: i64, theta: f64, w: f64, r: f64) -> f64 {
        let (f, ft) = f_on_segment(theta, seg);
        let p = self
            .plant
            .terms_with_f(theta, f, ft, r, self.op.v_m, self.op.t_u);
        (p.drive(r) / w - 0.5 * p.j_theta * w - p.f_m) / p.j
    }

    /// dy/dθ for y = [ω, r, z] with ω_T given.
    fn rhs(&self, seg: i64, theta: f64, y: &[f64], w_t: f64) -> [f64; 3] {
        let &[w, r, z] = y else {
            return [f64::NAN; 3];
        };
        [
            self.omega_dot(seg, theta, w, r),
            self.gains.k * (2.0 * PI / z - self.op.omega0) + self.gains.k2 * (w - w_t),
            1.0 / w - 1.0 / w_t,
        ]
    }
}

/// Simulate Eq. 172 from the steady state `orbit` with r offset by `dr0`.
///
/// # Errors
/// Bad inputs, odd/zero step count, or a stall.
pub fn simulate_contraction(
    plant: &PlantParams,
    op: &OperatingPoint,
    gains: FeedbackGains,
    orbit: &PeriodicOrbit,
    opts: &DelaySimOptions,
) -> Result<Contraction, IvtError> {
    check_plant(plant)?;
    op.validate()?;
    let m = opts.steps_per_segment;
    if m < 2 || m % 2 == 1 || opts.revolutions < 8 {
        return Err(IvtError::Input {
            name: "steps_per_segment/revolutions",
            value: m as f64,
            requirement: "even steps >= 2 and >= 8 revolutions",
        });
    }
    let sys = Loop {
        plant,
        op: *op,
        gains,
    };
    let h = FRAC_PI_2 / m as f64;
    let per_rev = 4 * m; // steps per revolution
                         // hist[i] = [ω at step i, ω at step i + ½] (one revolution, circular).
    let mut hist = vec![[0.0; 2]; per_rev];
    // Segment of step i: the corner-aligned grid puts each step inside one segment.
    let seg_of = |i: usize| segment_of((i as f64 + 0.5) * h);
    let hermite_mid = |w0: f64, w1: f64, d0: f64, d1: f64| 0.5 * (w0 + w1) + h * (d0 - d1) / 8.0;

    // Revolution 0: the open-loop steady state at r̄ fills the history and z.
    let (mut w, r_bar) = (orbit.omega_start, orbit.r);
    let mut rk_open = ExplicitRk::<4, [f64; 1]>::new(&RK4);
    let mut rk = ExplicitRk::<4, [f64; 3]>::new(&RK4);
    let mut z = 0.0;
    for (i, slot) in hist.iter_mut().enumerate() {
        let (seg, th) = (seg_of(i), i as f64 * h);
        let mut f = |t: f64, w: &[f64], dw: &mut [f64]| {
            if let (Some(dw), Some(&w)) = (dw.first_mut(), w.first()) {
                *dw = sys.omega_dot(seg, t, w, r_bar);
            }
        };
        let mut w1 = [w];
        rk_open.step(&mut f, th, h, &mut w1);
        let w1 = w1[0];
        let mid = hermite_mid(
            w,
            w1,
            first_slope(&rk_open),
            sys.omega_dot(seg, th + h, w1, r_bar),
        );
        *slot = [w, mid];
        z += h / 6.0 * (1.0 / w + 4.0 / mid + 1.0 / w1); // Simpson on the same nodes
        w = w1;
    }
    let mut y = [w, r_bar + opts.dr0, z];
    let mut error = Vec::with_capacity(opts.revolutions);
    for _rev in 0..opts.revolutions {
        for i in 0..per_rev {
            let (seg, th) = (seg_of(i), i as f64 * h);
            // NaN only off the ring (cannot happen): the stall check below reports it.
            let [wt0, wth] = hist.get(i).copied().unwrap_or([f64::NAN; 2]);
            let [wt1, _] = hist
                .get((i + 1) % per_rev)
                .copied()
                .unwrap_or([f64::NAN; 2]);
            // The RK4 stages sit at θ, θ + h/2 and θ + h: the history nodes 0, 1, 2.
            let mut f = |t: f64, y: &[f64], dy: &mut [f64]| {
                let node = (2.0 * (t - th) / h).round() as usize;
                let w_t = [wt0, wth, wt1].get(node).copied().unwrap_or(f64::NAN);
                dy.copy_from_slice(&sys.rhs(seg, t, y, w_t));
            };
            let mut y1 = y;
            rk.step(&mut f, th, h, &mut y1);
            if !(y1[0].is_finite() && y1[0] > 0.0 && y[2] > 0.0) {
                return Err(IvtError::Stall {
                    theta: th + h,
                    omega: y1[0],
                    r: y1[1],
                });
            }
            let d1 = sys.omega_dot(seg, th + h, y1[0], y1[1]);
            let mid = hermite_mid(y[0], y1[0], first_slope(&rk), d1);
            // z by Simpson on exactly the values that enter and leave the
            // history, so z ≡ Simpson ∫_{θ−2π}^{θ} dσ/ω to round-off. (RK4 on
            // z' = 1/ω − 1/ω_T would drift by O(h⁴) per revolution along the
            // neutral mode of Appendix C and never settle.)
            y1[2] = y[2] + h / 6.0 * (1.0 / y[0] + 4.0 / mid + 1.0 / y1[0])
                - h / 6.0 * (1.0 / wt0 + 4.0 / wth + 1.0 / wt1);
            // Overwrite the history slot of this step: it becomes ω_T one revolution later.
            if let Some(slot) = hist.get_mut(i) {
                *slot = [y[0], mid];
            }
            y = y1;
        }
        error.push(2.0 * PI / y[2] - op.omega0);
    }
    // The discrete loop settles at an O(h⁴) offset of ω_a (the RK4 stage
    // values of ω and the Hermite history values of ω_T differ at that order),
    // so the contraction is measured on successive differences, which decay
    // like λ^k whatever the offset.
    let diff: Vec<f64> = error
        .iter()
        .zip(error.iter().skip(1))
        .map(|(a, b)| b - a)
        .collect();
    let peak = diff.iter().fold(0.0f64, |a, e| a.max(e.abs()));
    let n = diff
        .iter()
        .rposition(|e| e.abs() > 1e-8 * peak)
        .map_or(0, |k| k + 1);
    if n < 8 {
        return Err(IvtError::Input {
            name: "revolutions",
            value: n as f64,
            requirement: "enough revolutions above the round-off floor (>= 8)",
        });
    }
    let q = n / 4;
    let rms = |s: &[f64]| (s.iter().map(|e| e * e).sum::<f64>() / s.len() as f64).sqrt();
    let (Some(late), Some(earlier)) = (diff.get(n - q..n), diff.get(n - 2 * q..n - q)) else {
        return Err(IvtError::Input {
            name: "revolutions",
            value: n as f64,
            requirement: "enough revolutions above the round-off floor (>= 8)",
        });
    };
    let (late, earlier) = (rms(late), rms(earlier));
    Ok(Contraction {
        measured: (late / earlier).powf(1.0 / q as f64),
        error,
    })
}

/// The independent check of a Floquet prediction (§4.3): simulates the loop
/// from the steady state `s.orbit` and returns the measured contraction with
/// its relative gap |measured − max|μ|| / max|μ| to `s.max_abs_multiplier`.
///
/// # Errors
/// As [`simulate_contraction`].
pub fn check_prediction(
    plant: &PlantParams,
    op: &OperatingPoint,
    gains: FeedbackGains,
    s: &DelayStability,
    opts: &DelaySimOptions,
) -> Result<(Contraction, f64), IvtError> {
    let c = simulate_contraction(plant, op, gains, &s.orbit, opts)?;
    let predicted = s.max_abs_multiplier;
    let gap = (c.measured - predicted).abs() / predicted;
    Ok((c, gap))
}
/// dω/dθ at the start of the last RK4 step (its stage 0, ω the state's
/// first entry): the Hermite midpoint's left slope.
fn first_slope<const N: usize>(rk: &ExplicitRk<4, [f64; N]>) -> f64 {
    rk.stage(0)
        .and_then(|k| k.first())
        .copied()
        .unwrap_or(f64::NAN)
}
