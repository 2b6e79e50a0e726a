//! The automatic bifurcation diagram of a forced system over an interval of
//! ω_f (issue 45 item 2; BifurcationKit's `bifurcationdiagram` for periodic
//! responses): the primary response curve traced with its events
//! ([`ivt_hb::branches::events`]), then recursively, to `depth` levels,
//!
//! - at each branch point both halves of the crossing branch (the root of
//!   the bifurcation equation nearer ω_f = const, [`super::switch()`]) stepped
//!   `±h` from it;
//! - at each period doubling the period-2 branch
//!   ([`ivt_hb::period_doubled_start`]);
//! - at each Neimark–Sacker point the torus branch ([`ivt_hb::branches::torus`]; not
//!   searched further);
//!
//! and, for branches no event leads to (isolas),
//!
//! - the folds of every branch followed in the forcing scale `s`
//!   (`f → s·f`, [`ivt_hb::fold_curve`]) over `fold_scale`: a fold curve that
//!   crosses `s = 1` again off the known branches is a fold of another
//!   branch, traced from there;
//! - every solution that deflated Newton ([`ivt_hb::all_solutions()`]) finds
//!   at `samples` frequencies spread over the interval, off the known
//!   branches, traced both ways.
//!
//! Every branch is traced within `[from, to]` (bounds, not ends: a branch
//! may leave and re-enter the interval only by a path inside it) and stops
//! where it closes on its own start (a loop through two branch points). A
//! branch that starts on a known branch is not traced again. The result
//! lists the branches (each with its parent, how it began, its points with
//! stability and its events) and what bounded the search.

mod follow;
mod isolas;
mod switching;

use follow::{periodic_point, segment_distance, sign, trace_within};

use super::frc::{event, trace_error, EventRecord};
use super::switch::new_direction;
use super::{finite, finite_list, pairs, positive, Array, Steps};
use ivt_hb::analyses::deflation::{all_solutions, SearchOptions};
use ivt_hb::branches::codim2::fold_curve;
use ivt_hb::branches::events::{
    every_event, observe, observer, BifurcationKind, Event, LocateOptions, Multipliers,
    PointMultipliers, Trace, TracedPoint,
};
use ivt_hb::branches::family::{Family, FamilyBranch, Frequency};
use ivt_hb::branches::frc::{from_trace, AmplitudeProbe, FrcPoint};
use ivt_hb::branches::switching::{period_doubled_start, switch_branch};
use ivt_hb::branches::torus::{torus_start, NeimarkSackerStart, TorusOptions, Truncation};
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::{AtFrequency, PeriodicProblem};
use ivt_hb::stability::{AdaptiveHsu, HsuSteps, StabilityKind};
use ivt_hb::HbError;
use ivt_hb::{Bifurcation, Corrector, ModifiedIhb};
use ivt_num::vector::norm2;
use ivt_path::continuation::{
    correct_at_fixed_lambda, ContinuationOptions, PathPoint, Termination,
};
use serde::Serialize;
use std::time::Instant;

/// The interval, the recursion and the isola search.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagramRequest {
    /// Start of the interval of ω_f (the primary curve starts here).
    pub from: f64,
    /// End of the interval.
    pub to: f64,
    /// Levels of switching: the primary curve is level 0, a branch switched
    /// at an event of level `k` is level `k + 1`; events of level `depth`
    /// are not switched at.
    pub depth: usize,
    /// Most branches (tori included).
    pub max_branches: usize,
    /// Start the torus branch at each Neimark–Sacker point.
    pub tori: bool,
    /// Harmonics and grid of the tori.
    pub torus: TorusOptions,
    /// Most points of a torus branch.
    pub torus_points: usize,
    /// The interval of the forcing scale over which folds are followed
    /// (`None`: no fold curves).
    pub fold_scale: Option<(f64, f64)>,
    /// Frequencies of the deflation search, spread evenly inside the
    /// interval (0: none).
    pub samples: usize,
    /// The deflation search's box `‖q‖∞ ≤ max_amplitude`.
    pub max_amplitude: f64,
    /// Its start amplitudes per phase.
    pub amplitudes: usize,
    /// ω_f at which every branch is solved exactly (inserted into its
    /// points, marked `at`).
    pub at: Vec<f64>,
    /// Every branch's steps and most points (by default Δη from 0.02 up to
    /// 0.05, 2000 points: [`DIAGRAM_STEPS`]).
    pub steps: Steps,
    /// Distance of a switched branch's first point from its event, relative
    /// to the orbit's ‖coefficients‖₂.
    pub step: f64,
}

