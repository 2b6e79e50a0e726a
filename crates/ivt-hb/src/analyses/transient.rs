//! Limit cycles from a state (issue 27, item 4): the transient from a given
//! state `(x₀, ẋ₀)` of an autonomous problem is integrated (Dormand–Prince 5(4)
//! of [`ivt_num`], error-controlled) until it has settled onto an attractor, the
//! settled orbit is sampled over one period and Fourier-analysed (Eq. 62–65), and
//! [`limit_cycle`] refines it by harmonic balance with ω unknown.
//!
//! Settling is seen on the Poincaré section `ẋ₀ = 0, ẍ₀ < 0` (the maxima of DOF
//! 0): crossing `i` is the state at the section, and the transient has settled
//! when crossing `i` returns to crossing `i − k` within `settle` relative, for the
//! smallest `k ≤ max_returns` (an orbit may cross the section `k` times per
//! period). The period is then `t_i − t_{i−k}`. A start in the basin of the
//! equilibrium (a crossing below max(100·tol, 1e-8) of the largest) ends with
//! [`HbError::Equilibrium`], one that never settles with
//! [`HbError::Transient`]; no start needs Fourier coefficients or a frequency.

use crate::branches::autonomous::{limit_cycle, LimitCycle};
use crate::error::HbError;
use crate::orbit::ihb::HbOptions;
use crate::problem::ode::first_order;
use crate::problem::PeriodicProblem;
use crate::Aft;
use ivt_num::rk::step_factor;
use ivt_num::{ExplicitRk, Tolerance, DP5};
use std::f64::consts::PI;

/// Limits and tolerances of the transient.
#[derive(Debug, Clone, PartialEq)]
pub struct TransientOptions {
    /// Relative (and, times the start's size, absolute) error tolerance of the
    /// integration (default 1e-10).
    pub tol: f64,
    /// Relative distance between two section crossings one period apart that
    /// counts as settled (default 1e-6: Newton's basin, not the answer).
    pub settle: f64,
    /// Most section crossings per period looked for (default 8).
    pub max_returns: usize,
    /// Most section crossings integrated before giving up (default 5000).
    pub max_crossings: usize,
    /// Most accepted integration steps before giving up (default 2 000 000).
    pub max_steps: usize,
}

impl Default for TransientOptions {
    fn default() -> Self {
        Self {
            tol: 1e-10,
            settle: 1e-6,
            max_returns: 8,
            max_crossings: 5000,
            max_steps: 2_000_000,
        }
    }
}

/// A transient settled onto a periodic attractor.
#[derive(Debug, Clone, PartialEq)]
pub struct Settled {
    /// State `[x, ẋ]` at the last section crossing (a maximum of DOF 0).
    pub state: Vec<f64>,
    /// Period from the section returns.
    pub period: f64,
    /// Time integrated until settled.
    pub time: f64,
    /// Section crossings per period.
    pub returns: usize,
}

/// The limit cycle reached from `state = [x₀…, ẋ₀…]` (`2·n_dof`) of the
/// autonomous `problem`: [`settle`], then [`limit_cycle`] from the settled
/// orbit's Fourier coefficients with `hb` and `stability_steps`.
///
/// # Errors
/// As [`settle`] and [`limit_cycle`].
pub fn limit_cycle_from_state<P: PeriodicProblem>(
    problem: &P,
    hb: &HbOptions,
    state: &[f64],
    opts: &TransientOptions,
    stability_steps: usize,
) -> Result<LimitCycle, HbError> {
    let settled = settle(problem, state, opts)?;
    let guess = fourier_start(problem, hb, &settled, opts)?;
    limit_cycle(
        problem,
        hb,
        2.0 * PI / settled.period,
        &guess,
        stability_steps,
    )
}

