//! Frequency-response curves of a condensed structure: the exact-Jacobian
//! pseudo-arclength continuation (Eq. 68–77, [`NewtonCorrector`]) of
//! [`CondensedBranch`] in ω_f, each fold located as the points arrive by
//! Newton on the extended system ([`ivt_hb::locate_fold`]) of the condensed
//! Jacobian, each amplitude peak located between the points (`peak.rs`),
//! any DOF recovered per
//! point, and per point the estimated errors of the linear solves and of the
//! harmonic truncation.

use super::branch::CondensedBranch;
use super::estimate::truncation_error;
use super::peak::{locate_peak, peaks, Sample};
use super::scaled::Scaled;
use super::stability::{
    BasisGrowth, CondensedFloquet, ReducedStability, DEFAULT_BASIS_TOL, DEFAULT_BLOCKS,
};
use ivt_hb::branches::events::{observe, BifurcationKind, EventObserver, Fold, LocateOptions};
use ivt_hb::branches::frc::FrcFold;
use ivt_hb::orbit::aft::Aft;
use ivt_hb::orbit::peak::refine_peak;
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::stability::HsuSteps;
use ivt_hb::HbError;
use ivt_path::branch::Branch;
use ivt_path::continuation::{
    correct_at_fixed_lambda, ContinuationOptions, NewtonCorrector, Stepper, Traced,
};

/// Options of a condensed frequency sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct CondensedFrcOptions {
    /// Start frequency ω_f.
    pub from: f64,
    /// End frequency ω_f.
    pub to: f64,
    /// Path options (λ bounds are set from `from`/`to`; `broyden.tol` is set
    /// from `rtol`). The path runs in scaled unknowns (`condense/scaled.rs`):
    /// steps `ds` are in units of the sweep's width |to − from| in ω_f
    /// (at least 1 % of ω_f) and
    /// of the nonlinear DOFs' linear response at `from`.
    pub continuation: ContinuationOptions,
    /// Corrector tolerance (on the receptance-form residual, a displacement)
    /// relative to the larger of the linear response ‖u_S‖₂ at the start and
    /// the point's own ‖q‖₂ (`condense/scaled.rs`).
    pub rtol: f64,
    /// DOF whose max |x_j(τ)| is the amplitude (default: the first nonlinear DOF).
    pub amplitude_dof: Option<usize>,
    /// DOFs whose coefficients every point carries.
    pub record_dofs: Vec<usize>,
    /// Estimate the harmonic truncation error per point (one extra
    /// factorization per omitted harmonic, up to 2n per point).
    pub truncation_estimate: bool,
    /// Floquet multipliers at every point from a reduced basis of at most
    /// this many Krylov blocks ([`ReducedStability`]); `None`: none (folds
    /// are located either way).
    pub stability_blocks: Option<usize>,
    /// The basis grows per point until its truncation estimate is at most
    /// this ([`BasisGrowth::tol`]).
    pub stability_tol: f64,
}

impl Default for CondensedFrcOptions {
    fn default() -> Self {
        Self {
            from: 0.5,
            to: 1.5,
            // Steps of at most 15 % of the sweep and of the scaled solution's
            // norm (scaled.rs); folds are located, not sampled. 10 % took
            // 82 points on the N = 500 beam, 15 % takes 46, with the same
            // folds to 12 digits; 20 % left the beam's lower fold unlocated.
            continuation: ContinuationOptions {
                ds: 0.02,
                ds_max: 0.15,
                ds_relative_scale: 1.0,
                target_iter: 8,
                second_order_predictor: true,
                ..ContinuationOptions::default()
            },
            rtol: 1e-12,
            amplitude_dof: None,
            record_dofs: Vec::new(),
            truncation_estimate: true,
            stability_blocks: Some(DEFAULT_BLOCKS),
            stability_tol: DEFAULT_BASIS_TOL,
        }
    }
}

