//! Shared test models: a slow, obvious f64 reference of the controller's
//! laws and a first-order surrogate plant in the angle domain.
#![allow(dead_code, clippy::indexing_slicing, clippy::unwrap_used)]

use ivt_ctrl::OpenLoopCoeffs;
use std::collections::VecDeque;
use std::f64::consts::TAU;

/// f64 reference of Eq. 160 (same clamping rules as the controller).
pub fn u_ol_f64(c: &OpenLoopCoeffs, v_m: f64, t_u: f64) -> f64 {
    let v = v_m.clamp(f64::from(c.v_m_range[0]), f64::from(c.v_m_range[1]));
    let t = t_u.clamp(f64::from(c.t_u_range[0]), f64::from(c.t_u_range[1]));
    let r_max = f64::from(c.r_max);
    let f_b =
        f64::from(c.boundary[0]) * v + f64::from(c.boundary[1]) * t + f64::from(c.boundary[2]);
    if f_b > 0.0 {
        return r_max;
    }
    let mut r = 0.0;
    for (i, row) in c.poly.iter().enumerate() {
        for (j, a) in row.iter().enumerate() {
            r += f64::from(*a) * v.powi(i as i32) * t.powi(j as i32);
        }
    }
    r.clamp(0.0, r_max)
}

/// Which law the reference runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RefLaw {
    /// Eq. 180.
    Delay { k: f64, k2: f64 },
    /// Eq. 181.
    NoDelay { k: f64, k2: f64 },
}

/// The obvious f64 controller: full timestamp history, plain sums.
pub struct Reference {
    pub ppr: usize,
    pub f_timer: f64,
    pub omega0: f64,
    pub law: RefLaw,
    pub r_max: f64,
    pub r_ol: f64,
    pub r_d: f64,
    hist: VecDeque<u32>,
    omega_prev: f64,
}

/// One output of the reference.
#[derive(Clone, Copy, Debug, Default)]
pub struct RefOut {
    pub omega: f64,
    pub omega_a: f64,
    pub omega_t: f64,
    pub r: f64,
    pub ready: bool,
}

impl Reference {
    pub fn new(ppr: usize, f_timer: f64, omega0: f64, law: RefLaw, r_max: f64) -> Self {
        Self {
            ppr,
            f_timer,
            omega0,
            law,
            r_max,
            r_ol: 0.0,
            r_d: 0.0,
            hist: VecDeque::new(),
            omega_prev: 0.0,
        }
    }

    fn dt(a: u32, b: u32) -> f64 {
        f64::from(a.wrapping_sub(b))
    }

    pub fn on_pulse(&mut self, ticks: u32) -> RefOut {
        self.hist.push_back(ticks);
        if self.hist.len() > self.ppr + 2 {
            self.hist.pop_front();
        }
        let n = self.hist.len();
        let dtheta = TAU / self.ppr as f64;
        let mut out = RefOut::default();
        if n >= 2 {
            out.omega = dtheta * self.f_timer / Self::dt(self.hist[n - 1], self.hist[n - 2]);
        }
        if n == self.ppr + 2 {
            out.omega_a = TAU * self.f_timer / Self::dt(self.hist[n - 1], self.hist[1]);
            out.omega_t = dtheta * self.f_timer / Self::dt(self.hist[1], self.hist[0]);
            out.ready = true;
            let inc = match self.law {
                RefLaw::Delay { k, k2 } => {
                    (k * (out.omega_a - self.omega0) + k2 * (out.omega - out.omega_t)) * dtheta
                }
                RefLaw::NoDelay { k, k2 } => {
                    k * (out.omega - self.omega0) * dtheta + k2 * (out.omega - self.omega_prev)
                }
            };
            self.r_d += inc;
        }
        self.omega_prev = out.omega;
        // Anti-windup: clamp the integrator so that r stays in [0, r_max].
        self.r_d = self.r_d.clamp(-self.r_ol, self.r_max - self.r_ol);
        out.r = (self.r_ol + self.r_d).clamp(0.0, self.r_max);
        out
    }
}

/// First-order surrogate of the averaged IVT (the structure of Eq. 186–187):
/// `τ dω̄/dt = g_v V_m − c T_U r − ω̄`, with the instantaneous speed
/// `ω(θ) = ω̄ (1 + a sin 4θ)` carrying the period-π/2 ripple of the
/// noncircular gears. Integrated in θ, one encoder pulse per step.
pub struct Surrogate {
    pub tau: f64,
    pub g_v: f64,
    pub c: f64,
    pub ripple: f64,
    pub omega_bar: f64,
    pub theta: f64,
    pub t: f64,
}

impl Surrogate {
    /// Defaults: τ = 0.05 s, g_v = 1.5 rad/s/V, c = 25 rad/s/(N·m·m), 2 % ripple.
    /// At V_m = 8 V, T_U = 8 N·m, ω0 = 100 rpm needs r = (12 − 10.472)/200 = 7.64 mm.
    pub fn new(omega_bar: f64) -> Self {
        Self {
            tau: 0.05,
            g_v: 1.5,
            c: 25.0,
            ripple: 0.02,
            omega_bar,
            theta: 0.0,
            t: 0.0,
        }
    }

    /// Advance by dθ with eccentricity r; returns the time of arrival \[s\].
    pub fn advance(&mut self, dtheta: f64, r: f64, v_m: f64, t_u: f64) -> f64 {
        let mid = self.theta + 0.5 * dtheta;
        let omega = (self.omega_bar * (1.0 + self.ripple * (4.0 * mid).sin())).max(1e-3);
        let dt = dtheta / omega;
        let w_ss = self.g_v * v_m - self.c * t_u * r;
        self.omega_bar = w_ss + (self.omega_bar - w_ss) * (-dt / self.tau).exp();
        self.theta += dtheta;
        self.t += dt;
        self.t
    }
}

/// Timer count at time t \[s\] (truncation, as a capture unit latches it),
/// plus an offset, modulo 2³².
pub fn ticks_at(t: f64, f_timer: f64, offset: u64) -> u32 {
    (((t * f_timer).floor() as u64).wrapping_add(offset) & 0xFFFF_FFFF) as u32
}
