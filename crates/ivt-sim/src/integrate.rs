//! Integration of the plant between events, in the time domain (start-up from
//! rest, near-stall) and in the angle domain (θ independent, t a state, the
//! form of Eq. 162) once ω is positive.
//!
//! Both domains wrap the one right-hand side [`Plant::derivatives`]:
//! - time domain: `y = [θ, ω, i_a]`, `y' = F(y)`;
//! - angle domain: `z = [t, ω, i_a]`, `dz/dθ = [1, ω̇, i̇_a]/ω`.
//!
//! Every step is a step of the one Runge–Kutta stepper of the workspace,
//! [`ivt_num::ExplicitRk`] with the [`RK4`] or [`DP5`] tableau on the
//! fixed-size state `[f64; 3]`, built for each step so that the tableau is a
//! constant the compiler folds into the stages. Each stepper call gets its
//! own right-hand-side closure: a closure called from one place only is
//! inlined into the stages, as the hand-written kernels were (one closure
//! shared by four calls was not, and cost ≈ 10 % of a DP5 run; measured, not
//! asserted).
//!
//! Steps never straddle a corner of f (θ = π/4 + kπ/2) or the requested target
//! angle (the next encoder pulse): in the angle domain the step is shortened to
//! land on it; in the time domain the crossing time is found on the dense
//! output and the step is retaken to end there. Each step uses the analytic
//! branch of f of its own segment, so the error control sees a smooth problem.

use crate::error::SimError;
use crate::plant::{segment_end, AngleTerms, Inputs, Plant, DIM};
use ivt_num::rk::step_factor;
use ivt_num::{ExplicitRk, DP5, RK4};
use std::cell::Cell;

pub use ivt_num::Tolerance;

/// The Dormand–Prince 5(4) stepper on the plant state.
type Dp5 = ExplicitRk<7, [f64; DIM]>;

/// V_m(t) and T_U(t) as seen by the plant.
pub trait InputProfile {
    /// `(V_m, T_U)` at time `t`.
    fn at(&self, t: f64) -> (f64, f64);
}

/// Constant inputs.
#[derive(Clone, Copy, Debug)]
pub struct ConstantInputs {
    /// V_m \[V\].
    pub v_m: f64,
    /// T_U \[N·m\].
    pub t_u: f64,
}

impl InputProfile for ConstantInputs {
    fn at(&self, _t: f64) -> (f64, f64) {
        (self.v_m, self.t_u)
    }
}

/// How the plant is integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Adaptive Dormand–Prince 5(4) in both domains.
    Dp5(Tolerance),
    /// Fixed-step RK4 in the angle domain with steps of at most `dtheta`
    /// (shortened to land on corners and pulses); the time-domain start-up
    /// phase uses DP5 with `startup` tolerances.
    Rk4 {
        /// Largest angle step \[rad\].
        dtheta: f64,
        /// Tolerances of the time-domain phase.
        startup: Tolerance,
    },
}

/// Why [`PlantIntegrator::advance`] returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reached {
    /// θ reached the target angle exactly.
    Angle,
    /// t reached the time limit (only checked in the time domain and between
    /// angle-domain steps).
    Time,
}

/// Counters for benchmarks and reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps in the time domain.
    pub time_steps: u64,
    /// Accepted steps in the angle domain.
    pub angle_steps: u64,
    /// Rejected adaptive steps.
    pub rejected: u64,
}

struct TimeSys<'a, P> {
    plant: &'a Plant,
    seg: i64,
    r: f64,
    prof: &'a P,
}

/// The stepper's state and derivative as `DIM`-arrays, or None after filling
/// `dy` with NaN: the stepper hands exactly DIM values, so any other length
/// is a bug that shows as a non-finite state (SimError::NotFinite), never a
/// panic.
#[inline(always)]
fn state<'a>(y: &'a [f64], dy: &'a mut [f64]) -> Option<(&'a [f64; DIM], &'a mut [f64; DIM])> {
    if y.len() != DIM || dy.len() != DIM {
        dy.fill(f64::NAN);
        return None;
    }
    Some((y.try_into().ok()?, dy.try_into().ok()?))
}

impl<P: InputProfile> TimeSys<'_, P> {
    /// `dy = F(t, y)` with `y = [θ, ω, i_a]`.
    #[inline(always)]
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) {
        let Some(([th, om, ia], dy)) = state(y, dy) else {
            return;
        };
        let (v_m, t_u) = self.prof.at(t);
        *dy = self.plant.derivatives(
            self.seg,
            &[*th, *om, *ia],
            &Inputs {
                r: self.r,
                v_m,
                t_u,
            },
        );
    }
}