/// Every branch's own first step, largest step and most points.
pub const DIAGRAM_STEPS: (f64, f64, usize) = (0.02, 0.05, 2000);

impl Default for DiagramRequest {
    /// ω_f ∈ [0.5, 2.5], depth 2, at most 24 branches, tori (the box
    /// |k₁| ≤ 5, |k₂| ≤ 10, 60 points), folds followed in the forcing scale
    /// over [0.25, 4], deflation at 6 frequencies.
    fn default() -> Self {
        Self {
            from: 0.5,
            to: 2.5,
            depth: 2,
            max_branches: 24,
            tori: true,
            torus: TorusOptions {
                truncation: Truncation::Box { h1: 5, h2: 10 },
                ..TorusOptions::default()
            },
            torus_points: 60,
            fold_scale: Some((0.25, 4.0)),
            samples: 6,
            max_amplitude: 10.0,
            amplitudes: 6,
            at: Vec::new(),
            steps: Steps::default(),
            step: 0.05,
        }
    }
}

impl DiagramRequest {
    /// The continuation options of every branch: [`DIAGRAM_STEPS`] with the
    /// request's `steps`, the Newton–chord corrector, within the interval.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for steps [`Steps::on`] refuses.
    pub fn path(&self) -> Result<ContinuationOptions, HbError> {
        let mut c = super::path_steps(&self.steps, DIAGRAM_STEPS)?;
        c.corrector = Corrector::Newton;
        c.lambda_min = self.from.min(self.to);
        c.lambda_max = self.from.max(self.to);
        Ok(c)
    }

    /// # Errors
    /// [`HbError::InvalidInput`] for an interval that is not finite, positive
    /// and non-empty, a fold scale interval not around 1, non-finite `at`,
    /// non-positive steps or box, a `step` outside (0, 1].
    pub fn validate(&self) -> Result<(), HbError> {
        let (from, to) = (finite("from", self.from)?, finite("to", self.to)?);
        if !(from > 0.0 && to > 0.0 && from != to) {
            return Err(HbError::InvalidInput(format!(
                "`from` = {from:?}, `to` = {to:?} must be > 0 and distinct"
            )));
        }
        if let Some((lo, hi)) = self.fold_scale {
            if !(lo.is_finite() && hi.is_finite() && lo < 1.0 && hi > 1.0) {
                return Err(HbError::InvalidInput(format!(
                    "`fold_scale` = ({lo:?}, {hi:?}) must be finite with lo < 1 < hi"
                )));
            }
        }
        finite_list("at", &self.at)?;
        self.path()?;
        positive("max_amplitude", self.max_amplitude)?;
        let step = finite("step", self.step)?;
        if !(step > 0.0 && step <= 1.0) {
            return Err(HbError::InvalidInput(format!(
                "`step` = {step:?} must be in (0, 1]"
            )));
        }
        Ok(())
    }
}

/// How a branch began.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BranchKind {
    /// The curve from `from`.
    Primary,
    /// Switched at a branch point of its parent.
    BranchPoint,
    /// The period-2 branch of a period doubling of its parent.
    PeriodDoubling,
    /// The torus branch of a Neimark–Sacker point of its parent.
    Torus,
    /// Found by following a fold of its parent in the forcing scale.
    FoldCurve,
    /// Found by deflated Newton at one ω_f.
    Deflation,
}

/// One point of a branch.
#[derive(Debug, Clone, Serialize)]
pub struct DiagramPoint {
    /// ω_f.
    pub omega: f64,
    /// max |x₀| (a torus: its maximum of |x₀| over the torus).
    pub amplitude: f64,
    /// The orbit's coefficients (a torus: the torus's, see its branch's
    /// `harmonics`).
    pub coeffs: Array<f64>,
    /// Stable (a torus: its normal exponent < 0 for one DOF, else `None`).
    pub stable: Option<bool>,
    /// The leading multiplier's class (periodic branches).
    pub stability: Option<StabilityKind>,
    /// Floquet multipliers `[[re, im], ...]` (periodic branches).
    pub multipliers: Option<Vec<[f64; 2]>>,
    /// Rotation number (tori).
    pub rotation_number: Option<f64>,
    /// Solved at an ω_f of `at`.
    pub at: bool,
}