/// One point of a condensed curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CondensedPoint {
    /// Excitation frequency ω_f.
    pub omega_f: f64,
    /// max_τ |x_j(τ)| of the amplitude DOF (the series' maximum, located by
    /// Newton from the largest of the 2N AFT samples).
    pub amplitude: f64,
    /// The condensed unknowns (harmonics of the nonlinear DOFs).
    pub coeffs: Vec<f64>,
    /// `(dof, [a0, a1..an, b1..bn])` of each recorded DOF.
    pub dof_coeffs: Vec<(usize, Vec<f64>)>,
    /// Estimated relative error of the receptances (the refined solves).
    pub solve_error: f64,
    /// Relative change of the receptances from the rounding of the stored
    /// `M` and `C` ([`crate::Structure::data_error`]).
    pub data_error: f64,
    /// Estimated relative error of the orbit (and of the amplitude when it
    /// is a nonlinear DOF's) at this ω_f from the corrector's residual and
    /// the receptances' errors (solve + data): the bound of `J⁻¹δR`, `J` the condensed Jacobian
    /// (`orbit_error`).
    pub orbit_error: f64,
    /// Estimated relative truncation error ([`truncation_error`]); `None` if
    /// not asked for.
    pub truncation_error: Option<f64>,
    /// Floquet multipliers with their error estimates, when asked for.
    pub floquet: Option<CondensedFloquet>,
}

/// A fold of a condensed curve: a [`FrcFold`] whose `amplitude` is that of
/// the amplitude DOF ([`CondensedPoint::amplitude`]) and whose `coeffs` are
/// the condensed unknowns (harmonics of the nonlinear DOFs).
pub type CondensedFold = FrcFold;

/// A traced condensed curve (its events: the folds, turning points in ω_f).
pub type CondensedFrc = Traced<CondensedPoint, CondensedFold>;