struct AngleSys<'a, P> {
    plant: &'a Plant,
    seg: i64,
    r: f64,
    prof: &'a P,
    cache: &'a AngleCache,
}

/// The [`AngleTerms`] of the last two angles evaluated: in the angle domain
/// they depend on the independent variable θ only, and RK4 evaluates θ_n,
/// θ_n + h/2 twice and θ_n + h, the next step's θ_n — two new angles per step
/// instead of four (the RHS's sin/cos were ≈ 30 % of a closed-loop run).
#[derive(Clone, Debug)]
struct AngleCache {
    /// (θ bits, segment) of each slot; segment `i64::MIN` marks an empty slot.
    keys: [Cell<(u64, i64)>; 2],
    terms: [Cell<AngleTerms>; 2],
    /// The slot the next miss overwrites (the older one).
    next: Cell<usize>,
}

impl Default for AngleCache {
    fn default() -> Self {
        let empty = AngleTerms {
            f: f64::NAN,
            f_theta: f64::NAN,
            sin_theta: f64::NAN,
            cos_theta: f64::NAN,
        };
        Self {
            keys: [Cell::new((0, i64::MIN)), Cell::new((0, i64::MIN))],
            terms: [Cell::new(empty), Cell::new(empty)],
            next: Cell::new(0),
        }
    }
}

impl AngleCache {
    #[inline(always)]
    fn get(&self, theta: f64, seg: i64) -> AngleTerms {
        let key = (theta.to_bits(), seg);
        if self.keys[0].get() == key {
            return self.terms[0].get();
        }
        if self.keys[1].get() == key {
            return self.terms[1].get();
        }
        let a = AngleTerms::new(theta, seg);
        let k = self.next.get();
        if let (Some(slot), Some(terms)) = (self.keys.get(k), self.terms.get(k)) {
            slot.set(key);
            terms.set(a);
        }
        self.next.set(1 - k);
        a
    }
}

impl<P: InputProfile> AngleSys<'_, P> {
    /// `dz = dz/dθ` with `z = [t, ω, i_a]` (Eq. 162).
    #[inline(always)]
    fn rhs(&self, theta: f64, z: &[f64], dz: &mut [f64]) {
        let Some(([t, om, ia], dz)) = state(z, dz) else {
            return;
        };
        let (v_m, t_u) = self.prof.at(*t);
        let [_, d_om, d_ia] = self.plant.derivatives_with(
            &self.cache.get(theta, self.seg),
            &[theta, *om, *ia],
            &Inputs {
                r: self.r,
                v_m,
                t_u,
            },
        );
        let inv = 1.0 / om;
        *dz = [inv, d_om * inv, d_ia * inv];
    }
}

/// The plant state and the machinery to move it forward to a target angle.
#[derive(Clone, Debug)]
pub struct PlantIntegrator {
    /// The plant.
    pub plant: Plant,
    /// Integration method.
    pub method: Method,
    /// Time \[s\].
    pub t: f64,
    /// `[θ, ω, i_a]`.
    pub y: [f64; DIM],
    /// Speed above which the angle domain is used \[rad/s\].
    pub omega_handover: f64,
    /// Counters.
    pub stats: Stats,
    h_time: f64,
    h_angle: f64,
    /// F at the end of the last angle step (first-same-as-last), with the
    /// segment, r and inputs it was evaluated with: reused as the next
    /// step's first stage when all of them are unchanged.
    fsal: Option<Fsal>,
    /// θ-only terms of the last angles evaluated (angle domain).
    angle_cache: AngleCache,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Fsal {
    theta: f64,
    z: [f64; DIM],
    seg: i64,
    r: f64,
    inputs: (f64, f64),
    k: [f64; DIM],
}

/// The step actually taken when x advances to fl(x + h): integrating h but
/// storing fl(x + h) would drift x against the solution by up to ½ ulp(x) per
/// step (1e-10 rad over 10⁶ RK4 steps at θ ≈ 100).
#[inline]
fn representable_step(x: f64, h: f64) -> f64 {
    (x + h) - x
}

/// Step budget of one [`PlantIntegrator::advance`] call: the closed loop
/// advances one pulse (or sensor sample) at a time, normally in 1–10 steps.
pub const MAX_STEPS_PER_ADVANCE: u64 = 2_000_000;

/// Relative slack used to decide that θ sits on a corner already.
const CORNER_EPS: f64 = 1e-12;

impl PlantIntegrator {
    /// Start at time `t`, angle θ, speed ω (rad/s) and armature current
    /// `i_a` (ignored when L_a = 0).
    pub fn new(plant: Plant, method: Method, t: f64, theta: f64, omega: f64, i_a: f64) -> Self {
        let i_a = if plant.has_inductance() { i_a } else { 0.0 };
        Self {
            plant,
            method,
            t,
            y: [theta, omega, i_a],
            omega_handover: 0.5,
            stats: Stats::default(),
            h_time: 0.0,
            h_angle: 0.0,
            fsal: None,
            angle_cache: AngleCache::default(),
        }
    }

