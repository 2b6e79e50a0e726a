//! Hsu's monodromy (Eq. 80) of a reduced variational equation whose linear
//! part is proportionally damped and whose nonlinear term acts on positions
//! only (`G_v = 0` on the orbit, checked per sample), by a splitting in
//! the reduced modal coordinates.
//!
//! With `Φ` the `M_r`-orthonormal eigenvectors of `(K_r, M_r)` and
//! `Φᵀ C_r Φ` diagonal (checked), the reduced Eq. 78 in τ = ωt reads per mode
//! `η_j'' + (d_j/ω) η_j' + (λ_j/ω²) η_j = −(1/ω²) w_jᵀ G_x(τ) W η`,
//! `W = V_S Φ` (`s×r`). The linear flow `exp(hA)` is exact 2×2 blocks per
//! mode; the kick `B(τ) = [0 0; −Wᵀ G_x W/ω² 0]` has `B² = 0`, so
//! `exp(hB) = I + hB` exactly. The symmetric (Strang) product
//! `exp(hA/2)(I + hB(τ_½))exp(hA/2)` per step is second order, with an
//! error expansion in even powers of `h`; its Richardson extrapolation
//! `X_S = (4Φ_S − Φ_{S/2})/3` is fourth order as `h → 0`, and the change of
//! the multipliers of `X_S` against `X_{S/2}`, over 3 (only the second
//! order assumed, [`SECOND_ORDER`]), estimates their error. A step costs `O(r²·s)` on the
//! monodromy instead of the `O(r³)` exponential of a Magnus step.

use super::ritz::{at, Reduced};
use faer::{Mat, Side};
use ivt_hb::orbit::aft::Aft;
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::stability::floquet::{eigenvalues, expm2};
use ivt_hb::stability::{richardson_error, Floquet, HsuEstimate, HsuSteps};
use ivt_hb::HbError;

/// The order of the Richardson estimate ([`richardson_error`]): the
/// extrapolated splitting is fourth order only once `h` resolves the
/// stiffest coupled mode, so the change of the multipliers is divided by
/// 2² − 1 = 3 (the splitting's own second order), not 2⁴ − 1.
const SECOND_ORDER: u32 = 2;

/// `Φᵀ C_r Φ` counts as diagonal when every off-diagonal entry is at most
/// this part of its largest diagonal entry (rounding of the projections).
const DIAGONAL: f64 = 1e-12;

/// The modal form of one reduced problem and its step control.
#[derive(Debug, Clone)]
pub(super) struct ModalHsu {
    /// Modes `r` and nonlinear DOFs `s`.
    r: usize,
    s: usize,
    /// `λ_j` (`ω_j²`) and `d_j` (`Φᵀ C_r Φ` diagonal) per mode.
    stiffness: Vec<f64>,
    damping: Vec<f64>,
    /// `W = V_S Φ`, row-major `s×r`.
    shape: Vec<f64>,
    harmonics: usize,
    tol: f64,
    /// Step count of level 0 (level `k`: `base·2^k`) and the highest level.
    base: usize,
    top: usize,
    /// Level the next orbit's coarsest monodromy is at.
    level: usize,
}