/// Traces the frequency response of `branch` from `opts.from` to `opts.to`.
///
/// # Errors
/// [`HbError::InvalidInput`] for bad bounds or DOFs, [`PathError::ContinuationStart`](ivt_path::PathError::ContinuationStart)
/// when the start does not converge, [`HbError::Singular`] when a dynamic
/// stiffness is singular at a point.
pub fn condensed_response<P: PeriodicProblem>(
    branch: &mut CondensedBranch<P>,
    opts: &CondensedFrcOptions,
) -> Result<CondensedFrc, HbError> {
    let valid = |w: f64| w.is_finite() && w > 0.0;
    if !(valid(opts.from) && valid(opts.to) && opts.from != opts.to && opts.rtol > 0.0) {
        return Err(HbError::InvalidInput(
            "sweep bounds must be positive, finite and distinct; rtol > 0".into(),
        ));
    }
    let n_dof = branch.structure().n_dof();
    let first = branch.dofs().first().copied().unwrap_or(0);
    let amp_dof = opts.amplitude_dof.unwrap_or(first);
    if let Some(bad) = opts
        .record_dofs
        .iter()
        .chain([&amp_dof])
        .find(|&&d| d >= n_dof)
    {
        return Err(HbError::InvalidInput(format!("DOF {bad} is out of range")));
    }
    let mut probe = Probe::new(branch, amp_dof, &opts.record_dofs)?;
    let mut stability = opts
        .stability_blocks
        .map(|max_blocks| {
            let growth = BasisGrowth {
                tol: opts.stability_tol,
                max_blocks,
            };
            ReducedStability::new(branch, growth, HsuSteps::default())
        })
        .transpose()?;
    let q0 = branch.linear_guess(opts.from)?;
    let q_scale = load_scale(branch, opts.from)?;
    // At least 1 % of ω_f: a one-point sweep (`solve`) keeps λ̃ ≤ 100.
    let width = (opts.to - opts.from)
        .abs()
        .max(0.01 * opts.from.max(opts.to));
    let mut scaled = Scaled::new(branch, q_scale, opts.from, width);
    let m = q0.len();
    let mut x = scaled.scaled(&q0, opts.from);
    let mut copts = opts.continuation.clone();
    copts.lambda_min = scaled.lambda(opts.from.min(opts.to));
    copts.lambda_max = scaled.lambda(opts.from.max(opts.to));
    // The residual is relative to q_scale already.
    copts.broyden.tol = opts.rtol;
    let its = correct_at_fixed_lambda(&mut scaled, &mut x, &copts)?;
    let direction = if opts.to > opts.from { 1.0 } else { -1.0 };
    let mut points = Vec::new();
    let mut failed = None;
    // Each fold is located as the points arrive (an `EventObserver` with the
    // [`Fold`] detector, Newton on the extended system of the scaled
    // branch), from the path point nearest the turn.
    let mut observer: EventObserver<_, HbError> =
        EventObserver::new(&LocateOptions::fold(), vec![Box::new(Fold)]);
    let m_len = scaled.len();
    let mut stepper = Stepper::new(
        &mut scaled,
        Box::new(NewtonCorrector::new(m_len, &copts)),
        &x,
        its,
        direction,
        &copts,
    )?;
    let (path, events) = observe(&mut stepper, &mut observer, |sc, p| {
        let (q, omega_f) = sc.physical(p.x.get(..m).unwrap_or_default(), p.lambda());
        let point = probe.point(
            sc.branch,
            &q,
            omega_f,
            opts.truncation_estimate,
            stability.as_mut(),
        );
        match point {
            Ok(point) => {
                points.push(point);
                true
            }
            Err(e) => {
                failed = Some(e);
                false
            }
        }
    })?;
    drop(stepper);
    let inserted = if failed.is_none() {
        let mut peak_probe = PeakProbe {
            scaled: &mut scaled,
            copts: &copts,
            probe: &mut probe,
            truncation: opts.truncation_estimate,
            stability: stability.as_mut(),
        };
        peak_probe.insert_peaks(&mut points)?
    } else {
        Vec::new()
    };
    // A path point's index among `points` after the insertions.
    let shifted = |j: usize| j + inserted.iter().filter(|&&p| p <= j).count();
    let branch = scaled.branch;
    if let Some(e) = failed.or_else(|| branch.take_failure().filter(|_| points.is_empty())) {
        return Err(e);
    }
    let mut folds = Vec::with_capacity(events.len());
    for event in events.iter().filter(|e| e.kind == BifurcationKind::Fold) {
        let fold = match &event.location {
            Ok(located) => {
                let coeffs: Vec<f64> = located.q.iter().map(|v| v * q_scale).collect();
                let omega_f = opts.from + located.lambda * width;
                CondensedFold {
                    index: shifted(event.index),
                    omega_f,
                    amplitude: probe.amplitude(branch, &coeffs, omega_f)?,
                    coeffs,
                    located: true,
                }
            }
            // Not located: the parabola's ω_f through the three points
            // around the turn (the stepper's estimate) and the nearest
            // point's orbit.
            Err(_) => {
                let turn = path.events.iter().find(|t| t.index == event.index);
                let index = shifted(event.index);
                match (points.get(index), turn) {
                    (Some(near), Some(turn)) => CondensedFold {
                        index,
                        omega_f: opts.from + turn.lambda * width,
                        amplitude: near.amplitude,
                        coeffs: near.coeffs.clone(),
                        located: false,
                    },
                    _ => continue,
                }
            }
        };
        folds.push(fold);
    }
    Ok(CondensedFrc {
        points,
        events: folds,
        termination: path.termination,
    })
}

/// What locating a peak between the points of a curve needs.
struct PeakProbe<'s, 'b, P: PeriodicProblem> {
    scaled: &'s mut Scaled<'b, P>,
    copts: &'s ContinuationOptions,
    probe: &'s mut Probe,
    truncation: bool,
    stability: Option<&'s mut ReducedStability>,
}

