//! The limit cycles born at a Hopf point, followed in the parameter
//! (issue 27, item 2): [`cycle_branch`] finds the Hopf points of the
//! equilibria of an autonomous family ([`crate::stability::hopf`]), starts the cycle
//! branch from the first one by its normal form, and follows it with
//! [`crate::limit_cycle_branch`] (HB with ω unknown and the phase condition
//! b₁ = 0, Eq. 61, pseudo-arclength Eq. 68–77) with Floquet stability at every
//! point; its folds (turning points in p) are located as the points arrive,
//! by the [`Fold`] detector: Newton on the fold system of the cycle equations
//! ([`crate::locate_fold`]); so are the cycles at the requested values of p
//! ([`Crossing`]: Newton at that p from the two points around it).
//!
//! The start: with the normal form `ż = (β(p) + iω) z + c₁ z|z|²`
//! (`β = Re λ`, `l₁ = Re c₁/ω`) the cycle at p has `|z|² = −β/(ω l₁)` and
//! `y(t) ≈ y* + 2 Re(z e^{iωt} q)`, on the side of p where `−β/l₁ > 0`; it is
//! taken at `p_H ± offset·|p_to − p_from|` and refined by [`limit_cycle`].

use crate::branches::autonomous::{limit_cycle, limit_cycle_leg, LimitCycle};
use crate::branches::events::{
    name_family_failures, BifurcationKind, Detector, EventObserver, Fold, LocateOptions, Observer,
    Unlocated,
};
use crate::error::HbError;
use crate::orbit::galerkin::GalerkinJacobian;
use crate::orbit::ihb::{HbOptions, HbResidual, HbSolution};
use crate::problem::{BoxedFamily, PeriodicProblem};
use crate::stability::hopf::{equilibrium, hopf_points, Field, HopfPoint, Undecided};
use crate::BroydenStats;
use ivt_num::vector::norm2;
use ivt_path::branch::Branch;
use ivt_path::continuation::{ContinuationOptions, PathPoint, Termination};
use ivt_path::events::Crossing;

pub(crate) mod member;
use member::{Failures, Member};

/// Options of [`cycle_branch`].
#[derive(Debug, Clone, PartialEq)]
pub struct CycleBranchOptions {
    /// Intervals of the grid of p on which the equilibria are followed and
    /// Hopf points bracketed.
    pub samples: usize,
    /// The start's distance from the Hopf point, relative to `|p_to − p_from|`.
    pub offset: f64,
    /// Path-following options of the cycle branch (λ bounds are set).
    pub continuation: ContinuationOptions,
    /// Hsu sub-intervals of each cycle's multipliers (> n).
    pub stability_steps: usize,
    /// Values of p at which the cycles are solved exactly (each crossing).
    pub at: Vec<f64>,
}

impl Default for CycleBranchOptions {
    fn default() -> Self {
        Self {
            samples: 100,
            offset: 1e-2,
            continuation: ContinuationOptions {
                ds: 0.02,
                ds_max: 0.05,
                max_points: 2000,
                ..ContinuationOptions::default()
            },
            stability_steps: 512,
            at: Vec::new(),
        }
    }
}

/// The cycle branch of a family.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleBranch {
    /// Hopf points of the equilibria in `[p_from, p_to]`, in order of p
    /// from `p_from`.
    pub hopf: Vec<HopfPoint>,
    /// Stretches of p where the Hopf search could not decide
    /// ([`hopf_points`]).
    pub undecided: Vec<Undecided>,
    /// `(p, cycle)` of the branch from the first Hopf point, in path order.
    pub points: Vec<(f64, LimitCycle)>,
    /// Folds of the branch: `(p, orbit)` located on the fold system.
    pub folds: Vec<(f64, HbSolution)>,
    /// The cycles at each p of [`CycleBranchOptions::at`], each crossing.
    pub at: Vec<(f64, LimitCycle)>,
    /// The folds and `at` cycles the path passed but that could not be
    /// located, near `(p, orbit)` (the path point the locator started
    /// from), in path order; then the `at` cycles located but not refined
    /// by [`limit_cycle`]. Each with the reason.
    pub unlocated: Vec<Unlocated<(f64, HbSolution)>>,
    /// Why tracing stopped (`None`: no Hopf point, nothing traced).
    pub termination: Option<Termination>,
}

