//! A branch of a [`Family`] followed by pseudo-arclength continuation (Eq. 68–77)
//! with the Floquet multipliers (Hsu, Eq. 80) at every point, its events detected
//! between consecutive points and each located by its extended system
//! ([`crate::bifurcation`], [`crate::fold`]):
//!
//! - fold: the λ component of the secant changes sign;
//! - period doubling: `Π(μᵢ + 1)` changes sign (a real μ crosses −1);
//! - Neimark–Sacker: `Πᵢ<ⱼ(μᵢμⱼ − 1)` changes sign with a complex pair present;
//! - branch point: `det [[R_q, R_λ], [tᵀ]]` changes sign (it keeps its sign
//!   through a fold, where only `det R_q` does).

use crate::bifurcation::{
    finish, jacobian_blocks, locate_multiplier_crossing, Bifurcation, BifurcationError,
    BifurcationKind, BifurcationOptions, Monodromy,
};
use crate::branch_point::locate_branch_point;
use crate::continuation::{ContinuationOptions, Corrector, Termination};
use crate::family::{Family, FamilyBranch};
use crate::fold::{locate_fold, Branch, FoldOptions};
use crate::ihb::HbError;
use crate::stability::{AdaptiveHsu, HsuSteps, StabilityKind};
use faer::c64;

/// Options of [`trace`].
#[derive(Debug, Clone, PartialEq)]
pub struct TraceOptions {
    /// End of the parameter interval (the path stops once it leaves
    /// `[min(λ₀, lambda_to), max(λ₀, lambda_to)]`).
    pub lambda_to: f64,
    /// Path following (its λ bounds are set from λ₀ and `lambda_to`).
    pub continuation: ContinuationOptions,
    /// Hsu sub-intervals of the path points' multipliers (by default chosen
    /// per point for multipliers to 1e-6).
    pub stability: HsuSteps,
    /// Options of the located events.
    pub locate: BifurcationOptions,
    /// The path's corrector ([`Corrector::Broyden`] by default).
    pub corrector: Corrector,
}

impl Default for TraceOptions {
    fn default() -> Self {
        Self {
            lambda_to: 1.0,
            continuation: ContinuationOptions::default(),
            stability: HsuSteps::default(),
            locate: BifurcationOptions::default(),
            corrector: Corrector::Broyden,
        }
    }
}

/// One point of the traced branch.
#[derive(Debug, Clone, PartialEq)]
pub struct TracedPoint {
    /// Fourier coefficients.
    pub q: Vec<f64>,
    /// Parameter λ.
    pub lambda: f64,
    /// Floquet multipliers (Hsu), decreasing modulus.
    pub multipliers: Vec<c64>,
    /// Error estimate of their monodromy ([`crate::HsuEstimate::error`]):
    /// `None` for fixed Hsu steps.
    pub multiplier_error: Option<f64>,
    /// Stability class.
    pub kind: StabilityKind,
}

/// An event between points `index` and `index + 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// What changed.
    pub kind: BifurcationKind,
    /// The point before the change (the Newton start).
    pub index: usize,
    /// The located bifurcation, or why it could not be located.
    pub location: Result<Bifurcation, BifurcationError>,
}

/// A traced branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// Points in path order.
    pub points: Vec<TracedPoint>,
    /// Events in path order.
    pub events: Vec<Event>,
    /// Why the path stopped.
    pub termination: Termination,
}

/// Follows `branch` from the orbit `q0` at `lambda0` (corrected first) towards
/// `opts.lambda_to`, with multipliers at every point, and locates its events.
///
/// # Errors
/// [`BifurcationError::Hb`] if the start cannot be used; events that cannot be
/// located carry their error in [`Event::location`].
pub fn trace<F: Family>(
    branch: &mut FamilyBranch<F>,
    q0: &[f64],
    lambda0: f64,
    opts: &TraceOptions,
) -> Result<Trace, BifurcationError> {
    let m = branch.len();
    if q0.len() != m || !opts.lambda_to.is_finite() || opts.lambda_to == lambda0 {
        return Err(HbError::InvalidInput(format!(
            "start must have {m} entries and lambda_to be finite and differ from λ₀"
        ))
        .into());
    }
    let mut x0 = q0.to_vec();
    x0.push(lambda0);
    let mut copts = opts.continuation.clone();
    copts.lambda_min = lambda0.min(opts.lambda_to);
    copts.lambda_max = lambda0.max(opts.lambda_to);
    let mut hsu = AdaptiveHsu::new(
        &branch.family().at(lambda0).0,
        branch.options().harmonics,
        opts.stability,
    )?;
    let mut points = Vec::new();
    let mut failed = None;
    // Multipliers as each point is reached (see `frequency_response`: where
    // the last Galerkin assembly is the point's, Hsu takes its ∂g samples).
    let stepper = branch.stepper(&x0, 0, opts.lambda_to - lambda0, &copts, opts.corrector)?;
    let path = stepper.run(|branch, p| {
        if failed.is_some() {
            return false;
        }
        let (q, lambda) = (&p.x[..m], p.lambda());
        let (problem, sol) = branch.solution(q, lambda);
        let known = branch.jacobian_samples_at(&p.x);
        match hsu.floquet_with_samples(&problem, &sol, known) {
            Ok(fl) => points.push(TracedPoint {
                q: q.to_vec(),
                lambda,
                multipliers: fl.floquet.multipliers,
                multiplier_error: fl.error,
                kind: fl.floquet.kind,
            }),
            Err(e) => failed = Some(e),
        }
        true
    });
    if let Some(e) = failed {
        return Err(e.into());
    }
    let mut bp_signs = Vec::with_capacity(path.points.len());
    let xs: Vec<&[f64]> = path.points.iter().map(|p| p.x.as_slice()).collect();
    for (k, x) in xs.iter().enumerate() {
        let (q, lambda) = (&x[..m], x[m]);
        // The exact corrector's tangent LU carries the sign; Broyden's path
        // has no factored bordered matrix, so it is assembled here.
        bp_signs.push(match path.points[k].bordered_sign {
            Some(sign) => sign,
            None => {
                secant(&xs, k).map_or(0.0, |t| augmented_sign(branch, q, lambda, &t, &opts.locate))
            }
        });
    }
    let mut events = Vec::new();
    let fold_at: Vec<usize> = path.folds.iter().map(|f| f.index).collect();
    for k in 0..points.len().saturating_sub(1) {
        let (a, b) = (&points[k], &points[k + 1]);
        let flipped = |f: fn(&[c64]) -> f64| f(&a.multipliers) * f(&b.multipliers) < 0.0;
        let complex = |p: &TracedPoint| p.multipliers.iter().any(|z| z.im.abs() > 1e-7 * z.norm());
        let mut found = Vec::new();
        if fold_at.contains(&k) {
            found.push(BifurcationKind::Fold);
        }
        if flipped(pd_indicator) {
            found.push(BifurcationKind::PeriodDoubling);
        }
        if flipped(ns_indicator) && (complex(a) || complex(b)) {
            found.push(BifurcationKind::NeimarkSacker);
        }
        if bp_signs[k] * bp_signs[k + 1] < 0.0 {
            found.push(BifurcationKind::BranchPoint);
        }
        for kind in found {
            let location = locate(branch, kind, &xs, k, opts);
            events.push(Event {
                kind,
                index: k,
                location,
            });
        }
    }
    Ok(Trace {
        points,
        events,
        termination: path.termination,
    })
}