impl<P: PeriodicProblem> PeakProbe<'_, '_, P> {
    /// Locates each amplitude peak of `points` ([`peaks`], [`locate_peak`]:
    /// orbits corrected at fixed ω_f to the curve's tolerance) and inserts
    /// it as a point of its own between its neighbours; returns the insert
    /// positions, increasing, in the indices of the points before.
    ///
    /// # Errors
    /// As [`Probe::point`] for a located peak.
    fn insert_peaks(&mut self, points: &mut Vec<CondensedPoint>) -> Result<Vec<usize>, HbError> {
        let curve: Vec<(f64, f64)> = points.iter().map(|p| (p.omega_f, p.amplitude)).collect();
        let mut inserted = Vec::new();
        for i in peaks(&curve).into_iter().rev() {
            let sample = |p: &CondensedPoint| Sample {
                omega_f: p.omega_f,
                amplitude: p.amplitude,
                q: p.coeffs.clone(),
            };
            let Some(mut bracket) = points
                .get(i.saturating_sub(1)..=i + 1)
                .map(|w| w.iter().map(sample).collect::<Vec<_>>())
            else {
                continue;
            };
            bracket.sort_by(|a, b| a.omega_f.total_cmp(&b.omega_f));
            let Ok(bracket) = <[Sample; 3]>::try_from(bracket) else {
                continue;
            };
            let Some(peak) = locate_peak(bracket, |guess, w| self.corrected(&guess, w)) else {
                continue;
            };
            let point = self.probe.point(
                self.scaled.branch,
                &peak.q,
                peak.omega_f,
                self.truncation,
                self.stability.as_deref_mut(),
            )?;
            // After point i when between it and point i + 1 in ω_f.
            let after = points.get(i..=i + 1).is_some_and(|w| match w {
                [a, b] => (peak.omega_f - a.omega_f) * (peak.omega_f - b.omega_f) < 0.0,
                _ => false,
            });
            let at = if after { i + 1 } else { i };
            points.insert(at, point);
            inserted.push(at);
        }
        inserted.reverse();
        Ok(inserted)
    }

    /// The orbit at ω_f corrected from `guess` (Newton at fixed ω_f on the
    /// scaled branch) with its amplitude.
    fn corrected(&mut self, guess: &[f64], omega_f: f64) -> Result<Sample, HbError> {
        let mut x = self.scaled.scaled(guess, omega_f);
        correct_at_fixed_lambda(self.scaled, &mut x, self.copts)?;
        let Some((&lambda, u)) = x.split_last() else {
            return Err(HbError::InvalidInput("empty condensed point".into()));
        };
        let (q, omega_f) = self.scaled.physical(u, lambda);
        let amplitude = self.probe.amplitude(self.scaled.branch, &q, omega_f)?;
        Ok(Sample {
            omega_f,
            amplitude,
            q,
        })
    }
}

/// Corrects the condensed unknowns `q` at fixed ω_f by Newton on the exact
/// condensed Jacobian until the residual (a displacement) is within `rtol`
/// of the larger of the linear response ‖u_S‖₂ at ω_f and ‖q‖₂
/// (`condense/scaled.rs`); returns the steps taken.
///
/// # Errors
/// As [`ivt_path::continuation::correct_at_fixed_lambda`]; [`HbError::Singular`]
/// when a dynamic stiffness is singular; [`HbError::InvalidInput`] for a `q`
/// of the wrong length or a bad ω_f or `rtol`.
pub fn correct_condensed<P: PeriodicProblem>(
    branch: &mut CondensedBranch<P>,
    q: &mut [f64],
    omega_f: f64,
    rtol: f64,
) -> Result<usize, HbError> {
    if !(omega_f.is_finite() && omega_f > 0.0 && rtol > 0.0) || q.len() != Branch::len(branch) {
        return Err(HbError::InvalidInput(
            "correct_condensed: ω_f > 0, rtol > 0 and one unknown per condensed coefficient".into(),
        ));
    }
    let q_scale = load_scale(branch, omega_f)?;
    let mut scaled = Scaled::new(branch, q_scale, omega_f, 0.01 * omega_f);
    let mut x = scaled.scaled(q, omega_f);
    let mut copts = ContinuationOptions::default();
    copts.broyden.tol = rtol;
    let steps = correct_at_fixed_lambda(&mut scaled, &mut x, &copts)?;
    let (physical, _) = scaled.physical(&x, 0.0);
    q.iter_mut().zip(&physical).for_each(|(a, b)| *a = *b);
    Ok(steps)
}