/// The Hopf points of `family(p)` (autonomous: no excitation) for p in
/// `[p_from, p_to]` (equilibria followed from `x = 0`), and the cycle
/// branch of the first, with its folds (module docs).
///
/// # Errors
/// [`HbError::InvalidInput`] for bounds, options or sizes, a forced family
/// ([`crate::branches::autonomous::require_autonomous`]); `family(p_from)`'s error;
/// the start cycle's failure ([`limit_cycle`]). Later, a `p` where `family`
/// fails is a failed step of the path; when the path stalls on such steps
/// (the family's error, a member of another size, a `g` that is NaN or ±∞
/// at a finite state) that cause is the error, not a `step_too_small` end.
///
/// `family` is any `p ↦ problem` with its members boxed: `&boxed_family(f)`
/// ([`crate::problem::boxed_family`]), so this body is compiled once for
/// every model.
pub fn cycle_branch(
    family: &BoxedFamily<'_, '_>,
    hb: &HbOptions,
    p_from: f64,
    p_to: f64,
    opts: &CycleBranchOptions,
) -> Result<CycleBranch, HbError> {
    if !(opts.offset > 0.0 && opts.offset < 1.0) {
        return Err(HbError::InvalidInput("offset must lie in (0, 1)".into()));
    }
    let first_member = family(p_from)?;
    crate::branches::autonomous::require_autonomous(&first_member, "cycle_branch")?;
    let n_dof = first_member.n_dof();
    let search = hopf_points(&family, &vec![0.0; n_dof], p_from, p_to, opts.samples)?;
    let mut out = CycleBranch {
        hopf: search.points,
        undecided: search.undecided,
        points: Vec::new(),
        folds: Vec::new(),
        at: Vec::new(),
        unlocated: Vec::new(),
        termination: None,
    };
    let Some(first) = out.hopf.first() else {
        return Ok(out);
    };
    let (lo, hi) = (p_from.min(p_to), p_from.max(p_to));
    let (p_start, start) = start_cycle(&family, hb, first, opts.offset * (hi - lo), opts)?;
    let failures = Failures::default();
    let member = |p: f64| Member::new(family(p), n_dof, p, Some(&failures));
    // Each fold (a turn in p) and each cycle at a value of `at` is located
    // as the points arrive: the [`Fold`] and [`Crossing`] detectors on the
    // cycle equations ([`CycleSystem`], unknowns {q, ω}).
    let mut system = CycleSystem::new(&member, hb, p_start)?;
    let p_index = system.len();
    let scale = norm2(&start.solution.coeffs);
    let mut detectors: Vec<Box<dyn Detector<_, _>>> = vec![Box::new(Fold)];
    for &p in &opts.at {
        detectors.push(Box::new(Crossing::scaled(p_index, p, scale)));
    }
    let mut observer = EventObserver::new(&LocateOptions::fold(), detectors);
    let (mut events, mut failure) = (Vec::new(), None);
    // The observed points (an event's index is one of them).
    let mut seen: Vec<Vec<f64>> = Vec::new();
    let mut watch = |p: &PathPoint| {
        seen.push(p.x.clone());
        match observer.on_point(&mut system, p) {
            Ok(found) => {
                failures.clear();
                events.extend(found);
                true
            }
            Err(e) => {
                failure = Some(e);
                false
            }
        }
    };
    // First away from the Hopf point; if the branch turns back past the
    // start, on to the other end.
    let far = if p_start > first.p { hi } else { lo };
    let steps = opts.stability_steps;
    let span = (p_start, far);
    let leg = limit_cycle_leg(
        member,
        hb,
        &start,
        span,
        &opts.continuation,
        steps,
        &mut watch,
    )?;
    stalled_by(&leg.termination, &failures)?;
    out.points = leg.points;
    out.termination = Some(leg.termination);
    let back = out.points.last().map(|(p, c)| (*p, c.clone()));
    if let Some((p_last, cycle)) = back {
        let other = if far == hi { lo } else { hi };
        if (p_last - p_start).abs() < (p_last - far).abs() && p_last != other {
            // The leg's first point is the last one observed.
            let mut joined = false;
            let on_point = |p: &PathPoint| !std::mem::replace(&mut joined, true) || watch(p);
            let span = (p_last, other);
            let leg = limit_cycle_leg(
                member,
                hb,
                &cycle,
                span,
                &opts.continuation,
                steps,
                on_point,
            )?;
            stalled_by(&leg.termination, &failures)?;
            out.points.extend(leg.points.into_iter().skip(1));
            out.termination = Some(leg.termination);
        }
    }
    if let Some(e) = failure {
        return Err(e);
    }
    events.extend(observer.finish(&mut system)?);
    events.sort_by_key(|e| e.index);
    // A located event's unknowns are `[q; ω]`, a path point's `[q; ω; p]`.
    let orbit = |u: &[f64]| {
        let (&omega_f, q) = u.split_last()?;
        Some(HbSolution {
            coeffs: q.to_vec(),
            omega_f,
            harmonics: hb.harmonics,
            subharmonic: 1,
            stats: BroydenStats::default(),
        })
    };
    let located = |e: &ivt_path::Event<HbError>| {
        let at = e.location.as_ref().ok()?;
        Some((at.lambda, orbit(&at.q)?))
    };
    // Detector 0 is the fold, detector d ≥ 1 the crossing of `at[d − 1]`.
    let sought = |d: usize| match d {
        0 => ("fold", None),
        _ => ("at", opts.at.get(d - 1).copied()),
    };
    for e in &events {
        let Err(err) = &e.location else { continue };
        let (what, value) = sought(e.detector);
        let near = seen.get(e.index).and_then(|x| {
            let (&p, u) = x.split_last()?;
            Some((p, orbit(u)?))
        });
        out.unlocated.extend(near.map(|near| Unlocated {
            what,
            value,
            near,
            reason: err.to_string(),
        }));
    }
    out.folds = (events.iter())
        .filter(|e| e.kind == BifurcationKind::Fold)
        .filter_map(located)
        .collect();
    // The cycles at `at`, value by value, each in path order, with their
    // multipliers (the located cycle refined by [`limit_cycle`]).
    for d in 1..=opts.at.len() {
        for (p, located) in events
            .iter()
            .filter(|e| e.detector == d)
            .filter_map(located)
        {
            match limit_cycle(&member(p), hb, located.omega_f, &located.coeffs, steps) {
                Ok(c) => out.at.push((p, c)),
                Err(e) => {
                    let (what, value) = sought(d);
                    out.unlocated.push(Unlocated {
                        what,
                        value,
                        near: (p, located),
                        reason: format!("the cycle located there was not refined: {e}"),
                    });
                }
            }
        }
    }
    name_family_failures(&mut out.unlocated, |p, _| family(p).err());
    Ok(out)
}