/// Where a branch began on its parent.
#[derive(Debug, Clone, Serialize)]
pub struct Origin {
    /// The event (or `fold` for a fold curve's crossing).
    pub kind: BifurcationKind,
    /// Its ω_f.
    pub omega: f64,
    /// Its index in the parent's `events` (`None` for a fold curve's
    /// crossing of `s = 1`).
    pub event: Option<usize>,
}

/// One branch of the diagram.
#[derive(Debug, Clone, Serialize)]
pub struct DiagramBranch {
    /// How it began.
    pub kind: BranchKind,
    /// The branch it came from (index into `branches`).
    pub parent: Option<usize>,
    /// Where on the parent.
    pub origin: Option<Origin>,
    /// Its level (primary 0).
    pub level: usize,
    /// Harmonics of its coefficients (a torus: the number of harmonics
    /// kept).
    pub harmonics: usize,
    /// Response period over excitation period (2 after a period doubling).
    pub subharmonic: usize,
    /// `[k₁, k₂]` of a torus's coefficient pairs (empty otherwise).
    pub torus_harmonics: Vec<[i64; 2]>,
    /// Points in path order.
    pub points: Vec<DiagramPoint>,
    /// Events in path order (none on tori).
    pub events: Vec<EventRecord>,
    /// Why tracing stopped (`stopped`: it closed on its start).
    pub termination: Termination,
}

/// What bounded the search.
#[derive(Debug, Clone, Serialize)]
pub struct DiagramSearch {
    /// The interval.
    pub interval: [f64; 2],
    /// The depth bound.
    pub depth: usize,
    /// The deepest level reached.
    pub deepest: usize,
    /// Events not switched at because they lie at the depth bound.
    pub events_beyond_depth: usize,
    /// The branch bound and whether it was reached.
    pub max_branches: usize,
    /// Whether new branches were left out at `max_branches`.
    pub branch_limit_reached: bool,
    /// Starts that lay on a known branch (not traced again).
    pub duplicates: usize,
    /// Switches and starts that failed, with their reasons.
    pub failures: Vec<String>,
    /// Folds followed in the forcing scale, and the scale's interval.
    pub fold_curves: usize,
    /// The forcing scale's interval.
    pub fold_scale: Option<[f64; 2]>,
    /// The deflation search's frequencies.
    pub deflation_omegas: Vec<f64>,
    /// Solutions it found (known ones included).
    pub deflation_solutions: usize,
    /// Whether every deflated run ended without a new solution.
    pub deflation_exhausted: bool,
    /// Branches that reached `max_points`.
    pub truncated_branches: usize,
}

/// The keys of `ivt hb diagram --json` and `ivt.hb.diagram`.
#[derive(Debug, Clone, Serialize)]
pub struct Diagram {
    /// The branches, the primary first.
    pub branches: Vec<DiagramBranch>,
    /// What bounded the search.
    pub search: DiagramSearch,
    /// Wall time.
    pub time_s: f64,
}

/// A periodic branch found but not yet traced: its HB options, first point
/// `[q, ω_f]`, direction in ω_f, and what it is.
struct Pending {
    hb: HbOptions,
    x0: Vec<f64>,
    direction: f64,
    kind: BranchKind,
    parent: Option<usize>,
    origin: Option<Origin>,
    level: usize,
}

/// The search's state: the request, the branches so far and the report.
struct Search<'a, P> {
    problem: &'a P,
    hb: HbOptions,
    req: &'a DiagramRequest,
    /// The continuation options of every branch, within the interval.
    path: ContinuationOptions,
    /// Each branch's states `[q, ω_f]` with its HB options (tori: `None`).
    states: Vec<Option<(HbOptions, Vec<Vec<f64>>)>>,
    /// Each branch's located events (tori: none).
    located: Vec<Vec<Event>>,
    branches: Vec<DiagramBranch>,
    search: DiagramSearch,
}