    /// θ \[rad\].
    pub fn theta(&self) -> f64 {
        self.y[0]
    }

    /// ω \[rad/s\].
    pub fn omega(&self) -> f64 {
        self.y[1]
    }

    /// Integrate with eccentricity `r` and inputs `prof` until θ = `theta_target`
    /// (exactly) or, in the time domain, until t = `t_max`.
    ///
    /// # Errors
    /// Step-size underflow or a non-finite state.
    pub fn advance<P: InputProfile>(
        &mut self,
        prof: &P,
        r: f64,
        theta_target: f64,
        t_max: f64,
    ) -> Result<Reached, SimError> {
        for _ in 0..MAX_STEPS_PER_ADVANCE {
            if self.y[0] >= theta_target {
                return Ok(Reached::Angle);
            }
            if self.t >= t_max {
                return Ok(Reached::Time);
            }
            if self.y[1] > self.omega_handover {
                self.angle_step(prof, r, theta_target)?;
            } else {
                self.time_step(prof, r, theta_target, t_max)?;
            }
            if !(self.y.iter().all(|v| v.is_finite()) && self.t.is_finite()) {
                return Err(SimError::NotFinite {
                    t: self.t,
                    state: self.y,
                });
            }
        }
        Err(SimError::TooManySteps {
            t: self.t,
            theta: self.y[0],
            omega: self.y[1],
            steps: MAX_STEPS_PER_ADVANCE,
        })
    }

    /// Segment index and its forward corner for a step starting at θ going forward.
    fn forward_segment(theta: f64) -> (i64, f64) {
        let mut k = crate::plant::segment_of(theta);
        let mut end = segment_end(k);
        if end - theta <= CORNER_EPS * theta.abs().max(1.0) {
            k += 1;
            end = segment_end(k);
        }
        (k, end)
    }

    fn angle_step<P: InputProfile>(
        &mut self,
        prof: &P,
        r: f64,
        theta_target: f64,
    ) -> Result<(), SimError> {
        let theta = self.y[0];
        let (seg, corner) = Self::forward_segment(theta);
        let bp = corner.min(theta_target);
        let sys = AngleSys {
            plant: &self.plant,
            seg,
            r,
            prof,
            cache: &self.angle_cache,
        };
        let z = [self.t, self.y[1], self.y[2]];
        match self.method {
            Method::Rk4 { dtheta, .. } => {
                let h = representable_step(theta, dtheta.min(bp - theta));
                let mut z1 = z;
                ExplicitRk::<4, [f64; DIM]>::new(&RK4).step(
                    &mut |x, y, dy| sys.rhs(x, y, dy),
                    theta,
                    h,
                    &mut z1,
                );
                self.commit_angle(if h == bp - theta { bp } else { theta + h }, z1);
                Ok(())
            }
            Method::Dp5(tol) => {
                let mut rk = Dp5::new(&DP5);
                let inputs = prof.at(z[0]);
                let k1 = match self.fsal {
                    Some(c)
                        if c.theta == theta
                            && c.z == z
                            && c.seg == seg
                            && c.r == r
                            && c.inputs == inputs =>
                    {
                        c.k
                    }
                    _ => {
                        let mut k = [0.0; DIM];
                        sys.rhs(theta, &z, &mut k);
                        k
                    }
                };
                if self.h_angle <= 0.0 {
                    self.h_angle =
                        rk.initial_step(&mut |x, y, dy| sys.rhs(x, y, dy), theta, &z, &k1, &tol);
                }
                loop {
                    let lands = self.h_angle >= bp - theta;
                    let h = if lands {
                        bp - theta
                    } else {
                        representable_step(theta, self.h_angle)
                    };
                    let mut z1 = [0.0; DIM];
                    let err = rk.try_step(
                        &mut |x, y, dy| sys.rhs(x, y, dy),
                        theta,
                        &z,
                        Some(&k1),
                        h,
                        &tol,
                        &mut z1,
                    );
                    if err <= 1.0 {
                        // A landing step that was cut short says nothing about the
                        // next h, except that it may grow; the factor is ≤ 5, so
                        // skip its powf when even 5h would not exceed h_angle.
                        if !lands || 5.0 * h > self.h_angle {
                            let hn = h * step_factor(err, DP5.order);
                            if !lands || hn > self.h_angle {
                                self.h_angle = hn;
                            }
                        }
                        let theta1 = if lands { bp } else { theta + h };
                        self.commit_angle(theta1, z1);
                        let mut k = [0.0; DIM];
                        k.copy_from_slice(rk.last_stage());
                        self.fsal = Some(Fsal {
                            theta: theta1,
                            z: z1,
                            seg,
                            r,
                            inputs: prof.at(z1[0]),
                            k,
                        });
                        return Ok(());
                    }
                    self.stats.rejected += 1;
                    self.h_angle = h * step_factor(err, DP5.order);
                    if self.h_angle < 1e-14 * theta.abs().max(1.0) {
                        return Err(self.underflow(self.h_angle));
                    }
                }
            }
        }
    }

