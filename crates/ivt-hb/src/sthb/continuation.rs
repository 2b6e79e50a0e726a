//! Pseudo-arclength continuation in ω of STHB solutions (Figs. 34–36).
//!
//! Interim path follower for the string: the general engine's continuation
//! (branch `hb`) was not available when this was written; the predictor–
//! corrector here is the textbook one (Eq. 68–77 of the thesis for the IHB):
//! tangent from `[J R_ω; t_prevᵀ] t = e`, predictor `u + s t`, Newton corrector
//! on `[R(u); tᵀ(u − u_pred)] = 0` with the exact STHB Jacobian, step control
//! by corrector iterations.
//!
//! Stability per point: the RK4 monodromy matrix (cheap, `O(N³)` per step);
//! Hill's method (Eq. 126–131) confirms where a multiplier is within
//! [`ContinuationOptions::hill_band`] of the unit circle, where the verdict
//! changes, or where `dω/ds` changes sign (a fold).

use faer::Mat;

use super::hb::norm2;
use super::lu::LuWorkspace;
use super::stability::{hill, monodromy, Stability};
use super::{SthbError, StringHb};

/// Path-following settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ContinuationOptions {
    /// Initial arclength step in `(a, ω)`.
    pub step: f64,
    /// Smallest step before giving up.
    pub step_min: f64,
    /// Largest step.
    pub step_max: f64,
    /// Stop after this many points.
    pub max_points: usize,
    /// Residual tolerance (`‖R‖ ≤ tol (1 + y0)`).
    pub tol: f64,
    /// Corrector iterations before the step is halved.
    pub max_corrector: usize,
    /// Assess stability at every point.
    pub stability: bool,
    /// Confirm by Hill when `| |μ| − 1 | <` this.
    pub hill_band: f64,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        Self {
            step: 0.02,
            step_min: 1e-6,
            step_max: 0.05,
            max_points: 2000,
            tol: 1e-10,
            max_corrector: 8,
            stability: true,
            hill_band: 0.02,
        }
    }
}

/// One point of a frequency–response curve.
#[derive(Clone, Debug, PartialEq)]
pub struct FrcPoint {
    /// Excitation frequency.
    pub omega: f64,
    /// `‖a‖` (complex coefficients, Figs. 34–36).
    pub norm: f64,
    /// Stability, if assessed.
    pub stability: Option<Stability>,
    /// Corrector iterations.
    pub iterations: usize,
    /// The solution coefficients.
    pub a: Vec<f64>,
}

/// Why a run ended (not an error).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// Passed the end frequency.
    ReachedEnd,
    /// Hit `max_points`.
    MaxPoints,
}

/// A frequency–response curve with run statistics.
#[derive(Clone, Debug)]
pub struct Frc {
    /// Points along the path.
    pub points: Vec<FrcPoint>,
    /// Why it ended.
    pub stop: StopReason,
    /// Jacobian factorizations (Newton steps) in total.
    pub factorizations: usize,
    /// How many points Hill's method assessed.
    pub hill_calls: usize,
}