impl ModalHsu {
    /// The modal form of `reduced`, `None`
    /// when the splitting does not apply: the damping is not proportional
    /// on the reduced basis, `steps` is fixed, or the eigenproblem fails.
    pub(super) fn new(reduced: &Reduced, harmonics: usize, steps: HsuSteps) -> Option<Self> {
        let HsuSteps::Tolerance { tol, max } = steps else {
            return None;
        };
        let base = (2 * (harmonics + 1)).max(32);
        if !(tol > 0.0 && tol.is_finite()) || max < 4 * base {
            return None;
        }
        let (r, s) = (reduced.size, reduced.at_dofs.len() / reduced.size.max(1));
        let modes = modes(r, &reduced.m, &reduced.k)?;
        let project = |a: &[f64], i: usize, j: usize| -> f64 {
            (0..r)
                .map(|p| {
                    let row: f64 = (0..r).map(|q| at(a, p * r + q) * modes[(q, j)]).sum();
                    modes[(p, i)] * row
                })
                .sum()
        };
        let stiffness: Vec<f64> = (0..r).map(|j| project(&reduced.k, j, j)).collect();
        let damping: Vec<f64> = (0..r).map(|j| project(&reduced.c, j, j)).collect();
        let scale = damping.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let proportional =
            (0..r).all(|i| (0..i).all(|j| project(&reduced.c, i, j).abs() <= DIAGONAL * scale));
        if !proportional || stiffness.iter().chain(&damping).any(|x| !x.is_finite()) {
            return None;
        }
        let shape = (0..s)
            .flat_map(|a| {
                let modes = &modes;
                (0..r).map(move |j| {
                    (0..r)
                        .map(|p| at(&reduced.at_dofs, a * r + p) * modes[(p, j)])
                        .sum()
                })
            })
            .collect();
        Some(Self {
            r,
            s,
            stiffness,
            damping,
            shape,
            harmonics,
            tol,
            base,
            top: (max / base).ilog2() as usize,
            level: 0,
        })
    }

    /// The multipliers of the orbit whose nonlinear DOFs have the harmonics
    /// `q` (`s` rows of `2n + 1`) at ω = `omega` (the orbit's own frequency,
    /// ω_f/p) with the excitation phase `p·τ`: levels are added until the
    /// Richardson estimate meets the tolerance; `None` if it does not within
    /// the cap (the splitting has not reached its asymptotic order on the
    /// stiffest coupled modes) or `G_v` is not zero on the orbit (the kick
    /// would not be nilpotent): the caller falls back to Magnus-4.
    ///
    /// # Errors
    /// [`HbError`] if the samples of a level cannot be set up.
    pub(super) fn floquet<P: PeriodicProblem>(
        &mut self,
        local: &P,
        q: &[f64],
        omega: f64,
        subharmonic: usize,
    ) -> Result<Option<HsuEstimate>, HbError> {
        let dim = 2 * self.r;
        let mut level = self.level.min(self.top.saturating_sub(2));
        let Some(mut coarse) = self.monodromy(local, q, omega, subharmonic, level)? else {
            return Ok(None);
        };
        let Some(mut fine) = self.monodromy(local, q, omega, subharmonic, level + 1)? else {
            return Ok(None);
        };
        let mut last: Option<Vec<faer::c64>> = None;
        loop {
            let extrapolated: Vec<f64> = fine
                .iter()
                .zip(&coarse)
                .map(|(f, c)| (4.0 * f - c) / 3.0)
                .collect();
            // Y is column-major: its transpose has the same eigenvalues.
            let mu = eigenvalues(&extrapolated, dim);
            if let Some(previous) = last.take() {
                let error = richardson_error(&mu, &previous, SECOND_ORDER);
                let finest = level + 1;
                if error <= self.tol {
                    self.level = if error * 32.0 <= self.tol {
                        finest.saturating_sub(3)
                    } else {
                        finest.saturating_sub(2)
                    };
                    return Ok(Some(HsuEstimate {
                        floquet: Floquet::new(mu),
                        steps: self.base << finest,
                        error: Some(error),
                    }));
                }
                if finest >= self.top || !error.is_finite() {
                    self.level = finest.saturating_sub(2);
                    return Ok(None);
                }
            }
            last = Some(mu);
            level += 1;
            coarse = fine;
            let Some(next) = self.monodromy(local, q, omega, subharmonic, level + 1)? else {
                return Ok(None);
            };
            fine = next;
        }
    }

