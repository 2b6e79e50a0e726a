//! Local stability of the integral time-delay feedback, thesis §4.3.
//!
//! Eq. 171 in θ with `z = ∫_{θ−2π}^{θ} dσ/ω` (Eq. 172) is recast as a transport
//! problem `u(θ, x) = ω(θ − x)`, x ∈ [0, 2π] (Eq. 173), and linearized about
//! the periodic steady state (ω̄, r̄, z̄ = 2π/ω0), Eq. 174:
//!
//! ```text
//! Δu_x + Δu_θ = 0
//! Δu_θ(θ,0) = A Δr + B Δu(θ,0)
//! Δr' = K Δz + k2 [Δu(θ,0) − Δu(θ,2π)],   K = −k ω0²/(2π)
//! Δz' = C [Δu(θ,0) − Δu(θ,2π)]
//! ```
//!
//! with A, B, C of Appendix B. Δu = Σ q_i T_i(x) on Chebyshev polynomials of
//! x/π − 1 and the spectral Tau method (Eq. 175–178) give η' = 𝒜(θ) η,
//! η = {q_0 … q_N, Δr, Δz} (Eq. 179, Appendix C). The monodromy matrix over
//! θ ∈ [0, 2π] is integrated with the order-6 Runge–Kutta on the smooth pieces
//! (A, B jump with f_θ at the gear corners); ω̄ is integrated alongside from
//! Eq. 162 so that A, B, C are exact at every stage. One multiplier is the
//! structural unit one (Appendix C: it comes from the integral variable z);
//! the one closest to 1 is set aside and reported separately.

use super::pieces::{pieces, rk6, steps_for};
use super::shooting::{shoot_steady_state, PeriodicOrbit, ShootingOptions};
use super::{check_plant, IvtError, OperatingPoint};
use core::f64::consts::PI;
use ivt_kin::plant::{PlantParams, PlantTerms};
use ivt_kin::variant::f_on_segment;
use nalgebra::DMatrix;

/// Feedback gains of Eq. 171/180 in SI: `dr/dθ = k(ω_a − ω0) + k2(ω − ω_T)`,
/// so k and k2 are in m·s/rad² (metres of r per radian of θ per rad/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeedbackGains {
    /// Integral gain k \[m·s/rad²\].
    pub k: f64,
    /// Damping gain k2 \[m·s/rad²\].
    pub k2: f64,
}

impl FeedbackGains {
    /// From the thesis's printed "mm·rad⁻¹" numbers, read (as in
    /// `ivt_ctrl::units::gain_from_mm_per_rad`) as millimetres of r per radian
    /// of θ per rad/s of speed error: `k_SI = 1e-3 · k_printed`.
    pub fn from_thesis_mm_per_rad(k: f64, k2: f64) -> Self {
        Self {
            k: 1e-3 * k,
            k2: 1e-3 * k2,
        }
    }

    /// Back to the printed unit (mm·rad⁻¹ per rad/s).
    pub fn to_thesis_mm_per_rad(self) -> (f64, f64) {
        (1e3 * self.k, 1e3 * self.k2)
    }
}

/// Largest Chebyshev order N accepted: the monodromy costs about N⁵ (3 ms at
/// N = 16, some seconds at N = 64) while N = 16 is already converged to
/// ~1e-5 in the max |multiplier|; a larger N is refused before allocation.
pub const MAX_CHEBYSHEV_ORDER: usize = 64;

/// Discretization of the stability analysis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelayOptions {
    /// Chebyshev order N (even; thesis uses an even N). 16 is converged to
    /// ~1e-6 in the max |multiplier| (docs/guide/src/reproducing.md).
    pub chebyshev_order: usize,
    /// RK6 steps per gear segment for the monodromy; 0 = automatic (grows
    /// with N² because the Tau transport operator is stiff like N²). If the
    /// integration blows up (explicit-RK instability), the step count is
    /// doubled, twice at most, before an error is returned.
    pub steps_per_segment: usize,
    /// Shooting accuracy for the steady state (ω̄(0), r̄).
    pub shooting: ShootingOptions,
}

impl Default for DelayOptions {
    fn default() -> Self {
        Self {
            chebyshev_order: 16,
            steps_per_segment: 0,
            shooting: ShootingOptions::default(),
        }
    }
}