/// ‖u_S‖₂ of harmonic p at ω_f (the linear response of the nonlinear DOFs:
/// the residual is a displacement), or 1 for an unloaded structure.
fn load_scale<P: PeriodicProblem>(
    branch: &mut CondensedBranch<P>,
    omega_f: f64,
) -> Result<f64, HbError> {
    let p = branch.options().subharmonic;
    let rc = branch.receptances(omega_f)?;
    let norm = rc
        .response
        .get(p)
        .map_or(0.0, |f| f.col(0).iter().map(|z| z.norm_sqr()).sum::<f64>())
        .sqrt();
    Ok(if norm > 0.0 { norm } else { 1.0 })
}

/// The first-order relative error of the condensed orbit `q` at ω_f as a
/// point of the curve, when the residual is `R(q)` (the corrector's
/// tolerance) and the receptances carry the relative error
/// `receptance_error` = e. The perturbed point moves by `A⁻¹[δR; 0]` with
/// the bordered Jacobian `A = [J ∂R/∂ω_f; tᵀ 0]` (`t` the curve's tangent:
/// the move normal to the curve; at fixed ω_f, `J⁻¹δR`, would be ill-posed
/// at a fold), `δR = −R(q) + Σ_h δR_h`, `δR_h = δH_h (F_h − G_h) = ε_h X_h`
/// for some complex |ε_h| ≤ e (`X_h = H_h(F_h − G_h)`; for several
/// nonlinear DOFs the same form per DOF, first order), so
/// `‖δq‖₁ ≤ ‖A⁻¹R‖₁ + e Σ_(d,h) (‖A⁻¹ v_dh‖₁ + ‖A⁻¹ v′_dh‖₁)` over the `q`
/// rows, `v_dh` the rows of `X_h` of DOF d and `v′_dh` those of `iX_h`;
/// relative to max_τ |x_S(τ)| ≥ max|q|/2 (a Fourier coefficient is at most
/// twice the maximum). Infinite where `A` is singular.
fn orbit_error<P: PeriodicProblem>(
    branch: &mut CondensedBranch<P>,
    q: &[f64],
    omega_f: f64,
    receptance_error: f64,
) -> f64 {
    let m = q.len();
    let n = branch.options().harmonics;
    let l = 2 * n + 1;
    let mut r = vec![0.0; m];
    let mut jac = vec![0.0; m * m];
    let mut r_omega = vec![0.0; m];
    Branch::residual(branch, q, omega_f, &mut r);
    Branch::jacobian(branch, q, omega_f, &mut jac);
    Branch::residual_lambda(branch, q, omega_f, 0.0, &mut r_omega);
    // The tangent (t_q, 1) with J t_q = −∂R/∂ω_f, normalized.
    let Some(j_inv) = ivt_num::lu::inverse(&jac, m) else {
        return f64::INFINITY;
    };
    let mut tangent: Vec<f64> = j_inv
        .chunks_exact(m)
        .map(|row| -ivt_num::vector::dot(row, &r_omega))
        .chain([1.0])
        .collect();
    let norm = ivt_num::vector::norm2(&tangent);
    tangent.iter_mut().for_each(|t| *t /= norm);
    let k = m + 1;
    let mut bordered = vec![0.0; k * k];
    for (i, row) in bordered.chunks_exact_mut(k).enumerate() {
        match (jac.get(i * m..(i + 1) * m), r_omega.get(i)) {
            (Some(j), Some(&w)) => {
                row.iter_mut()
                    .zip(j.iter().chain([&w]))
                    .for_each(|(a, b)| *a = *b);
            }
            _ => row.copy_from_slice(&tangent),
        }
    }
    let Some(full) = ivt_num::lu::inverse(&bordered, k) else {
        return f64::INFINITY;
    };
    // The q rows and the R columns of A⁻¹ (row-major m×k, last column unused).
    let inverse: Vec<f64> = full.chunks_exact(k).take(m).flatten().copied().collect();
    // ‖A⁻¹ v‖₁ (q rows) for v given by its non-zero entries.
    let applied = |entries: &[(usize, f64)]| -> f64 {
        inverse
            .chunks_exact(k)
            .map(|row| {
                entries
                    .iter()
                    .map(|&(j, v)| row.get(j).map_or(0.0, |a| a * v))
                    .sum::<f64>()
                    .abs()
            })
            .sum()
    };
    let dense: Vec<(usize, f64)> = r.iter().copied().enumerate().collect();
    let mut bound = applied(&dense);
    for d in 0..m / l {
        let at = |i: usize| q.get(d * l + i).copied().unwrap_or(0.0);
        // h = 0: X_0 = a0/2, real (D(0) is real).
        bound += receptance_error * applied(&[(d * l, 0.5 * at(0))]);
        for h in 1..=n {
            let (ra, rb) = (d * l + h, d * l + n + h);
            let (a, b) = (at(h), at(n + h));
            // X = a − ib in the rows (a, b); iX = b + ia in them as (b, −a).
            bound +=
                receptance_error * (applied(&[(ra, a), (rb, b)]) + applied(&[(ra, b), (rb, -a)]));
        }
    }
    let scale = q.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let err = 2.0 * bound / scale;
    if err.is_nan() {
        f64::INFINITY
    } else {
        err
    }
}