/// Integrates the transient of the autonomous `problem` from `state` until it
/// settles (see the module docs).
///
/// # Errors
/// [`HbError::InvalidInput`] for a state of the wrong size, non-finite or all
/// zero, a singular mass matrix or a non-zero excitation;
/// [`HbError::Equilibrium`] when the transient comes to rest;
/// [`HbError::Transient`] when it leaves the finite numbers or does not settle
/// within the limits of `opts`.
pub fn settle<P: PeriodicProblem>(
    problem: &P,
    state: &[f64],
    opts: &TransientOptions,
) -> Result<Settled, HbError> {
    let scale = validate(problem, state, opts)?;
    let mut flow = Flow::new(problem, state, opts.tol, scale);
    let rest = 1e-12 * norm_inf(&flow.k1).max(f64::MIN_POSITIVE);
    let mut crossings: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut section = vec![0.0; state.len()];
    let v0 = problem.n_dof();
    while crossings.len() < opts.max_crossings {
        if flow.steps >= opts.max_steps {
            return Err(HbError::Transient {
                time: flow.t,
                reason: "no periodic attractor within the step limit",
            });
        }
        // The first velocity (validated: the state holds 2·n_dof values).
        let velocity = |y: &[f64]| y.get(v0).copied().unwrap_or(f64::NAN);
        let before = velocity(&flow.y);
        flow.step()?;
        if norm_inf(&flow.k1) <= rest {
            return Err(HbError::Equilibrium);
        }
        if !(before > 0.0 && velocity(&flow.y) <= 0.0) {
            continue;
        }
        let s = flow.root(v0);
        flow.dense(s, &mut section);
        let t = flow.t - flow.h_last * (1.0 - s);
        let size = norm_inf(&section);
        let largest = crossings
            .iter()
            .map(|c| norm_inf(&c.1))
            .fold(size, f64::max);
        // At rest below the integration's own noise: an error-controlled
        // solution that decays to the absolute tolerance (tol × the start's
        // size) stays there, so the ratio is at least 100·tol.
        if size <= (100.0 * opts.tol).max(1e-8) * largest {
            return Err(HbError::Equilibrium);
        }
        for (k, (tk, sk)) in crossings.iter().rev().take(opts.max_returns).enumerate() {
            let dist = section
                .iter()
                .zip(sk)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
            if dist <= opts.settle * size {
                return Ok(Settled {
                    state: section,
                    period: t - tk,
                    time: t,
                    returns: k + 1,
                });
            }
        }
        crossings.push((t, section.clone()));
    }
    Err(HbError::Transient {
        time: flow.t,
        reason: "the transient did not settle within the crossing limit",
    })
}

/// Fourier coefficients (`n_dof` blocks `[a0, a.., b..]`, `hb.harmonics`) of the
/// settled orbit, sampled at the `2N` AFT points of one period from its
/// section state (dense output of the same integration).
///
/// # Errors
/// [`HbError::InvalidInput`] or [`HbError::Transient`] as [`settle`];
/// the AFT's size errors.
pub fn fourier_start<P: PeriodicProblem>(
    problem: &P,
    hb: &HbOptions,
    settled: &Settled,
    opts: &TransientOptions,
) -> Result<Vec<f64>, HbError> {
    let scale = validate(problem, &settled.state, opts)?;
    let mut aft = Aft::new(hb.harmonics, hb.n_half)?;
    let (nd, ns, l) = (problem.n_dof(), aft.n_samples(), aft.coeff_len());
    let mut samples = vec![0.0; ns * nd]; // DOF-major: DOF d's samples at d·ns
    let mut flow = Flow::new(problem, &settled.state, opts.tol, scale);
    let mut y = vec![0.0; settled.state.len()];
    let mut j = 0;
    while j < ns {
        let t_j = settled.period * j as f64 / ns as f64;
        if t_j > flow.t {
            flow.step()?;
            continue;
        }
        let s = 1.0 - (flow.t - t_j) / flow.h_last.max(f64::MIN_POSITIVE);
        if j == 0 {
            y.copy_from_slice(&settled.state);
        } else {
            flow.dense(s.clamp(0.0, 1.0), &mut y);
        }
        for (sample, yd) in samples.iter_mut().skip(j).step_by(ns).zip(&y) {
            *sample = *yd;
        }
        j += 1;
    }
    let mut guess = vec![0.0; nd * l];
    for (dof_samples, dof_guess) in samples.chunks_exact(ns).zip(guess.chunks_exact_mut(l)) {
        aft.analyze(dof_samples, dof_guess);
    }
    // Shift the time origin to where the phase condition b₁ = 0 of DOF 0
    // holds (with a₁ > 0): the section (a maximum) is there only for a pure
    // cosine, and Newton should not have to turn the whole orbit.
    let n = hb.harmonics;
    if let (Some(&a1), Some(&b1)) = (guess.get(1), guess.get(n + 1)) {
        let phi = b1.atan2(a1);
        for block in guess.chunks_exact_mut(l) {
            crate::orbit::aft::shift_time(block, phi);
        }
    }
    Ok(guess)
}