impl<'a, P: PeriodicProblem> Search<'a, P> {
    /// Whether `x = [q, ω_f]` lies within `tol` of a traced branch with the
    /// options `hb`.
    fn known(&self, hb: &HbOptions, x: &[f64], tol: f64) -> bool {
        self.states.iter().flatten().any(|(h, states)| {
            h.harmonics == hb.harmonics
                && h.subharmonic == hb.subharmonic
                && states
                    .windows(2)
                    .any(|w| matches!(w, [a, b] if a.len() == x.len() && segment_distance(x, a, b) < tol))
        })
    }

    /// Whether the period-one orbit `q` at ω_f lies on a traced branch: each
    /// crossing of ω_f by a branch corrected there at fixed ω_f by Newton,
    /// within `1e-6·max(‖q‖, 1)` of `q`.
    fn on_branch_at(&self, q: &[f64], omega: f64) -> bool {
        let copts = self.path.clone();
        let Ok(mut branch) = FamilyBranch::new(Frequency(self.problem), &self.hb, omega) else {
            return false;
        };
        let tol = 1e-6 * norm2(q).max(1.0);
        self.states.iter().flatten().any(|(h, states)| {
            h.harmonics == self.hb.harmonics
                && h.subharmonic == self.hb.subharmonic
                && states.windows(2).any(|w| {
                    let [a, b] = w else { return false };
                    let la = a.last().copied().unwrap_or(f64::NAN);
                    let lb = b.last().copied().unwrap_or(f64::NAN);
                    let product = (la - omega) * (lb - omega);
                    if product.is_nan() || product > 0.0 || la == lb {
                        return false;
                    }
                    let t = (omega - la) / (lb - la);
                    let mut x: Vec<f64> = a.iter().zip(b).map(|(u, v)| u + t * (v - u)).collect();
                    if let Some(l) = x.last_mut() {
                        *l = omega;
                    }
                    correct_at_fixed_lambda(&mut branch, &mut x, &copts).is_ok()
                        && x.iter()
                            .zip(q)
                            .map(|(u, v)| (u - v).powi(2))
                            .sum::<f64>()
                            .sqrt()
                            < tol
                })
        })
    }

    /// Room for one more branch; records the bound otherwise.
    fn room(&mut self) -> bool {
        let room = self.branches.len() < self.req.max_branches;
        if !room {
            self.search.branch_limit_reached = true;
        }
        room
    }

