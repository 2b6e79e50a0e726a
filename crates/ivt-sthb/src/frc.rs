//! Frequency–response curves ‖a‖(ω) of the string (Figs. 34–36): the STHB
//! residual followed in ω by the engine's exact-Jacobian pseudo-arclength
//! ([`NewtonCorrector`], Eq. 68–77 with the exact `J` of Eq. 115–125),
//! with a stability verdict per point.
//!
//! Stability per point: the RK4 monodromy matrix (cheap, `O(N³)` per step);
//! Hill's method (Eq. 126–131) confirms where a multiplier is within
//! [`StringFrcOptions::hill_band`] of the unit circle, where the verdict
//! changes, or where `dω/ds` changes sign (a fold) — while its matrix has at
//! most [`HILL_MAX_DIM`] rows; above that the confirmation is the monodromy
//! with half the step ([`monodromy_refined`]), whose Richardson error estimate
//! is the point's `multiplier_error`.

use super::reduced::ReducedString;
use super::stability::{
    hill, hill_dim, monodromy, monodromy_refined, Stability, StabilityMethod, HILL_MAX_DIM,
};
use super::StringHb;
use ivt_hb::branches::events::{
    observe, BifurcationKind, Detector, EventObserver, Fold, LocateOptions, Observer,
};
use ivt_hb::branches::frc::{Frc, FrcFold, FrcPoint};
use ivt_hb::HbError;
use ivt_num::BroydenOptions;
use ivt_path::branch::Branch;
use ivt_path::continuation::{
    ContinuationOptions, NewtonCorrector, Path, PathPoint, Stepper, Termination,
};
use ivt_path::events::Event;

/// Settings of a string curve.
#[derive(Clone, Debug, PartialEq)]
pub struct StringFrcOptions {
    /// Path following (λ = ω; its bounds are set from the sweep). The tolerance
    /// `broyden.tol` is relative to the forcing, `‖R‖ ≤ tol (1 + |y0|)`, and
    /// `broyden.max_iter` bounds the Newton corrector.
    pub continuation: ContinuationOptions,
    /// Confirm by Hill when `| |μ| − 1 | <` this.
    pub hill_band: f64,
}

impl Default for StringFrcOptions {
    fn default() -> Self {
        Self {
            // Steps up to 0.05 in (a, ω) give 173 points over 1 ≤ ω ≤ 6 (k_d = 10)
            // with one factorization per point on the flanks.
            continuation: ContinuationOptions {
                ds: 0.02,
                ds_min: 1e-6,
                ds_max: 0.05,
                max_points: 2000,
                target_iter: 12,
                broyden: BroydenOptions {
                    tol: 1e-10,
                    max_iter: 8,
                    ..BroydenOptions::default()
                },
                ..ContinuationOptions::default()
            },
            hill_band: 0.02,
        }
    }
}

/// A string curve in the engine's [`Frc`] form, with how it was obtained.
///
/// `FrcPoint::amplitude` is `‖a‖`, the Euclidean norm of the complex
/// coefficients (Eq. 114, the ordinate of Figs. 34–36); `multipliers` are those
/// of the method in `methods`, decreasing modulus, and `multiplier_error` the
/// Richardson estimate of a [`StabilityMethod::MonodromyRefined`] verdict
/// (`None` otherwise); each turn of the path is
/// located as the points arrive by Newton on the bordered fold system
/// ([`ivt_hb::locate_fold`], exact `J`),
/// `located = false` leaving the parabola through the points around the turn.
#[derive(Clone, Debug)]
pub struct StringFrc {
    /// The curve.
    pub frc: Frc,
    /// The method behind each point's verdict.
    pub methods: Vec<StabilityMethod>,
    /// Jacobian assemblies: the full ones of the start's Newton, then those of
    /// the branch's invariant-subspace block (`sthb::reduced`; most followed by
    /// one LU).
    pub jacobians: usize,
    /// How many points Hill's method assessed.
    pub hill_calls: usize,
}

/// The error of a path point without the `n` coefficients before its ω (the
/// continuation makes none: every point holds `[a, ω]`).
fn empty_point() -> HbError {
    HbError::InvalidInput("a path point lacks its coefficients".into())
}

/// The coefficients `a` of a path point `[a, ω]` with `n` of them.
///
/// # Errors
/// [`HbError::InvalidInput`] if the point holds fewer than `n + 1` values.
pub(super) fn coefficients(p: &PathPoint, n: usize) -> Result<&[f64], HbError> {
    p.x.get(..n)
        .filter(|_| p.x.len() > n)
        .ok_or_else(empty_point)
}