    fn commit_angle(&mut self, theta: f64, z: [f64; DIM]) {
        self.y = [theta, z[1], z[2]];
        self.t = z[0];
        self.stats.angle_steps += 1;
    }

    fn underflow(&self, h: f64) -> SimError {
        SimError::StepUnderflow {
            t: self.t,
            theta: self.y[0],
            omega: self.y[1],
            h,
        }
    }

    fn time_step<P: InputProfile>(
        &mut self,
        prof: &P,
        r: f64,
        theta_target: f64,
        t_max: f64,
    ) -> Result<(), SimError> {
        let tol = match self.method {
            Method::Dp5(tol) => tol,
            Method::Rk4 { startup, .. } => startup,
        };
        let theta = self.y[0];
        let forward = self.y[1] >= 0.0;
        let (seg, hi) = Self::forward_segment(theta);
        let hi = hi.min(theta_target);
        // going backward: the segment that ends below θ
        let (seg, lo) = if forward {
            (seg, f64::NEG_INFINITY)
        } else {
            let mut k = crate::plant::segment_of(theta);
            let start = segment_end(k - 1);
            if theta - start <= CORNER_EPS * theta.abs().max(1.0) {
                k -= 1;
            }
            (k, segment_end(k - 1))
        };
        let sys = TimeSys {
            plant: &self.plant,
            seg,
            r,
            prof,
        };
        let mut rk = Dp5::new(&DP5);
        let mut k1 = [0.0; DIM];
        sys.rhs(self.t, &self.y, &mut k1);
        if self.h_time <= 0.0 {
            self.h_time = rk
                .initial_step(
                    &mut |x, y, dy| sys.rhs(x, y, dy),
                    self.t,
                    &self.y,
                    &k1,
                    &tol,
                )
                .min(1e-3);
        }
        loop {
            let lands = self.h_time >= t_max - self.t;
            let h = if lands {
                t_max - self.t
            } else {
                representable_step(self.t, self.h_time)
            };
            let mut y1 = [0.0; DIM];
            let err = rk.try_step(
                &mut |x, y, dy| sys.rhs(x, y, dy),
                self.t,
                &self.y,
                Some(&k1),
                h,
                &tol,
                &mut y1,
            );
            let fac = step_factor(err, DP5.order);
            if err > 1.0 {
                self.stats.rejected += 1;
                self.h_time = h * fac;
                if self.h_time < 1e-14 * self.t.abs().max(1.0) {
                    return Err(self.underflow(self.h_time));
                }
                continue;
            }
            if !lands || h * fac > self.h_time {
                self.h_time = h * fac;
            }
            let th1 = y1[0];
            let boundary = if th1 >= hi {
                Some(hi)
            } else if th1 <= lo {
                Some(lo)
            } else {
                None
            };
            match boundary {
                None => {
                    self.t += h;
                    self.y = y1;
                }
                Some(b) => {
                    // crossing time on the dense output (bisection: θ is monotone
                    // within a step because ω keeps its sign), then retake the step
                    let (mut a, mut c) = (0.0, 1.0);
                    let mut at = [0.0; DIM];
                    for _ in 0..60 {
                        let m = 0.5 * (a + c);
                        rk.dense(&self.y, &y1, h, m, &mut at);
                        let thm = at[0];
                        if (thm - b) * (th1 - b) > 0.0 {
                            c = m;
                        } else {
                            a = m;
                        }
                    }
                    let hs = c * h;
                    let mut y2 = [0.0; DIM];
                    rk.try_step(
                        &mut |x, y, dy| sys.rhs(x, y, dy),
                        self.t,
                        &self.y,
                        Some(&k1),
                        hs,
                        &tol,
                        &mut y2,
                    );
                    self.t += hs;
                    self.y = y2;
                    self.y[0] = b;
                }
            }
            // the brake and the one-way clutches cannot drive the motor backwards
            if self.y[1] < 0.0 {
                self.y[1] = 0.0;
            }
            self.stats.time_steps += 1;
            return Ok(());
        }
    }
}

#[cfg(test)]
#[path = "integrate_tests.rs"]
mod tests;
