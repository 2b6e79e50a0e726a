//! The "traditional route": Galerkin modal ODEs of Eq. 103 derived in closed
//! form (Eq. 109–110), independent of the DST/FFT machinery of [`super::StringHb`].
//!
//! `ω² q̈_n + ω c_d q̇_n + n²π² q_n − ℒ_n(q) − y0 δ_{n1} cos t = 0` with
//! `ℒ_n = −2 k_d π⁴ Σ_{abc} a b c² q_a q_b q_c I(n,a,b,c)` and
//! `I = ∫₀¹ sin nπx sin cπx cos aπx cos bπx dx`, evaluated by product-to-sum
//! identities. Used as the reference in tests (time integration) and, as a
//! [`PeriodicProblem`] of the general engine (`M = I`, `C = c_d I`,
//! `K = diag(n²π²)`, `g = −ℒ(q)`, `f = y0 cos θ` on mode 1), for the
//! "traditional route": the same curve by the modified IHB + continuation.

use ivt_num::{ExplicitRk, RK4};
use std::f64::consts::PI;

use super::StringParams;
use ivt_hb::problem::{displacement_jacobian, PeriodicProblem};

/// The cubic Galerkin model of the fixed–fixed string with `N` sine modes.
#[derive(Clone, Debug)]
pub struct ModalString {
    /// Parameters (`modes`, `kd`, `cd`, `y0` are used).
    pub params: StringParams,
    /// Nonzero terms `(n, a, b, c, coefficient)` of `ℒ_n = Σ coef q_a q_b q_c`.
    terms: Vec<(usize, usize, usize, usize, f64)>,
    /// `M = I`, `C = c_d I`, `K = diag(n²π²)` (row-major `N × N`) for the engine.
    mass: Vec<f64>,
    damping: Vec<f64>,
    stiffness: Vec<f64>,
}

/// `∫₀¹ cos pπx cos rπx dx` for integers `p`, `r`.
fn cos_cos(p: i64, r: i64) -> f64 {
    0.5 * (f64::from(u8::from(p == r)) + f64::from(u8::from(p == -r)))
}

impl ModalString {
    /// Build the cubic tensor of Eq. 110 for `params.modes` modes.
    pub fn new(params: StringParams) -> Self {
        let n = params.modes as i64;
        let mut terms = Vec::new();
        for nn in 1..=n {
            for a in 1..=n {
                for b in 1..=n {
                    for c in 1..=n {
                        // sin n sin c = ½[cos(n−c) − cos(n+c)], cos a cos b = ½[cos(a−b) + cos(a+b)].
                        let mut i = 0.0;
                        for (u, su) in [(nn - c, 1.0), (nn + c, -1.0)] {
                            for v in [a - b, a + b] {
                                i += 0.25 * su * cos_cos(u, v);
                            }
                        }
                        if i != 0.0 {
                            let coef = -2.0 * params.kd * PI.powi(4) * (a * b * c * c) as f64 * i;
                            terms.push((
                                (nn - 1) as usize,
                                (a - 1) as usize,
                                (b - 1) as usize,
                                (c - 1) as usize,
                                coef,
                            ));
                        }
                    }
                }
            }
        }
        let nm = params.modes;
        let diag = |f: &dyn Fn(usize) -> f64| {
            let mut m = vec![0.0; nm * nm];
            for (i, x) in m.iter_mut().step_by(nm + 1).enumerate() {
                *x = f(i);
            }
            m
        };
        Self {
            mass: diag(&|_| 1.0),
            damping: diag(&|_| params.cd),
            stiffness: diag(&|i| ((i + 1) as f64 * PI).powi(2)),
            params,
            terms,
        }
    }

    /// The engine's coefficient vector (`N` blocks `[a0, a1..aM, b1..bM]` with
    /// `x = a0/2 + Σ a_k cos kτ + b_k sin kτ`) of an STHB solution `a`
    /// (harmonic-major, [`super::StringHb::index`], constant term without the ½).
    /// NaN if `a` does not hold `modes·(2·harmonics + 1)` values.
    pub fn engine_coeffs(&self, a: &[f64]) -> Vec<f64> {
        self.convert(a, true)
    }

    /// Inverse of [`Self::engine_coeffs`] (NaN if `q` does not hold
    /// `modes·(2·harmonics + 1)` values).
    pub fn sthb_coeffs(&self, q: &[f64]) -> Vec<f64> {
        self.convert(q, false)
    }

    /// [`Self::engine_coeffs`] of `from` (`to_engine`) or its inverse: entry
    /// `(h, d)` of the harmonic-major STHB layout (row `h` holds harmonic row
    /// `h` of every mode `d`) is slot [`engine_slot`] of DOF block `d`.
    fn convert(&self, from: &[f64], to_engine: bool) -> Vec<f64> {
        let (n, m) = (self.params.modes, self.params.harmonics);
        let l = 2 * m + 1;
        let mut to = vec![f64::NAN; n * l];
        if n == 0 || from.len() != n * l {
            return to;
        }
        for h in 0..l {
            let (slot, scale) = engine_slot(h, m);
            for d in 0..n {
                let (sthb, engine) = (h * n + d, d * l + slot);
                let (src, dst) = if to_engine {
                    (sthb, engine)
                } else {
                    (engine, sthb)
                };
                if let (Some(&x), Some(y)) = (from.get(src), to.get_mut(dst)) {
                    *y = if to_engine { scale * x } else { x / scale };
                }
            }
        }
        to
    }