    /// The split monodromy of `base·2^level` steps, column-major `2r×2r`
    /// (state `[η; η']`).
    fn monodromy<P: PeriodicProblem>(
        &self,
        local: &P,
        q: &[f64],
        omega: f64,
        subharmonic: usize,
        level: usize,
    ) -> Result<Option<Vec<f64>>, HbError> {
        let (r, s) = (self.r, self.s);
        let steps = self.base << level;
        let h = 2.0 * std::f64::consts::PI / steps as f64;
        let Some(kicks) = self.kicks(local, q, omega, subharmonic, steps)? else {
            return Ok(None);
        };
        let half = self.flows(0.5 * h, omega);
        let whole = self.flows(h, omega);
        let dim = 2 * r;
        let mut y = vec![0.0; dim * dim];
        y.iter_mut().step_by(dim + 1).for_each(|v| *v = 1.0);
        let mut projected = vec![0.0; s];
        let mut forced = vec![0.0; s];
        for column in y.chunks_exact_mut(dim) {
            flow(column, &half);
            for (i, g) in kicks.chunks_exact(s * s).enumerate() {
                // η' −= h/ω² Wᵀ G_x W η.
                let (eta, rate) = column.split_at_mut(r);
                for (p, w) in projected.iter_mut().zip(self.shape.chunks_exact(r)) {
                    *p = w.iter().zip(eta.iter()).map(|(a, b)| a * b).sum();
                }
                for (f, g_row) in forced.iter_mut().zip(g.chunks_exact(s)) {
                    *f = h / (omega * omega)
                        * g_row
                            .iter()
                            .zip(&projected)
                            .map(|(a, b)| a * b)
                            .sum::<f64>();
                }
                for (f, w) in forced.iter().zip(self.shape.chunks_exact(r)) {
                    rate.iter_mut().zip(w).for_each(|(v, a)| *v -= f * a);
                }
                flow(column, if i + 1 < steps { &whole } else { &half });
            }
        }
        Ok(Some(y))
    }

    /// `G_x` (`s×s`, row-major) at the midpoints `(i + ½)h` of the `steps`
    /// steps; `None` if `G_v` is not zero at one of them.
    fn kicks<P: PeriodicProblem>(
        &self,
        local: &P,
        q: &[f64],
        omega: f64,
        subharmonic: usize,
        steps: usize,
    ) -> Result<Option<Vec<f64>>, HbError> {
        let s = self.s;
        let mut aft = Aft::new(self.harmonics, steps)?;
        let samples = 2 * steps;
        let (mut xs, mut vs) = (vec![0.0; s * samples], vec![0.0; s * samples]);
        let mut column = vec![0.0; samples];
        aft.synthesize_states(q, s, 0, 1.0, &mut xs, &mut column);
        aft.synthesize_states(q, s, 1, omega, &mut vs, &mut column);
        // The midpoints are the odd samples of the 2·steps grid.
        let odd = |v: &[f64]| -> Vec<f64> {
            v.chunks_exact(s)
                .skip(1)
                .step_by(2)
                .flatten()
                .copied()
                .collect()
        };
        let phases: Vec<f64> = (0..steps)
            .map(|i| subharmonic as f64 * aft.tau(2 * i + 1))
            .collect();
        let mut dg = vec![0.0; steps * 2 * s * s];
        local.nonlinear_jacobian_samples(&odd(&xs), &odd(&vs), &phases, &mut dg);
        if dg
            .chunks_exact(2 * s * s)
            .any(|d| d.iter().skip(s * s).any(|&gv| gv != 0.0))
        {
            return Ok(None);
        }
        Ok(Some(
            dg.chunks_exact(2 * s * s)
                .flat_map(|d| d.iter().take(s * s).copied())
                .collect(),
        ))
    }

    /// `exp(hA_j)` (row-major 2×2) of every mode.
    fn flows(&self, h: f64, omega: f64) -> Vec<[f64; 4]> {
        self.stiffness
            .iter()
            .zip(&self.damping)
            .map(|(l, d)| {
                let mut e = [0.0; 4];
                expm2(&[0.0, h, -h * l / (omega * omega), -h * d / omega], &mut e);
                e
            })
            .collect()
    }
}