fn locate<F: Family>(
    branch: &mut FamilyBranch<F>,
    kind: BifurcationKind,
    xs: &[&[f64]],
    k: usize,
    opts: &TraceOptions,
) -> Result<Bifurcation, BifurcationError> {
    let m = branch.len();
    let (q, lambda) = (&xs[k][..m], xs[k][m]);
    match kind {
        BifurcationKind::Fold => {
            let fold_opts = FoldOptions {
                max_iter: opts.locate.max_iter,
                ..FoldOptions::default()
            };
            let f = locate_fold(branch, q, lambda, &fold_opts)?;
            let mut mono = Monodromy::new(branch, f.lambda, opts.locate.stability_steps)?;
            let multipliers = mono.multipliers(branch, &f.q, f.lambda);
            finish(
                branch,
                kind,
                f.q,
                f.lambda,
                multipliers,
                Vec::new(),
                f.iterations,
            )
        }
        BifurcationKind::BranchPoint => {
            let t = secant(xs, k + 1).expect("two points");
            locate_branch_point(branch, q, lambda, &t, &opts.locate)
        }
        _ => locate_multiplier_crossing(branch, kind, q, lambda, &opts.locate),
    }
}

/// Unit secant into point `k` (out of point 0 for `k = 0`).
fn secant(xs: &[&[f64]], k: usize) -> Option<Vec<f64>> {
    let (a, b) = if k == 0 {
        (xs.first()?, xs.get(1)?)
    } else {
        (&xs[k - 1], &xs[k])
    };
    let mut t: Vec<f64> = b.iter().zip(a.iter()).map(|(p, q)| p - q).collect();
    let n = t.iter().map(|v| v * v).sum::<f64>().sqrt();
    t.iter_mut().for_each(|v| *v /= n);
    Some(t)
}

/// `Re Π(μᵢ + 1)`: changes sign when a real multiplier crosses −1.
fn pd_indicator(mu: &[c64]) -> f64 {
    mu.iter().fold(c64::new(1.0, 0.0), |a, z| a * (z + 1.0)).re
}

/// `Re Πᵢ<ⱼ(μᵢμⱼ − 1)`: changes sign when a pair's product crosses 1.
fn ns_indicator(mu: &[c64]) -> f64 {
    let mut p = c64::new(1.0, 0.0);
    for i in 0..mu.len() {
        for j in i + 1..mu.len() {
            p *= mu[i] * mu[j] - 1.0;
        }
    }
    p.re
}

/// Sign of `det [[R_q, R_λ], [tᵀ]]` (rows scaled to unit max so the
/// determinant stays in range).
fn augmented_sign<F: Family>(
    branch: &mut FamilyBranch<F>,
    q: &[f64],
    lambda: f64,
    t: &[f64],
    opts: &BifurcationOptions,
) -> f64 {
    let m = q.len();
    let n1 = m + 1;
    let (jac, r_lambda) = jacobian_blocks(branch, q, lambda, opts);
    let mut aug = faer::Mat::<f64>::zeros(n1, n1);
    for i in 0..n1 {
        let row: Vec<f64> = if i < m {
            jac[i * m..(i + 1) * m]
                .iter()
                .copied()
                .chain([r_lambda[i]])
                .collect()
        } else {
            t.to_vec()
        };
        let scale = row
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        for (j, v) in row.iter().enumerate() {
            aug[(i, j)] = v / scale;
        }
    }
    aug.determinant().signum()
}