    /// `ℒ(q)` into `out` (NaN if `q` or `out` is not `N` long).
    pub fn nonlinear(&self, q: &[f64], out: &mut [f64]) {
        let n = self.params.modes;
        if q.len() != n || out.len() != n {
            return out.fill(f64::NAN);
        }
        out.fill(0.0);
        // Every index of `terms` is < N (built in `new`).
        let at = |i: usize| q.get(i).copied().unwrap_or(f64::NAN);
        for &(r, a, b, c, k) in &self.terms {
            if let Some(o) = out.get_mut(r) {
                *o += k * at(a) * at(b) * at(c);
            }
        }
    }

    /// `∂ℒ/∂q` (row-major `N × N`) into `out` (NaN if `q` is not `N` long or
    /// `out` not `N²`).
    pub fn nonlinear_jacobian(&self, q: &[f64], out: &mut [f64]) {
        let n = self.params.modes;
        if q.len() != n || out.len() != n * n {
            return out.fill(f64::NAN);
        }
        out.fill(0.0);
        let at = |i: usize| q.get(i).copied().unwrap_or(f64::NAN);
        for &(r, a, b, c, k) in &self.terms {
            for (col, x, y) in [(a, b, c), (b, a, c), (c, a, b)] {
                if let Some(o) = out.get_mut(r * n + col) {
                    *o += k * at(x) * at(y);
                }
            }
        }
    }

    /// State derivative of `y = (q, q̇)` at normalized time `t` for frequency `omega`.
    /// NaN if `y`, `dy` are not `2N` long or `scratch` is shorter than `N`.
    pub fn rhs(&self, omega: f64, t: f64, y: &[f64], dy: &mut [f64], scratch: &mut [f64]) {
        let n = self.params.modes;
        let Some(scratch) = scratch.get_mut(..n) else {
            return dy.fill(f64::NAN);
        };
        if y.len() != 2 * n || dy.len() != 2 * n {
            return dy.fill(f64::NAN);
        }
        let (q, v) = y.split_at(n);
        self.nonlinear(q, scratch);
        let (dq, dv) = dy.split_at_mut(n);
        dq.copy_from_slice(v);
        let modes = dv.iter_mut().zip(v.iter().zip(q)).zip(scratch.iter());
        for (i, ((dvi, (vi, qi)), li)) in modes.enumerate() {
            let kappa = ((i + 1) as f64 * PI).powi(2);
            let f = if i == 0 {
                self.params.y0 * t.cos()
            } else {
                0.0
            };
            *dvi = (f - omega * self.params.cd * vi - kappa * qi + li) / (omega * omega);
        }
    }

    /// Classical RK4 over `periods` periods of `2π` with `steps_per_period`
    /// steps, from state `y` (overwritten) starting at `t = 0`.
    pub fn integrate(&self, omega: f64, y: &mut [f64], periods: usize, steps_per_period: usize) {
        let h = 2.0 * PI / steps_per_period as f64;
        let mut scr = vec![0.0; y.len() / 2];
        let mut rhs = |t: f64, y: &[f64], dy: &mut [f64]| self.rhs(omega, t, y, dy, &mut scr);
        let mut rk = ExplicitRk::with_dim(&RK4, y.len());
        // Time restarts at 0 every period (the forcing is 2π-periodic).
        for _ in 0..periods {
            rk.fixed_steps(&mut rhs, 0.0, h, steps_per_period, y);
        }
    }
}

/// The engine's slot (index in a DOF block `[a0, a1..aM, b1..bM]`) of STHB
/// harmonic row `h` (`0`: constant, `2k − 1`: cos kt, `2k`: sin kt) and the
/// factor from STHB to engine (2 for the constant: the engine stores `a0`, STHB
/// `a0/2`).
fn engine_slot(h: usize, m: usize) -> (usize, f64) {
    match h {
        0 => (0, 2.0),
        h if h % 2 == 1 => (h.div_ceil(2), 1.0),
        h => (m + h / 2, 1.0),
    }
}

/// The hand-derived model as a problem of the general engine: `M q̈ + C q̇ + K q
/// + g(q) = f(θ)` with `g = −ℒ(q)` (cubic, velocity independent) and its exact
/// Jacobian `−∂ℒ/∂q`.
impl PeriodicProblem for ModalString {
    fn n_dof(&self) -> usize {
        self.params.modes
    }
    fn mass(&self) -> &[f64] {
        &self.mass
    }
    fn damping(&self) -> &[f64] {
        &self.damping
    }
    fn stiffness(&self) -> &[f64] {
        &self.stiffness
    }
    fn nonlinear(&self, x: &[f64], _v: &[f64], _theta: f64, out: &mut [f64]) {
        ModalString::nonlinear(self, x, out);
        out.iter_mut().for_each(|g| *g = -*g);
    }
    fn excitation(&self, theta: f64, out: &mut [f64]) {
        out.fill(0.0);
        if let Some(first) = out.first_mut() {
            *first = self.params.y0 * theta.cos();
        }
    }
    displacement_jacobian!(|s, x, _theta, dg_dx| {
        ModalString::nonlinear_jacobian(s, x, dg_dx);
        dg_dx.iter_mut().for_each(|g| *g = -*g)
    });
}