/// Follows the branch of periodic responses from `omega_from` to `omega_to`
/// (either direction), starting from rest at `omega_from`, calling `on_point`
/// with the problem linearized at each point; with `folds`, each fold is
/// located as the points arrive ([`Fold`] in an [`EventObserver`], on the
/// reduced branch, its `q` embedded back). Returns the path, its events and
/// the Jacobian count of the path (the fold locations' own assemblies not
/// counted).
fn follow<C>(
    hb: &mut StringHb,
    (omega_from, omega_to): (f64, f64),
    opts: &ContinuationOptions,
    folds: bool,
    on_point: C,
) -> Result<(Path, Vec<Event<HbError>>, usize), HbError>
where
    C: FnMut(&mut ReducedString<'_>, &PathPoint) -> bool,
{
    if !(omega_from.is_finite() && omega_to.is_finite() && omega_from > 0.0 && omega_to > 0.0) {
        return Err(HbError::InvalidInput(format!(
            "frequencies must be positive: {omega_from:?} .. {omega_to:?}"
        )));
    }
    let tol = opts.broyden.tol;
    let mut start = vec![0.0; hb.dim()];
    let first = hb
        .solve(omega_from, &mut start, tol, 50)
        .map_err(|e| match e {
            HbError::NoConvergence { .. } => HbError::ColdStart {
                omega: omega_from,
                cause: Box::new(e),
            },
            e => e,
        })?;
    // The branch lives in the invariant subspace (`reduced`): trace it there.
    let mut system = ReducedString::new(hb);
    let mut reduced = vec![0.0; system.sub.dim()];
    system.sub.gather(&start, &mut reduced);
    reduced.push(omega_from);
    let mut copts = opts.clone();
    copts.broyden.tol = tol * (1.0 + system.hb.params().y0.abs());
    copts.lambda_min = omega_from.min(omega_to);
    copts.lambda_max = omega_from.max(omega_to);
    let direction = if omega_to >= omega_from { 1.0 } else { -1.0 };
    let detectors: Vec<Box<dyn Detector<ReducedString<'_>, HbError>>> = if folds {
        vec![Box::new(Fold)]
    } else {
        Vec::new()
    };
    let mut observer = Counted {
        observer: EventObserver::new(&LocateOptions::fold(), detectors),
        jacobians: 0,
    };
    let m_len = system.len();
    let mut stepper = Stepper::new(
        &mut system,
        Box::new(NewtonCorrector::new(m_len, &copts)),
        &reduced,
        first.iterations,
        direction,
        &copts,
    )?;
    let (mut path, mut events) = observe(&mut stepper, &mut observer, on_point)?;
    drop(stepper);
    if let Termination::StepTooSmall(e) = &path.termination {
        return Err(HbError::Stalled {
            omega: path.points.last().map_or(omega_from, PathPoint::lambda),
            step: copts.ds_min,
            cause: Box::new(HbError::Solve(e.clone())),
        });
    }
    // Back to the full coefficients (zeros outside the subspace), then ω.
    let n = system.hb.dim();
    for p in &mut path.points {
        let Some((&omega, reduced)) = p.x.split_last() else {
            return Err(empty_point());
        };
        let mut full = vec![0.0; n + 1];
        let (coeffs, last) = full.split_at_mut(n);
        system.sub.embed(reduced, coeffs);
        last.fill(omega);
        p.x = full;
    }
    for located in events.iter_mut().filter_map(|e| e.location.as_mut().ok()) {
        let mut full = vec![0.0; n];
        system.sub.embed(&located.q, &mut full);
        located.q = full;
    }
    // `solve` assembles once more than it iterates (the converged check).
    let jacobians = first.iterations + 1 + system.jacobians - observer.jacobians;
    Ok((path, events, jacobians))
}

/// An observer with the Jacobian assemblies it makes (the fold locations),
/// so that the path's count leaves them out.
struct Counted<O> {
    observer: O,
    jacobians: usize,
}

impl<'a, O: Observer<ReducedString<'a>>> Observer<ReducedString<'a>> for Counted<O> {
    type Error = O::Error;

    fn on_point(
        &mut self,
        branch: &mut ReducedString<'a>,
        point: &PathPoint,
    ) -> Result<Vec<Event<O::Error>>, O::Error> {
        let before = branch.jacobians;
        let found = self.observer.on_point(branch, point);
        self.jacobians += branch.jacobians - before;
        found
    }

    fn finish(&mut self, branch: &mut ReducedString<'a>) -> Result<Vec<Event<O::Error>>, O::Error> {
        let before = branch.jacobians;
        let found = self.observer.finish(branch);
        self.jacobians += branch.jacobians - before;
        found
    }
}