/// The kept cause of failed members when a leg ended by stalling on them
/// (module [`member`]).
fn stalled_by(termination: &Termination, failures: &Failures) -> Result<(), HbError> {
    match (termination, failures.take()) {
        (Termination::StepTooSmall(_), Some(cause)) => Err(cause),
        _ => Ok(()),
    }
}

/// The cycle near the Hopf point `hopf` at `p_H ± distance` by its normal
/// form, refined by [`limit_cycle`]: `(p, cycle)`.
fn start_cycle<P, F>(
    family: &F,
    hb: &HbOptions,
    hopf: &HopfPoint,
    distance: f64,
    opts: &CycleBranchOptions,
) -> Result<(f64, LimitCycle), HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError>,
{
    let n = hb.harmonics;
    let l = 2 * n + 1;
    for side in [-1.0, 1.0] {
        let Some((p, x, beta)) = near_pair(family, hopf, side, distance)? else {
            continue;
        };
        let radius2 = -beta / (hopf.omega * hopf.lyapunov);
        if !(radius2 > 0.0 && radius2.is_finite()) {
            continue;
        }
        let rho = radius2.sqrt();
        let [q_re, q_im] = &hopf.eigenvector;
        // Per DOF: a₀ = 2x*, a₁ = 2ρ Re q, b₁ = −2ρ Im q (the DOF rows of q).
        let mut guess = vec![0.0; x.len() * l];
        let dofs = x.iter().zip(q_re).zip(q_im);
        for (coeffs, ((xd, qr), qi)) in guess.chunks_exact_mut(l).zip(dofs) {
            let entries = [(0, 2.0 * xd), (1, 2.0 * rho * qr), (n + 1, -2.0 * rho * qi)];
            for (k, value) in entries {
                if let Some(c) = coeffs.get_mut(k) {
                    *c = value;
                }
            }
        }
        let cycle = limit_cycle(&family(p)?, hb, hopf.omega, &guess, opts.stability_steps)?;
        return Ok((p, cycle));
    }
    Err(HbError::InvalidInput(
        "no side of the Hopf point has cycles (l₁ = 0 or β does not change sign)".into(),
    ))
}

/// Most halvings of the start's distance from the Hopf point.
const MAX_HALVINGS: usize = 60;