/// `column = exp(hA) column` for the state `[η; η']` and the modes' 2×2
/// flows.
fn flow(column: &mut [f64], flows: &[[f64; 4]]) {
    let (eta, rate) = column.split_at_mut(flows.len());
    for ((x, v), [a, b, c, d]) in eta.iter_mut().zip(rate.iter_mut()).zip(flows) {
        let (x0, v0) = (*x, *v);
        *x = a * x0 + b * v0;
        *v = c * x0 + d * v0;
    }
}

/// `M`-orthonormal eigenvectors of `(K, M)` (`r×r` row-major, symmetric,
/// `M` positive definite): `M^{-1/2} Q` with `Q` the eigenvectors of
/// `M^{-1/2} K M^{-1/2}`; `None` if an eigenproblem fails or `M` is not
/// positive definite.
fn modes(r: usize, m: &[f64], k: &[f64]) -> Option<Mat<f64>> {
    let mass = Mat::<f64>::from_fn(r, r, |i, j| 0.5 * (at(m, i * r + j) + at(m, j * r + i)));
    let eig = mass.self_adjoint_eigen(Side::Lower).ok()?;
    let (u, d) = (eig.U(), eig.S().column_vector());
    if (0..r).any(|i| d[i].is_nan() || d[i] <= 0.0) {
        return None;
    }
    let root = Mat::<f64>::from_fn(r, r, |i, j| {
        (0..r).map(|p| u[(i, p)] * u[(j, p)] / d[p].sqrt()).sum()
    });
    let stiff = Mat::<f64>::from_fn(r, r, |i, j| 0.5 * (at(k, i * r + j) + at(k, j * r + i)));
    let a = &root * &stiff * &root;
    let sym = Mat::<f64>::from_fn(r, r, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let eig = sym.self_adjoint_eigen(Side::Lower).ok()?;
    Some(&root * eig.U())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]

    use super::*;
    use ivt_hb::orbit::ihb::HbSolution;
    use ivt_hb::problem::GeneralProblem;
    use ivt_hb::stability::multiplier_distance;
    use ivt_hb::stability::AdaptiveHsu;

    /// A 3-DOF chain with a non-diagonal mass, `C = 0.02 M + 0.01 K`.
    const M: [f64; 9] = [2.0, 0.5, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0, 1.0];
    const K: [f64; 9] = [3.0, -1.0, 0.0, -1.0, 2.0, -1.0, 0.0, -1.0, 1.5];
    /// The cubic spring's constant at DOF 2.
    const K3: f64 = 5.0;
    /// An orbit of DOF 2 (n = 3, not an HB solution: the variational
    /// equation is defined along any periodic motion) and its ω.
    const ORBIT: [f64; 7] = [0.1, 0.8, 0.0, 0.1, 0.3, 0.05, 0.0];
    const OMEGA: f64 = 1.3;

    fn damping(alpha: f64) -> Vec<f64> {
        M.iter().zip(K).map(|(m, k)| alpha * m + 0.01 * k).collect()
    }

    /// The chain as its own reduced problem (`V = I`, `S = {2}`).
    fn reduced(c: Vec<f64>) -> Reduced {
        Reduced {
            size: 3,
            m: M.to_vec(),
            c,
            k: K.to_vec(),
            at_dofs: vec![0.0, 0.0, 1.0],
            lift: vec![0.0, 0.0, 1.0],
        }
    }

    /// `K3 x_d³` on the last DOF `d` of `n` with `M`, `C`, `K`: the chain
    /// (`n = 3`) or its local problem (`n = 1`, no matrices).
    fn cubic(n: usize, m: Vec<f64>, c: Vec<f64>, k: Vec<f64>) -> impl PeriodicProblem {
        let d = n - 1;
        let law = move |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
            g.fill(0.0);
            g[d] = K3 * x[d].powi(3);
        };
        let slope = move |x: &[f64], _v: &[f64], _t: f64, dg: &mut [f64]| {
            dg.fill(0.0);
            dg[d * n + d] = 3.0 * K3 * x[d] * x[d];
        };
        GeneralProblem::new(n, m, c, k, law, |_t: f64, f: &mut [f64]| f.fill(0.0))
            .with_velocity_dependent(false)
            .with_jacobian(slope)
    }

    fn spring() -> impl PeriodicProblem {
        cubic(1, vec![0.0], vec![0.0], vec![0.0])
    }

    /// Hausdorff distance of two multiplier sets relative to max(1, |μ|),
    /// the measure of the Richardson estimates.
    fn distance(a: &[faer::c64], b: &[faer::c64]) -> f64 {
        multiplier_distance(a, b)
    }

    /// The split multipliers equal Magnus-4 Hsu of the whole chain (tight
    /// tolerance) within the split estimate plus the reference's.
    #[test]
    fn splitting_equals_magnus_hsu_within_its_estimate() {
        let steps = HsuSteps::Tolerance {
            tol: 1e-8,
            max: 4096,
        };
        let local = spring();
        let mut modal = ModalHsu::new(&reduced(damping(0.02)), 3, steps).unwrap();
        let split = modal.floquet(&local, &ORBIT, OMEGA, 1).unwrap().unwrap();
        let chain = cubic(3, M.to_vec(), damping(0.02), K.to_vec());
        let tight = HsuSteps::Tolerance {
            tol: 1e-11,
            max: 8192,
        };
        let mut hsu = AdaptiveHsu::new(&chain, 3, tight).unwrap();
        let mut coeffs = vec![0.0; 21];
        coeffs[14..].copy_from_slice(&ORBIT);
        let sol = HbSolution {
            coeffs,
            omega_f: OMEGA,
            harmonics: 3,
            subharmonic: 1,
            stats: Default::default(),
        };
        let reference = hsu.floquet(&chain, &sol).unwrap();
        let d = distance(&split.floquet.multipliers, &reference.floquet.multipliers);
        let estimate = split.error.unwrap() + reference.error.unwrap();
        assert!(d <= estimate, "distance {d:e} > estimate {estimate:e}");
        assert!(split.error.unwrap() <= 1e-8);
        // Not vacuous: the orbit's kick moves the multipliers well beyond
        // the estimate from the linear chain's.
        let linear = HbSolution {
            coeffs: vec![0.0; 21],
            ..sol
        };
        let free = hsu.floquet(&chain, &linear).unwrap();
        let moved = distance(&free.floquet.multipliers, &split.floquet.multipliers);
        assert!(moved > 1e3 * estimate, "moved {moved:e}");
    }

    /// Damping that is not proportional on the basis, or a fixed step
    /// count, leaves the splitting out; so does a `G_v` that is not zero on
    /// the orbit (the chain's Magnus-4 takes over), while a problem flagged
    /// velocity dependent whose `G_v` is zero keeps it.
    #[test]
    fn splitting_needs_proportional_damping_and_positions_only() {
        let steps = HsuSteps::default();
        let mut c = damping(0.02);
        c[0] += 0.05;
        assert!(ModalHsu::new(&reduced(c), 3, steps).is_none());
        assert!(ModalHsu::new(&reduced(damping(0.02)), 3, HsuSteps::Fixed(64)).is_none());
        let viscous = GeneralProblem::new(
            1,
            vec![0.0],
            vec![0.0],
            vec![0.0],
            |_x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| g[0] = v[0].powi(3),
            |_t: f64, f: &mut [f64]| f[0] = 0.0,
        );
        let mut modal = ModalHsu::new(&reduced(damping(0.02)), 3, steps).unwrap();
        assert!(modal.floquet(&viscous, &ORBIT, OMEGA, 1).unwrap().is_none());
        let flagged = GeneralProblem::new(
            1,
            vec![0.0],
            vec![0.0],
            vec![0.0],
            |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| g[0] = K3 * x[0].powi(3),
            |_t: f64, f: &mut [f64]| f[0] = 0.0,
        );
        assert!(flagged.velocity_dependent());
        let mut modal = ModalHsu::new(&reduced(damping(0.02)), 3, steps).unwrap();
        let split = modal.floquet(&flagged, &ORBIT, OMEGA, 1).unwrap();
        assert!(split.is_some_and(|e| e.error.unwrap() <= 1e-6));
    }
}