/// Checks the state and the problem; returns the state's size `‖state‖∞`.
fn validate<P: PeriodicProblem>(
    problem: &P,
    state: &[f64],
    opts: &TransientOptions,
) -> Result<f64, HbError> {
    let nd = problem.n_dof();
    let scale = norm_inf(state);
    if state.len() != 2 * nd || !state.iter().all(|v| v.is_finite()) || scale == 0.0 {
        return Err(HbError::InvalidInput(format!(
            "the start state [x, v] must have {} finite entries, not all zero",
            2 * nd
        )));
    }
    if !(opts.tol > 0.0 && opts.tol < 1.0 && opts.settle > 0.0 && opts.max_returns > 0) {
        return Err(HbError::InvalidInput(
            "transient options: 0 < tol < 1, settle > 0, max_returns ≥ 1".into(),
        ));
    }
    if ivt_num::lu::inverse(problem.mass(), nd).is_none() {
        return Err(HbError::InvalidInput(
            "the mass matrix must be invertible to integrate the transient".into(),
        ));
    }
    let mut f = vec![0.0; nd];
    for i in 0..16 {
        problem.excitation(2.0 * PI * i as f64 / 16.0, &mut f);
        if f.iter().any(|v| *v != 0.0) {
            return Err(HbError::InvalidInput(
                "a limit cycle needs an autonomous problem (zero excitation)".into(),
            ));
        }
    }
    Ok(scale)
}

/// `max_i |u_i|`.
fn norm_inf(u: &[f64]) -> f64 {
    u.iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

/// The error-controlled DP5 integration of the first-order form of a problem,
/// one accepted step at a time, with the dense output of the last step.
struct Flow<R> {
    rhs: R,
    rk: ExplicitRk<7, Vec<f64>>,
    tol: Tolerance,
    /// Time at the end of the last accepted step.
    t: f64,
    /// State at `t`, at the start of the last step, and the trial state.
    y: Vec<f64>,
    y_prev: Vec<f64>,
    y_trial: Vec<f64>,
    /// F(t, y).
    k1: Vec<f64>,
    /// Next step size and that of the last accepted step.
    h: f64,
    h_last: f64,
    steps: usize,
}

/// The right-hand side `F(t, y)` of a first-order form, borrowed from its problem.
type Rhs<'p> = Box<dyn FnMut(f64, &[f64], &mut [f64]) + 'p>;

impl<'p> Flow<Rhs<'p>> {
    /// The flow of `problem` from `state` (mass checked invertible) with the
    /// relative tolerance `tol` and the absolute `tol·scale`.
    fn new<P: PeriodicProblem>(problem: &'p P, state: &[f64], tol: f64, scale: f64) -> Self {
        let mut rhs: Rhs<'p> = Box::new(first_order(problem, 1.0));
        let tol = Tolerance {
            rtol: tol,
            atol: tol * scale,
        };
        let dim = state.len();
        let mut rk = ExplicitRk::with_dim(&DP5, dim);
        let mut k1 = vec![0.0; dim];
        rhs(0.0, state, &mut k1);
        let h = rk.initial_step(&mut rhs, 0.0, state, &k1, &tol);
        Self {
            rhs,
            rk,
            tol,
            t: 0.0,
            y: state.to_vec(),
            y_prev: state.to_vec(),
            y_trial: vec![0.0; dim],
            k1,
            h,
            h_last: 0.0,
            steps: 0,
        }
    }

    /// One accepted step (rejected ones retried with a smaller step).
    fn step(&mut self) -> Result<(), HbError> {
        loop {
            let err = self.rk.try_step(
                &mut self.rhs,
                self.t,
                &self.y,
                Some(&self.k1),
                self.h,
                &self.tol,
                &mut self.y_trial,
            );
            let h = self.h;
            self.h *= step_factor(err, DP5.order);
            if !(self.h.is_finite() && self.h > 1e-14 * self.t.abs().max(1e-300)) {
                return Err(HbError::Transient {
                    time: self.t,
                    reason: "the integration step collapsed (the state left the finite numbers)",
                });
            }
            if err <= 1.0 {
                std::mem::swap(&mut self.y_prev, &mut self.y);
                std::mem::swap(&mut self.y, &mut self.y_trial);
                self.k1.copy_from_slice(self.rk.last_stage());
                self.t += h;
                self.h_last = h;
                self.steps += 1;
                return Ok(());
            }
        }
    }

    /// The dense output of the last step at its fraction `s ∈ [0, 1]`.
    fn dense(&self, s: f64, out: &mut [f64]) {
        self.rk.dense(&self.y_prev, &self.y, self.h_last, s, out);
    }

    /// The fraction `s` of the last step where component `i` of the dense
    /// output crosses zero (it changes sign over the step): bisection to
    /// machine precision.
    fn root(&self, i: usize) -> f64 {
        let mut u = vec![0.0; self.y.len()];
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            self.dense(mid, &mut u);
            if u.get(i).is_some_and(|&v| v > 0.0) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }
}