/// The equilibrium and `β = Re λ` of the crossing pair at `p_H + side·d`,
/// with `d` halved from `distance` until the pair is complex there and
/// `|β| ≤ ω/20` (the normal form's range: on a wide interval `offset`·|p_to
/// − p_from| can reach where the pair has turned real): `(p, x, β)`, or
/// `None` if no such `d`.
fn near_pair<P, F>(
    family: &F,
    hopf: &HopfPoint,
    side: f64,
    distance: f64,
) -> Result<Option<(f64, Vec<f64>, f64)>, HbError>
where
    P: PeriodicProblem,
    F: Fn(f64) -> Result<P, HbError>,
{
    let mut d = distance;
    for _ in 0..MAX_HALVINGS {
        let p = hopf.p + side * d;
        d *= 0.5;
        let problem = family(p)?;
        let mut x = hopf.equilibrium.clone();
        if equilibrium(&problem, &mut x).is_err() {
            continue;
        }
        let dim = 2 * x.len();
        let beta =
            crate::stability::floquet::eigenvalues(&Field::new(&problem)?.linearisation(&x), dim)
                .iter()
                .filter(|e| e.im > 0.0)
                .min_by(|a, b| {
                    (a.im - hopf.omega)
                        .abs()
                        .total_cmp(&(b.im - hopf.omega).abs())
                })
                .map(|e| e.re);
        if let Some(beta) = beta.filter(|b| b.abs() <= hopf.omega / 20.0) {
            return Ok(Some((p, x, beta)));
        }
    }
    Ok(None)
}

/// The cycle equations `[R(q, ω; p); b₁] = 0` in the unknowns `u = {q, ω}`
/// as a [`Branch`] in p (the fold locator's system).
pub(crate) struct CycleSystem<'f, F> {
    family: &'f F,
    res: HbResidual,
    galerkin: GalerkinJacobian,
    jq: Vec<f64>,
    rp: Vec<f64>,
    rm: Vec<f64>,
    phase: usize,
}

impl<'f, P: PeriodicProblem, F: Fn(f64) -> P> CycleSystem<'f, F> {
    pub(crate) fn new(family: &'f F, hb: &HbOptions, p: f64) -> Result<Self, HbError> {
        let res = HbResidual::new(&family(p), hb)?;
        let m = res.len();
        Ok(Self {
            family,
            galerkin: GalerkinJacobian::new(&res),
            res,
            jq: vec![0.0; m * m],
            rp: vec![0.0; m],
            rm: vec![0.0; m],
            phase: hb.harmonics + 1,
        })
    }
}

impl<P: PeriodicProblem, F: Fn(f64) -> P> Branch for CycleSystem<'_, F> {
    fn len(&self) -> usize {
        self.res.len() + 1
    }
    /// `[R(q, ω; p); b₁]` (NaN unless `u` and `r` hold `m + 1` entries).
    fn residual(&mut self, u: &[f64], p: f64, r: &mut [f64]) {
        let m = self.res.len();
        let (Some((&omega, q)), Some((b1, r_q))) = (u.split_last(), r.split_last_mut()) else {
            return r.fill(f64::NAN);
        };
        if q.len() != m || r_q.len() != m {
            return r.fill(f64::NAN);
        }
        self.res.eval(&(self.family)(p), q, omega, 1.0, r_q);
        *b1 = u.get(self.phase).copied().unwrap_or(f64::NAN);
    }
    /// `[[Φ_q, ∂R/∂ω], [e_{b₁}ᵀ, 0]]`, `∂R/∂ω` by a central difference (NaN
    /// unless `u` holds `m + 1` entries and `jac` `(m + 1)²`).
    fn jacobian(&mut self, u: &[f64], p: f64, jac: &mut [f64]) {
        let m = self.res.len();
        let Some((&omega, q)) = u.split_last() else {
            return jac.fill(f64::NAN);
        };
        if q.len() != m || jac.len() != (m + 1) * (m + 1) {
            return jac.fill(f64::NAN);
        }
        let problem = (self.family)(p);
        self.galerkin
            .assemble(&mut self.res, &problem, q, omega, 1.0, &mut self.jq);
        let h = 1e-6 * omega;
        self.res.eval(&problem, q, omega + h, 1.0, &mut self.rp);
        self.res.eval(&problem, q, omega - h, 1.0, &mut self.rm);
        jac.fill(0.0);
        // Rows `m + 1` long (`m ≥ 1`): `[Φ_q row, ∂R/∂ω]`, then the phase row.
        let (top, phase_row) = jac.split_at_mut(m * (m + 1));
        let columns = self.jq.chunks_exact(m).zip(self.rp.iter().zip(&self.rm));
        for (row, (jq_row, (rp, rm))) in top.chunks_exact_mut(m + 1).zip(columns) {
            if let Some((d_omega, head)) = row.split_last_mut() {
                head.copy_from_slice(jq_row);
                *d_omega = (rp - rm) / (2.0 * h);
            }
        }
        if let Some(entry) = phase_row.get_mut(self.phase) {
            *entry = 1.0;
        }
    }
}