impl DelayOptions {
    /// Refuse a Chebyshev order that is odd, zero or above
    /// [`MAX_CHEBYSHEV_ORDER`], before anything is allocated. Every entry point
    /// (CLI, Python, reproduce) calls it; [`monodromy`] does too.
    ///
    /// # Errors
    /// [`IvtError::Input`] naming `chebyshev_order` and the limit.
    pub fn validate(&self) -> Result<(), IvtError> {
        let nn = self.chebyshev_order;
        if nn == 0 || nn % 2 == 1 || nn > MAX_CHEBYSHEV_ORDER {
            return Err(IvtError::Input {
                name: "chebyshev_order",
                value: nn as f64,
                requirement: "even, >= 2 and <= 64 (MAX_CHEBYSHEV_ORDER: the cost grows like N^5)",
            });
        }
        Ok(())
    }

    fn steps(&self) -> usize {
        if self.steps_per_segment > 0 {
            self.steps_per_segment
        } else {
            // Explicit RK6 on the Tau transport block is stable from about N²/8
            // steps per segment (measured: N = 8 → 8, N = 16 → 32); 0.16 N²
            // leaves a 25 % margin and changes the max |multiplier| by ≤ 1e-7
            // against 4× more steps at N = 16.
            let n = self.chebyshev_order as f64;
            (0.16 * n * n).ceil().max(16.0) as usize
        }
    }
}

/// Floquet multipliers of Eq. 179 at one operating point.
#[derive(Clone, Debug, PartialEq)]
pub struct DelayStability {
    /// Largest |multiplier| without the structural unit one.
    pub max_abs_multiplier: f64,
    /// The multiplier set aside as the structural one (≈ 1).
    pub structural: (f64, f64),
    /// All multipliers (re, im), largest modulus first.
    pub multipliers: Vec<(f64, f64)>,
    /// The steady state linearized about.
    pub orbit: PeriodicOrbit,
}

