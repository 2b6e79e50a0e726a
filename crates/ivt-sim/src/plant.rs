//! The IVT plant as a first-order system: Eq. 151, optionally with the
//! armature inductance of Eq. 137.
//!
//! State `y = [θ, ω, i_a]` in the time domain. With `L_a = 0` (Eq. 138, the
//! thesis's model) the current is algebraic, `i_a` is carried as 0 and its
//! derivative is 0; with `L_a > 0`
//!
//! ```text
//! L_a i̇_a = −R_a i_a − k_e f ω + V_m                     (Eq. 137, ω_m = f ω)
//! J θ̈     = G r − ½ J_θ ω² + f k_t i_a − f2 r             (Eq. 151 with f1 − F_m ω → f k_t i_a)
//! ```
//!
//! The coefficients come from [`ivt_kin::plant::PlantParams::terms_with_trig`];
//! this module only chooses *which smooth branch* of f(θ) is used. f has
//! corners at θ = π/4 + kπ/2 (Eq. 43) where f_θ jumps (Eq. 139). On segment
//! `k`, f(θ) = A cos(θ − kπ/2) exactly; evaluating that analytic branch for
//! the whole of one integration step (and ending steps on the corners) makes
//! every step integrate a smooth ODE, so the integrators keep their order.

use ivt_kin::plant::PlantParams;
use std::f64::consts::TAU;

/// Dimension of the plant state `[θ, ω, i_a]`.
pub const DIM: usize = 3;

pub use ivt_kin::variant::{f_on_segment, segment_end, segment_of};

/// The terms of the right-hand side that depend on θ alone (on one gear
/// segment): f, f_θ (Eq. 43, 139) and sin θ, cos θ of the gravity term —
/// the three transcendental calls of an RHS evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngleTerms {
    /// f(θ) on the segment's analytic branch.
    pub f: f64,
    /// f_θ(θ) on the same branch.
    pub f_theta: f64,
    /// sin θ.
    pub sin_theta: f64,
    /// cos θ.
    pub cos_theta: f64,
}

impl AngleTerms {
    /// The terms at θ on segment `seg`.
    #[inline]
    pub fn new(theta: f64, seg: i64) -> Self {
        let (f, f_theta) = f_on_segment(theta, seg);
        // θ only enters G(θ) here (f is given), which is 2π-periodic: reducing θ
        // to [0, 2π) first lets sin/cos skip their slow argument reduction at
        // large θ; the reduction error, ≤ |θ/2π|·ulp(2π), is ~1e-14 rad.
        let theta_g = theta - TAU * libm::floor(theta / TAU);
        Self {
            f,
            f_theta,
            sin_theta: libm::sin(theta_g),
            cos_theta: libm::cos(theta_g),
        }
    }
}

/// The slowly varying inputs seen by the plant during one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    /// Roller eccentricity r \[m\].
    pub r: f64,
    /// Motor voltage V_m \[V\].
    pub v_m: f64,
    /// Brake torque T_U \[N·m\].
    pub t_u: f64,
}

/// The plant: Table 1 parameters (with overrides) and the right-hand side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plant {
    /// Physical parameters; `params.l_a > 0` switches on the current state.
    pub params: PlantParams,
}

impl Plant {
    /// Plant with the given parameters.
    pub fn new(params: PlantParams) -> Self {
        Self { params }
    }

    /// Whether the armature current is a state (L_a > 0).
    #[inline]
    pub fn has_inductance(&self) -> bool {
        self.params.l_a > 0.0
    }

    /// The one right-hand side: time derivatives `[θ̇, ω̇, i̇_a]` at `y` on
    /// gear segment `seg`. Every integrator (time or angle domain) calls this.
    #[inline]
    pub fn derivatives(&self, seg: i64, y: &[f64; DIM], u: &Inputs) -> [f64; DIM] {
        self.derivatives_with(&AngleTerms::new(y[0], seg), y, u)
    }

    /// [`Self::derivatives`] with the θ-only terms `a` = `AngleTerms::new(y[0], seg)`
    /// already known: in the angle domain θ is the independent variable, so
    /// RK4's two middle stages and the end of one step / start of the next
    /// share them (the caller caches them; the result is bit-identical).
    #[inline(always)]
    pub fn derivatives_with(&self, a: &AngleTerms, y: &[f64; DIM], u: &Inputs) -> [f64; DIM] {
        let omega = y[1];
        let (f, f_theta) = (a.f, a.f_theta);
        let p = &self.params;
        let terms = |v_m| p.terms_with_trig(a.sin_theta, a.cos_theta, f, f_theta, u.r, v_m, u.t_u);
        if self.has_inductance() {
            let t = terms(0.0);
            let i_a = y[2];
            let torque = t.g * u.r - t.f2 * u.r + f * p.k_t * i_a;
            let accel = (torque - 0.5 * t.j_theta * omega * omega) / t.j;
            let di = (u.v_m - p.r_a * i_a - p.k_e * f * omega) / p.l_a;
            [omega, accel, di]
        } else {
            [omega, terms(u.v_m).acceleration(omega, u.r), 0.0]
        }
    }