/// The path from `omega_from` to `omega_to` without stability (`x` = coefficients
/// then ω; ‖a‖ by [`StringHb::complex_norm`]).
///
/// # Errors
/// [`HbError::ColdStart`] if the first solve fails, [`HbError::Stalled`]
/// if the step falls below `ds_min`, [`HbError::InvalidInput`] for bad frequencies.
pub fn trace(
    hb: &mut StringHb,
    omega_from: f64,
    omega_to: f64,
    opts: &ContinuationOptions,
) -> Result<Path, HbError> {
    Ok(follow(hb, (omega_from, omega_to), opts, false, |_, _| true)?.0)
}

/// The curve from `omega_from` to `omega_to` with a stability verdict per point.
///
/// # Errors
/// As [`trace`], or a stability failure ([`HbError::Eigen`]).
pub fn frequency_response(
    hb: &mut StringHb,
    omega_from: f64,
    omega_to: f64,
    opts: &StringFrcOptions,
) -> Result<StringFrc, HbError> {
    // Each point's verdict with the error estimate of a refined monodromy.
    let mut verdicts: Vec<(Stability, Option<f64>)> = Vec::new();
    let mut hill_calls = 0;
    let mut failure = None;
    let mut prev_dlambda = if omega_to >= omega_from { 1.0 } else { -1.0 };
    let span = (omega_from, omega_to);
    let (path, events, jacobians) = follow(hb, span, &opts.continuation, true, |sys, p| {
        let omega = p.lambda();
        let fold = p.dlambda.signum() != f64::signum(prev_dlambda);
        prev_dlambda = p.dlambda;
        let verdict = monodromy(sys.hb, omega).and_then(|s| {
            let near = (s.critical().norm() - 1.0).abs() < opts.hill_band;
            let changed = verdicts.last().is_some_and(|v| v.0.kind != s.kind);
            if !(near || changed || fold) {
                Ok((s, None))
            } else if hill_dim(sys.hb) <= HILL_MAX_DIM {
                hill_calls += 1;
                hill(sys.hb, omega).map(|h| (h, None))
            } else {
                monodromy_refined(sys.hb, omega, &s).map(|(f, e)| (f, Some(e)))
            }
        });
        match verdict {
            Ok(s) => {
                verdicts.push(s);
                true
            }
            Err(e) => {
                failure = Some(e);
                false
            }
        }
    })?;
    if let Some(e) = failure {
        return Err(e);
    }
    let n = hb.dim();
    let methods = verdicts.iter().map(|s| s.0.method).collect();
    let points = path
        .points
        .iter()
        .zip(verdicts)
        .map(|(p, (s, error))| {
            let coeffs = coefficients(p, n)?;
            Ok(FrcPoint {
                omega_f: p.lambda(),
                amplitude: hb.complex_norm(coeffs),
                kind: s.kind,
                multipliers: s.multipliers,
                multiplier_error: error,
                coeffs: coeffs.to_vec(),
            })
        })
        .collect::<Result<Vec<_>, HbError>>()?;
    let folds = events
        .iter()
        .filter(|e| e.kind == BifurcationKind::Fold)
        .map(|e| {
            let near = points.get(e.index).ok_or_else(empty_point)?;
            Ok(match &e.location {
                Ok(loc) => FrcFold {
                    index: e.index,
                    omega_f: loc.lambda,
                    amplitude: hb.complex_norm(&loc.q),
                    coeffs: loc.q.clone(),
                    located: true,
                },
                // Not located: the parabola's ω through the points around
                // the turn (the stepper's estimate).
                Err(_) => FrcFold {
                    index: e.index,
                    omega_f: path
                        .events
                        .iter()
                        .find(|f| f.index == e.index)
                        .map_or(near.omega_f, |f| f.lambda),
                    amplitude: near.amplitude,
                    coeffs: near.coeffs.clone(),
                    located: false,
                },
            })
        })
        .collect::<Result<_, HbError>>()?;
    Ok(StringFrc {
        frc: Frc {
            points,
            events: folds,
            termination: path.termination,
        },
        methods,
        jacobians,
        hill_calls,
    })
}