/// The constant part of the Tau rows: dq_i/dθ = −Σ_n D[n][i] q_n (Eq. 175),
/// with d T_n/dx = Σ_i D[n][i] T_i and T_i(x) = cos(i·arccos(x/π − 1)).
/// Row i (of N) holds the coefficient of T_i in dT_n/dx for n = 0..=N.
fn tau_rows(n_order: usize) -> Vec<Vec<f64>> {
    (0..n_order)
        .map(|i| {
            let ci = if i == 0 { 2.0 } else { 1.0 };
            (0..=n_order)
                .map(|n| {
                    if n > i && (n - i) % 2 == 1 {
                        2.0 * n as f64 / ci / PI
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect()
}

/// ω̄' of Eq. 162 and the coefficients A, B, C of Appendix B (Eq. 174) at one
/// angle of the orbit, from the plant terms there and ω̄(θ) = `w`.
fn appendix_b(p: &PlantTerms, r: f64, w: f64) -> (f64, f64, f64, f64) {
    let drive = p.drive(r);
    let wp = (drive / w - 0.5 * p.j_theta * w - p.f_m) / p.j;
    let a = (-p.j_r * wp - 0.5 * p.j_theta_r * w + (p.g - p.f2) / w) / p.j;
    let b = -(drive / (w * w) + 0.5 * p.j_theta) / p.j;
    (wp, a, b, -1.0 / (w * w))
}

/// The periodic system matrix 𝒜(θ) of Eq. 179 (Appendix C), row-major
/// (N + 3)², for η = {q_0 … q_N, Δr, Δz}, at the angle θ with ω̄(θ) = `omega`
/// on the orbit at r = `r`; N = `opts.chebyshev_order`. The monodromy of
/// [`monodromy`] applies the same matrix without forming it; this dense form
/// is for other transformation-matrix rules, e.g. Hsu's product of matrix
/// exponentials (Eq. 80, `ivt_hb::stability::floquet::monodromy_hsu`) that §4.3 cites.
///
/// # Errors
/// Bad inputs, an odd or zero N, non-finite gains or ω̄ ≤ 0.
#[allow(clippy::too_many_arguments)]
pub fn system_matrix(
    plant: &PlantParams,
    op: &OperatingPoint,
    gains: FeedbackGains,
    r: f64,
    theta: f64,
    omega: f64,
    opts: &DelayOptions,
) -> Result<DMatrix<f64>, IvtError> {
    check_plant(plant)?;
    op.validate()?;
    opts.validate()?;
    for (name, v) in [("k", gains.k), ("k2", gains.k2), ("r", r), ("theta", theta)] {
        if !v.is_finite() {
            return Err(IvtError::Input {
                name,
                value: v,
                requirement: "finite",
            });
        }
    }
    if !(omega.is_finite() && omega > 0.0) {
        return Err(IvtError::Input {
            name: "omega",
            value: omega,
            requirement: "finite and > 0",
        });
    }
    let nn = opts.chebyshev_order;
    let dt = tau_rows(nn);
    let (f, ft) = ivt_kin::variant::f_and_f_theta(theta);
    let p = plant.terms_with_f(theta, f, ft, r, op.v_m, op.t_u);
    let (_, a, b, c) = appendix_b(&p, r, omega);
    let t0 = |i: usize| if i.is_multiple_of(2) { 1.0 } else { -1.0 };
    // Outside the table (never asked for below) a coefficient is zero.
    let coef = |i: usize, n: usize| dt.get(i).and_then(|row| row.get(n)).copied().unwrap_or(0.0);
    let big_k = -gains.k * op.omega0 * op.omega0 / (2.0 * PI);
    Ok(DMatrix::from_fn(nn + 3, nn + 3, |i, n| match (i, n) {
        // Eq. 175: q_i' = −Σ_n D[n][i] q_n for i < N.
        (i, n) if n <= nn && i < nn => -coef(i, n),
        // Eq. 176 solved for q_N' (T0_N = 1 for even N).
        (i, n) if n <= nn && i == nn => {
            b * t0(n) + (0..nn).map(|k| t0(k) * coef(k, n)).sum::<f64>()
        }
        // Eq. 177–178: (T_0 − T_I)_n = (−1)^n − 1.
        (i, n) if n <= nn && i == nn + 1 => gains.k2 * (t0(n) - 1.0),
        (_, n) if n <= nn => c * (t0(n) - 1.0),
        (i, n) if i == nn && n == nn + 1 => a,
        (i, n) if i == nn + 1 && n == nn + 2 => big_k,
        _ => 0.0,
    }))
}

/// Steady state to linearize about: shooting to the time-mean ω0 (exact to
/// ~1e-12; the IHB value may seed it).
///
/// # Errors
/// As [`shoot_steady_state`].
pub fn steady_orbit(
    plant: &PlantParams,
    op: &OperatingPoint,
    r_seed: Option<f64>,
    opts: &DelayOptions,
) -> Result<PeriodicOrbit, IvtError> {
    shoot_steady_state(plant, op, r_seed, &opts.shooting)
}

/// The monodromy matrix of Eq. 179 over θ ∈ [0, 2π] about `orbit`.
///
/// # Errors
/// Bad inputs, an odd or zero N, or a stall of ω̄.
pub fn monodromy(
    plant: &PlantParams,
    op: &OperatingPoint,
    gains: FeedbackGains,
    orbit: &PeriodicOrbit,
    opts: &DelayOptions,
) -> Result<DMatrix<f64>, IvtError> {
    let mut steps = opts.steps();
    let mut history = Vec::new();
    for _ in 0..3 {
        let m = monodromy_with_steps(plant, op, gains, orbit, opts, steps)?;
        let size = m.iter().fold(0.0f64, |a, v| {
            if v.is_finite() {
                a.max(v.abs())
            } else {
                f64::INFINITY
            }
        });
        // A linear loop that is anywhere near stable cannot amplify by 1e12 in
        // one revolution; such growth is the explicit integrator going unstable.
        if size < 1e12 {
            return Ok(m);
        }
        history.push(size);
        steps *= 2;
    }
    Err(IvtError::NoConvergence {
        method: "monodromy integration (unstable step size)",
        iterations: 3,
        history,
    })
}

fn monodromy_with_steps(
    plant: &PlantParams,
    op: &OperatingPoint,
    gains: FeedbackGains,
    orbit: &PeriodicOrbit,
    opts: &DelayOptions,
    steps: usize,
) -> Result<DMatrix<f64>, IvtError> {
    check_plant(plant)?;
    op.validate()?;
    opts.validate()?;
    let nn = opts.chebyshev_order;
    for (name, v) in [("k", gains.k), ("k2", gains.k2)] {
        if !v.is_finite() {
            return Err(IvtError::Input {
                name,
                value: v,
                requirement: "finite",
            });
        }
    }
    let d = nn + 3;
    let dt = tau_rows(nn);
    // T_i(x=0) = (−1)^i; T_i(2π) = 1; (T_0 − T_I)_i = (−1)^i − 1.
    let t0: Vec<f64> = (0..=nn)
        .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    let diff: Vec<f64> = t0.iter().map(|t| t - 1.0).collect();
    let big_k = -gains.k * op.omega0 * op.omega0 / (2.0 * PI);
    let r = orbit.r;
    // State: [ω̄, Φ column-major (d × d)], Φ = I.
    let mut y = vec![0.0; 1 + d * d];
    if let Some((w, phi)) = y.split_first_mut() {
        *w = orbit.omega_start;
        phi.iter_mut().step_by(d + 1).for_each(|v| *v = 1.0);
    }
    let mut rk = rk6(y.len());
    for (a, b, seg) in pieces(0.0, 2.0 * PI) {
        let mut rhs = |theta: f64, y: &[f64], dy: &mut [f64]| {
            let (f, ft) = f_on_segment(theta, seg);
            let p = plant.terms_with_f(theta, f, ft, r, op.v_m, op.t_u);
            let (Some((&w, phis)), Some((dw, outs))) = (y.split_first(), dy.split_first_mut())
            else {
                return;
            };
            let (wp, a_coef, b_coef, c_coef) = appendix_b(&p, r, w);
            *dw = wp;
            // Column by column of Φ: {q_0 … q_N, Δr, Δz}.
            for (phi, out) in phis.chunks_exact(d).zip(outs.chunks_exact_mut(d)) {
                let (q, [dr, dz]) = phi.split_at(nn + 1) else {
                    continue;
                };
                let (out_q, [out_n, out_r, out_z]) = out.split_at_mut(nn) else {
                    continue;
                };
                let mut bound = 0.0; // Σ_{i<N} T0_i q'_i
                for (i, ((o, row), t)) in out_q.iter_mut().zip(&dt).zip(&t0).enumerate() {
                    let mut s = 0.0;
                    for (coef, qn) in row.iter().zip(q).skip(i + 1) {
                        s += coef * qn;
                    }
                    *o = -s;
                    bound += t * *o;
                }
                let u0: f64 = q.iter().zip(&t0).map(|(a, b)| a * b).sum();
                let jump: f64 = q.iter().zip(&diff).map(|(a, b)| a * b).sum();
                // Eq. 176 solved for q'_N (T0_N = 1 for even N).
                *out_n = a_coef * dr + b_coef * u0 - bound;
                *out_r = big_k * dz + gains.k2 * jump; // Eq. 177
                *out_z = c_coef * jump; // Eq. 178
            }
        };
        let n = steps_for(b - a, steps);
        let h = (b - a) / n as f64;
        for i in 0..n {
            rk.step(&mut rhs, a + i as f64 * h, h, &mut y);
            let w = y.first().copied().unwrap_or(f64::NAN);
            if !(w.is_finite() && w > 0.0) {
                return Err(IvtError::Stall {
                    theta: a + (i + 1) as f64 * h,
                    omega: w,
                    r,
                });
            }
        }
    }
    Ok(DMatrix::from_iterator(d, d, y.into_iter().skip(1)))
}

/// Max |Floquet multiplier| of Eq. 179 at `op` for `gains`, linearized about
/// the exact steady state (r̄ unconstrained, as in the thesis's Fig. 42).
///
/// # Errors
/// Bad inputs, stall, or no convergence of the steady state.
pub fn delay_stability(
    plant: &PlantParams,
    op: &OperatingPoint,
    gains: FeedbackGains,
    opts: &DelayOptions,
) -> Result<DelayStability, IvtError> {
    opts.validate()?;
    let orbit = steady_orbit(plant, op, None, opts)?;
    delay_stability_about(plant, op, gains, &orbit, opts)
}

/// As [`delay_stability`] about a given steady state (reused across gains).
///
/// # Errors
/// As [`monodromy`].
pub fn delay_stability_about(
    plant: &PlantParams,
    op: &OperatingPoint,
    gains: FeedbackGains,
    orbit: &PeriodicOrbit,
    opts: &DelayOptions,
) -> Result<DelayStability, IvtError> {
    let m = monodromy(plant, op, gains, orbit, opts)?;
    // Row-major storage of M is the column-major storage of Mᵀ.
    let eig = ivt_hb::eigenvalues(m.transpose().as_slice(), m.nrows());
    let mut mult: Vec<(f64, f64)> = eig.iter().map(|z| (z.re, z.im)).collect();
    if mult.iter().any(|(a, b)| !(a.is_finite() && b.is_finite())) {
        return Err(IvtError::NoConvergence {
            method: "monodromy eigenvalues",
            iterations: 0,
            history: vec![f64::NAN],
        });
    }
    let nearest_one = mult.iter().copied().enumerate().min_by(|a, b| {
        let da = (a.1 .0 - 1.0).hypot(a.1 .1);
        let db = (b.1 .0 - 1.0).hypot(b.1 .1);
        da.total_cmp(&db)
    });
    let Some((unit, structural)) = nearest_one else {
        return Err(IvtError::NoConvergence {
            method: "monodromy eigenvalues (none)",
            iterations: 0,
            history: vec![f64::NAN],
        });
    };
    let max_abs = mult
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != unit)
        .map(|(_, (a, b))| a.hypot(*b))
        .fold(0.0, f64::max);
    mult.sort_by(|a, b| b.0.hypot(b.1).total_cmp(&a.0.hypot(a.1)));
    Ok(DelayStability {
        max_abs_multiplier: max_abs,
        structural,
        multipliers: mult,
        orbit: *orbit,
    })
}