    /// Armature current in quasi-steady state (L_a → 0): (V_m − k_e f ω)/R_a.
    /// Used to start an inductive run consistently and in the power balance.
    pub fn quasi_static_current(&self, theta: f64, omega: f64, v_m: f64) -> f64 {
        let (f, _) = f_on_segment(theta, segment_of(theta));
        (v_m - self.params.k_e * f * omega) / self.params.r_a
    }

    /// Kinetic energy ½ J(r, θ) ω² (J is continuous across the corners).
    pub fn kinetic_energy(&self, theta: f64, omega: f64, r: f64) -> f64 {
        let t = self.params.terms(theta, r, 0.0, 0.0);
        0.5 * t.j * omega * omega
    }

    /// Mechanical power into θ (N·m·rad/s) split as (motor, load+gravity, motor loss):
    /// `(f1 ω, (G − f2) r ω, −F_m ω²)` for L_a = 0. Their sum is d(½Jω²)/dt at
    /// constant r, which the energy test checks.
    pub fn powers(&self, seg: i64, y: &[f64; DIM], u: &Inputs) -> [f64; 3] {
        let (f, f_theta) = f_on_segment(y[0], seg);
        let t = self
            .params
            .terms_with_f(y[0], f, f_theta, u.r, u.v_m, u.t_u);
        let w = y[1];
        [t.f1 * w, (t.g - t.f2) * u.r * w, -t.f_m * w * w]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ivt_kin::variant;
    use std::f64::consts::FRAC_PI_4;

    /// The segment branch equals Eq. 43/139 inside each segment.
    #[test]
    fn segment_branch_matches_variant() {
        for k in 0..4000 {
            let th = -20.0 + k as f64 * 0.01037;
            let (f, ft) = f_on_segment(th, segment_of(th));
            assert!((f - variant::f(th)).abs() < 1e-14);
            assert!((ft - variant::f_theta(th)).abs() < 1e-14);
        }
        assert!((segment_end(0) - FRAC_PI_4).abs() < 1e-16);
        assert_eq!(segment_of(segment_end(3) + 1e-12), 4);
    }

    /// Over θ ∈ [0.05, 12.92] at θ̇ = 9 rad/s the RHS's θ̈ equals Eq. 151 to
    /// 1e-12 relative (round-off of the same sums), θ's derivative is θ̇, and
    /// with L_a > 0 the current, set to its quasi-static value, holds still.
    fn assert_rhs_matches_eq151(params: PlantParams, u: Inputs) {
        let p = Plant::new(params);
        let inductive = params.l_a > 0.0;
        for k in 0..100 {
            let th = 0.05 + 0.13 * k as f64;
            let i = if inductive {
                p.quasi_static_current(th, 9.0, u.v_m)
            } else {
                0.0
            };
            let d = p.derivatives(segment_of(th), &[th, 9.0, i], &u);
            let a = params.acceleration(th, 9.0, u.r, u.v_m, u.t_u);
            assert!(
                (d[1] - a).abs() <= 1e-12 * a.abs().max(1.0),
                "θ = {th}: {} vs {a}",
                d[1]
            );
            assert_eq!(d[0], 9.0);
            if inductive {
                assert!(d[2].abs() < 1e-9, "θ = {th}: di/dt = {}", d[2]);
            }
        }
    }

    /// With L_a = 0 the RHS is exactly `PlantParams::acceleration` (Eq. 151).
    #[test]
    fn rhs_is_eq151() {
        let u = Inputs {
            r: 0.0067,
            v_m: 6.0,
            t_u: 6.0,
        };
        assert_rhs_matches_eq151(PlantParams::printed(), u);
    }

    /// With the current at its quasi-static value the inductive RHS gives the
    /// same θ̈ as Eq. 151 (Eq. 137 → Eq. 138).
    #[test]
    fn inductive_rhs_reduces_to_eq151() {
        let mut params = PlantParams::printed();
        params.l_a = 1e-3;
        let u = Inputs {
            r: 0.005,
            v_m: 8.0,
            t_u: 4.0,
        };
        assert_rhs_matches_eq151(params, u);
    }
}