/// Follow the branch of periodic responses from `omega_from` to `omega_to`.
///
/// # Errors
/// The first Newton solve's error, [`SthbError::Stalled`] if the step falls
/// below `step_min`, or a stability failure.
pub fn frequency_response(
    hb: &mut StringHb,
    omega_from: f64,
    omega_to: f64,
    opts: &ContinuationOptions,
) -> Result<Frc, SthbError> {
    if !(omega_from.is_finite() && omega_to.is_finite() && omega_from > 0.0 && omega_to > 0.0) {
        return Err(SthbError::Invalid(format!(
            "frequencies must be positive: {omega_from} .. {omega_to}"
        )));
    }
    let n = hb.dim();
    let dir = if omega_to >= omega_from { 1.0 } else { -1.0 };
    let mut a = vec![0.0; n];
    let first = hb
        .solve(omega_from, &mut a, opts.tol, 50)
        .map_err(|e| match e {
            SthbError::NoConvergence { .. } => SthbError::ColdStart {
                omega: omega_from,
                cause: Box::new(e),
            },
            e => e,
        })?;
    let mut factorizations = first.iterations;
    let mut aug = LuWorkspace::new(n + 1);
    let mut jac = Mat::<f64>::zeros(n, n);
    let (mut r, mut r_w) = (vec![0.0; n], vec![0.0; n]);
    let mut tangent = vec![0.0; n + 1];
    tangent[n] = dir;
    let mut omega = omega_from;
    let mut frc = Frc {
        points: Vec::new(),
        stop: StopReason::MaxPoints,
        factorizations: 0,
        hill_calls: 0,
    };
    let mut prev_stab: Option<Stability> = None;
    let mut step = opts.step;
    let mut prev_t_omega = dir;
    let mut iterations = first.iterations;
    let mut landed = false;
    let (mut u_pred, mut z) = (vec![0.0; n + 1], vec![0.0; n + 1]);
    loop {
        // The Jacobian at the converged point (Ŝ from the last balance) gives the tangent.
        hb.residual_jacobian(&a, omega, &mut r, &mut jac);
        hb.d_residual_d_omega(&a, omega, &mut r_w);
        fill_augmented(&mut aug.mat, &jac, &r_w, &tangent);
        factorizations += 1;
        if !aug.factor() {
            return Err(SthbError::Singular { omega });
        }
        z.fill(0.0);
        z[n] = 1.0;
        aug.solve(&mut z);
        let zn = norm2(&z);
        // Orient along the previous tangent.
        let sgn = if z.iter().zip(&tangent).map(|(x, y)| x * y).sum::<f64>() < 0.0 {
            -1.0
        } else {
            1.0
        };
        for (t, v) in tangent.iter_mut().zip(&z) {
            *t = sgn * v / zn;
        }
        let fold = tangent[n].signum() != prev_t_omega.signum();
        prev_t_omega = tangent[n];
        let stability = if opts.stability {
            let mut s = monodromy(hb, omega)?;
            let near = (s.critical.norm() - 1.0).abs() < opts.hill_band;
            let changed = prev_stab.is_some_and(|p| p.kind != s.kind);
            if near || changed || fold {
                s = hill(hb, omega)?;
                frc.hill_calls += 1;
            }
            prev_stab = Some(s);
            Some(s)
        } else {
            None
        };
        frc.points.push(FrcPoint {
            omega,
            norm: hb.complex_norm(&a),
            stability,
            iterations,
            a: a.clone(),
        });
        if landed || (omega - omega_to) * dir >= 0.0 {
            frc.stop = StopReason::ReachedEnd;
            break;
        }
        if frc.points.len() >= opts.max_points {
            break;
        }
        // Predictor–corrector with step halving. The chord corrector reuses the
        // tangent's factorization (no new LU); full Newton is the fallback.
        let mut chord_ok = true;
        loop {
            for i in 0..n {
                u_pred[i] = a[i] + step * tangent[i];
            }
            u_pred[n] = omega + step * tangent[n];
            // Land exactly on the end frequency when the step would pass it.
            let clip =
                ((u_pred[n] - omega_to) * dir > 0.0 && tangent[n] * dir > 0.0).then_some(omega_to);
            let chord = if chord_ok {
                correct_chord(hb, &mut aug, &u_pred, &tangent, clip, opts).ok()
            } else {
                None
            };
            let attempt = match chord {
                Some((u, its)) => Ok((u, its, its <= 6, its >= 12)),
                None => {
                    chord_ok = false;
                    correct(hb, &mut aug, &mut jac, &u_pred, &tangent, clip, opts).map(
                        |(u, its)| {
                            factorizations += its;
                            (u, its, its <= 3, its >= 6)
                        },
                    )
                }
            };
            match attempt {
                Ok((u, its, easy, hard)) => {
                    landed = clip.is_some();
                    a.copy_from_slice(&u[..n]);
                    omega = u[n];
                    iterations = its;
                    if easy {
                        step = (step * 1.5).min(opts.step_max);
                    } else if hard {
                        step *= 0.7;
                    }
                    break;
                }
                Err(e) => {
                    step *= 0.5;
                    if step < opts.step_min {
                        return Err(SthbError::Stalled {
                            omega,
                            step,
                            cause: Box::new(e),
                        });
                    }
                }
            }
        }
    }
    frc.factorizations = factorizations;
    Ok(frc)
}