/// max_τ |x(τ)| of the series `coeffs`: the largest of the 2N samples of
/// `aft` (`samples`: its scratch), refined by Newton on `x′(τ) = 0` (the
/// sampled maximum alone is low by up to ~(π/2N)²/2 relative).
pub(crate) fn series_max(aft: &mut Aft, samples: &mut [f64], coeffs: &[f64]) -> f64 {
    aft.synthesize(coeffs, samples);
    refine_peak(coeffs, samples)
}

/// The per-point quantities: amplitude, recorded DOFs, error estimates.
struct Probe {
    aft: Aft,
    samples: Vec<f64>,
    /// Position of the amplitude DOF among the nonlinear DOFs, if it is one.
    amp_local: Option<usize>,
    amp_dof: usize,
    record: Vec<usize>,
}

impl Probe {
    fn new<P: PeriodicProblem>(
        branch: &CondensedBranch<P>,
        amp_dof: usize,
        record: &[usize],
    ) -> Result<Self, HbError> {
        let hb = branch.options();
        let aft = Aft::new(hb.harmonics, hb.n_half)?;
        Ok(Self {
            samples: vec![0.0; aft.n_samples()],
            amp_local: branch.dofs().iter().position(|&d| d == amp_dof),
            amp_dof,
            record: record.to_vec(),
            aft,
        })
    }

    /// [`series_max`] of `coeffs`.
    fn max_abs(&mut self, coeffs: &[f64]) -> f64 {
        series_max(&mut self.aft, &mut self.samples, coeffs)
    }

    fn amplitude<P: PeriodicProblem>(
        &mut self,
        branch: &mut CondensedBranch<P>,
        q: &[f64],
        omega_f: f64,
    ) -> Result<f64, HbError> {
        let l = self.aft.coeff_len();
        match self.amp_local {
            Some(d) => Ok(self.max_abs(q.get(d * l..(d + 1) * l).unwrap_or_default())),
            None => {
                let coeffs = branch.recover(q, omega_f, &[self.amp_dof])?;
                Ok(coeffs.first().map(|c| self.max_abs(c)).unwrap_or(0.0))
            }
        }
    }

    fn point<P: PeriodicProblem>(
        &mut self,
        branch: &mut CondensedBranch<P>,
        q: &[f64],
        omega_f: f64,
        truncation: bool,
        stability: Option<&mut ReducedStability>,
    ) -> Result<CondensedPoint, HbError> {
        let amplitude = self.amplitude(branch, q, omega_f)?;
        let recovered = branch.recover(q, omega_f, &self.record)?;
        let solve_error = branch.solve_error(omega_f)?;
        let data_error = branch.data_error(omega_f)?;
        let orbit_error = orbit_error(branch, q, omega_f, solve_error + data_error);
        let truncation_error = if truncation {
            Some(truncation_error(branch, q, omega_f)?)
        } else {
            None
        };
        let floquet = stability
            .map(|st| st.floquet(branch, q, omega_f))
            .transpose()?;
        Ok(CondensedPoint {
            omega_f,
            amplitude,
            coeffs: q.to_vec(),
            dof_coeffs: self.record.iter().copied().zip(recovered).collect(),
            solve_error,
            data_error,
            orbit_error,
            truncation_error,
            floquet,
        })
    }
}