    /// Traces a pending branch and records it; its index, or `None` at the
    /// branch bound.
    fn trace(&mut self, pending: Pending) -> Result<Option<usize>, HbError> {
        if !self.room() {
            return Ok(None);
        }
        let lambda0 = pending.x0.last().copied().unwrap_or(f64::NAN);
        let mut branch = FamilyBranch::new(Frequency(self.problem), &pending.hb, lambda0)?;
        let copts = self.path.clone();
        let close = pending.kind != BranchKind::Primary;
        let trace = trace_within(&mut branch, &pending.x0, pending.direction, &copts, close)?;
        if trace.termination == Termination::MaxPoints {
            self.search.truncated_branches += 1;
        }
        let states: Vec<Vec<f64>> = trace
            .points
            .iter()
            .map(|p| p.q.iter().copied().chain([p.lambda]).collect())
            .collect();
        let curve = from_trace(&trace, &pending.hb)?;
        let mut probe = AmplitudeProbe::new(&pending.hb)?;
        let events: Vec<EventRecord> = trace
            .events
            .iter()
            .map(|e| event(e, &curve, &mut probe))
            .collect();
        let mut points: Vec<(usize, DiagramPoint)> = curve
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| (2 * i, periodic_point(p, false)))
            .collect();
        points.extend(self.solve_at(&mut branch, &pending.hb, &states)?);
        points.sort_by_key(|(slot, _)| *slot);
        let index = self.branches.len();
        self.branches.push(DiagramBranch {
            kind: pending.kind,
            parent: pending.parent,
            origin: pending.origin,
            level: pending.level,
            harmonics: pending.hb.harmonics,
            subharmonic: pending.hb.subharmonic,
            torus_harmonics: Vec::new(),
            points: points.into_iter().map(|(_, p)| p).collect(),
            events,
            termination: trace.termination,
        });
        self.search.deepest = self.search.deepest.max(pending.level);
        self.states.push(Some((pending.hb, states)));
        self.located.push(trace.events);
        Ok(Some(index))
    }

    /// The orbit at each ω_f of `at` where the path `states` crosses it,
    /// corrected there by Newton, with its multipliers: `(slot, point)`,
    /// the slot between those of its two path points.
    fn solve_at<F: Family>(
        &self,
        branch: &mut FamilyBranch<F>,
        hb: &HbOptions,
        states: &[Vec<f64>],
    ) -> Result<Vec<(usize, DiagramPoint)>, HbError> {
        let copts = self.path.clone();
        let mut out = Vec::new();
        for &target in &self.req.at {
            for (k, w) in states.windows(2).enumerate() {
                let [a, b] = w else { continue };
                let la = a.last().copied().unwrap_or(f64::NAN);
                let lb = b.last().copied().unwrap_or(f64::NAN);
                if !((la - target) * (lb - target) < 0.0 || lb == target) {
                    continue;
                }
                let t = (target - la) / (lb - la);
                let mut x: Vec<f64> = a.iter().zip(b).map(|(u, v)| u + t * (v - u)).collect();
                if let Some(l) = x.last_mut() {
                    *l = target;
                }
                correct_at_fixed_lambda(branch, &mut x, &copts)?;
                let problem = branch.family().at(target).0;
                let mut mult = Multipliers::new(AdaptiveHsu::new(
                    &problem,
                    hb.harmonics,
                    HsuSteps::default(),
                )?);
                let point = PathPoint {
                    x,
                    iterations: 0,
                    dlambda: 0.0,
                    bordered_sign: None,
                };
                let traced: TracedPoint =
                    PointMultipliers::<_, HbError>::at(&mut mult, branch, &point)?;
                let single = Trace {
                    points: vec![traced],
                    events: Vec::new(),
                    termination: Termination::LeftInterval,
                };
                let curve = from_trace(&single, hb)?;
                out.extend(
                    curve
                        .points
                        .first()
                        .map(|p| (2 * k + 1, periodic_point(p, true))),
                );
            }
        }
        Ok(out)
    }
}

/// The automatic bifurcation diagram of `problem` over `[req.from, req.to]`
/// (see the module docs).
///
/// # Errors
/// [`DiagramRequest::validate`]'s; the primary curve's start and path (a
/// failure on a later branch is recorded in `search.failures`).
pub fn diagram(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    req: &DiagramRequest,
) -> Result<Diagram, HbError> {
    req.validate()?;
    let problem = &problem;
    let t0 = Instant::now();
    let mut s = Search {
        problem,
        hb: hb.clone(),
        req,
        path: req.path()?,
        states: Vec::new(),
        located: Vec::new(),
        branches: Vec::new(),
        search: DiagramSearch {
            interval: [req.from, req.to],
            depth: req.depth,
            deepest: 0,
            events_beyond_depth: 0,
            max_branches: req.max_branches,
            branch_limit_reached: false,
            duplicates: 0,
            failures: Vec::new(),
            fold_curves: 0,
            fold_scale: None,
            deflation_omegas: Vec::new(),
            deflation_solutions: 0,
            deflation_exhausted: false,
            truncated_branches: 0,
        },
    };
    let at_start = AtFrequency::new(problem, req.from);
    let start = ModifiedIhb::new(&at_start, hb.clone())?.solve(req.from, None)?;
    let mut x0 = start.coeffs;
    x0.push(req.from);
    s.trace(Pending {
        hb: hb.clone(),
        x0,
        direction: req.to - req.from,
        kind: BranchKind::Primary,
        parent: None,
        origin: None,
        level: 0,
    })?;
    // Breadth first: every branch's events, then the isola searches, then
    // the events of what they found.
    let mut next = 0;
    let mut searched = false;
    loop {
        while next < s.branches.len() {
            s.switch_at_events(next)?;
            next += 1;
        }
        if searched {
            break;
        }
        s.fold_curves()?;
        s.deflation()?;
        searched = true;
    }
    Ok(Diagram {
        branches: s.branches,
        search: s.search,
        time_s: t0.elapsed().as_secs_f64(),
    })
}