fn fill_augmented(m: &mut Mat<f64>, jac: &Mat<f64>, r_w: &[f64], tangent: &[f64]) {
    let n = jac.nrows();
    for j in 0..n {
        for i in 0..n {
            m[(i, j)] = jac[(i, j)];
        }
        m[(j, n)] = r_w[j];
        m[(n, j)] = tangent[j];
    }
    m[(n, n)] = tangent[n];
}

/// Chord corrector: the residual of `[R(u); tᵀ(u − u_pred)]` (or `ω − ω_fix`)
/// solved with the factorization already in `aug` (the tangent system). Fails
/// fast when the contraction is worse than ½ per iteration.
fn correct_chord(
    hb: &mut StringHb,
    aug: &mut LuWorkspace,
    u_pred: &[f64],
    tangent: &[f64],
    fix_omega: Option<f64>,
    opts: &ContinuationOptions,
) -> Result<(Vec<f64>, usize), SthbError> {
    let n = hb.dim();
    let mut u = u_pred.to_vec();
    if let Some(w) = fix_omega {
        u[n] = w;
    }
    let mut rhs = vec![0.0; n + 1];
    let target = opts.tol * (1.0 + hb.params().y0.abs());
    let mut history: Vec<f64> = Vec::new();
    for it in 0..=3 * opts.max_corrector {
        let omega = u[n];
        hb.residual(&u[..n], omega, &mut rhs[..n]);
        rhs[n] = match fix_omega {
            Some(w) => u[n] - w,
            None => (0..=n).map(|i| tangent[i] * (u[i] - u_pred[i])).sum(),
        };
        let norm = norm2(&rhs);
        history.push(norm);
        if !norm.is_finite() {
            return Err(SthbError::NonFinite { omega });
        }
        if norm <= target {
            return Ok((u, it));
        }
        if it >= 1 && norm > 0.5 * history[it - 1] {
            break;
        }
        aug.solve(&mut rhs);
        for (x, d) in u.iter_mut().zip(&rhs) {
            *x -= d;
        }
    }
    Err(SthbError::NoConvergence {
        method: "chord corrector",
        omega: u[n],
        history,
    })
}

/// Newton corrector on `[R(u); tᵀ(u − u_pred)] = 0`, or on `[R(u); ω − ω_fix] = 0`
/// when `fix_omega` is given. Returns the point and the iteration count.
fn correct(
    hb: &mut StringHb,
    aug: &mut LuWorkspace,
    jac: &mut Mat<f64>,
    u_pred: &[f64],
    tangent: &[f64],
    fix_omega: Option<f64>,
    opts: &ContinuationOptions,
) -> Result<(Vec<f64>, usize), SthbError> {
    let n = hb.dim();
    let mut u = u_pred.to_vec();
    if let Some(w) = fix_omega {
        u[n] = w;
    }
    let mut row = tangent.to_vec();
    if fix_omega.is_some() {
        row.fill(0.0);
        row[n] = 1.0;
    }
    let (mut r, mut r_w, mut rhs) = (vec![0.0; n], vec![0.0; n], vec![0.0; n + 1]);
    let target = opts.tol * (1.0 + hb.params().y0.abs());
    let mut history = Vec::new();
    for it in 0..=opts.max_corrector {
        let omega = u[n];
        hb.residual_jacobian(&u[..n], omega, &mut r, jac);
        let constraint = match fix_omega {
            Some(w) => u[n] - w,
            None => (0..=n).map(|i| tangent[i] * (u[i] - u_pred[i])).sum(),
        };
        let norm = norm2(&r).hypot(constraint);
        history.push(norm);
        if !norm.is_finite() {
            return Err(SthbError::NonFinite { omega });
        }
        if norm <= target {
            return Ok((u, it));
        }
        if it == opts.max_corrector || (it >= 2 && norm > history[it - 1]) {
            break;
        }
        hb.d_residual_d_omega(&u[..n], omega, &mut r_w);
        fill_augmented(&mut aug.mat, jac, &r_w, &row);
        if !aug.factor() {
            return Err(SthbError::Singular { omega });
        }
        rhs[..n].copy_from_slice(&r);
        rhs[n] = constraint;
        aug.solve(&mut rhs);
        for (x, d) in u.iter_mut().zip(&rhs) {
            *x -= d;
        }
    }
    Err(SthbError::NoConvergence {
        method: "arclength corrector",
        omega: u[n],
        history,
    })
}
