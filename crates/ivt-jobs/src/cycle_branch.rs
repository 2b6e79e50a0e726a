//! Hopf points of an autonomous family and the limit-cycle branch born at
//! the first ([`ivt_hb::cycle_branch()`]: equilibria followed in p, the Hopf
//! point's first Lyapunov coefficient, the cycle branch by HB with ω unknown
//! and Eq. 68–77, Floquet stability (Hsu) and its folds located).

use super::{all_finite, finite_list, pairs, path_steps, stability_steps, Array, Steps};
use crate::fold_curve::{unlocated_points, CurveFoldPoint, UnlocatedPoint};
use ivt_hb::branches::autonomous::LimitCycle;
use ivt_hb::branches::cycle_branch::{cycle_branch as trace_cycles, CycleBranchOptions};
use ivt_hb::branches::events::BifurcationKind;
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::{boxed_family, BoxedFamily, PeriodicProblem};
use ivt_hb::stability::StabilityKind;
use ivt_hb::HbError;
use ivt_path::continuation::{ContinuationOptions, Termination};
use serde::Serialize;

/// The interval of p, the grid of the Hopf search and the path's steps.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleBranchRequest {
    /// The equilibria are followed from this p …
    pub p_from: f64,
    /// … to this one (≠ `p_from`).
    pub p_to: f64,
    /// p at which the cycles are solved exactly (each crossing).
    pub at: Vec<f64>,
    /// Intervals of the equilibria's grid in p.
    pub grid: usize,
    /// The cycle branch's steps and most points (by default Δη from 0.02 up
    /// to 0.05, 2000 points: [`CYCLE_BRANCH_STEPS`]).
    pub steps: Steps,
    /// The first cycle's distance from the Hopf point, relative to
    /// `|p_to − p_from|`.
    pub offset: f64,
}

/// The cycle branch's own first step, largest step and most points.
pub const CYCLE_BRANCH_STEPS: (f64, f64, usize) = (0.02, 0.05, 2000);

impl Default for CycleBranchRequest {
    /// The example's interval μ ∈ [−0.2, 0.1], a grid of 100, steps
    /// 0.02 to 0.05, 2000 points, the start 1 % of the interval from the
    /// Hopf point.
    fn default() -> Self {
        Self {
            p_from: -0.2,
            p_to: 0.1,
            at: Vec::new(),
            grid: 100,
            steps: Steps::default(),
            offset: 1e-2,
        }
    }
}

impl CycleBranchRequest {
    /// # Errors
    /// [`HbError::InvalidInput`] for a non-finite number or equal ends (the
    /// grid, the steps and the offset are checked by [`ivt_hb::cycle_branch()`]).
    pub fn validate(&self) -> Result<(), HbError> {
        all_finite(&[
            ("p_from", self.p_from),
            ("p_to", self.p_to),
            ("offset", self.offset),
        ])?;
        if self.p_from == self.p_to {
            return Err(HbError::InvalidInput(
                "`p_from` and `p_to` must differ".into(),
            ));
        }
        finite_list("at", &self.at)?;
        self.path().map(|_| ())
    }

    /// [`CYCLE_BRANCH_STEPS`] with the request's `steps`.
    ///
    /// # Errors
    /// [`HbError::InvalidInput`] for steps [`Steps::on`] refuses.
    pub fn path(&self) -> Result<ContinuationOptions, HbError> {
        path_steps(&self.steps, CYCLE_BRANCH_STEPS)
    }
}

/// A Hopf point of the equilibria.
#[derive(Debug, Clone, Serialize)]
pub struct HopfRecord {
    /// Where.
    pub p: f64,
    /// The crossing eigenvalues' frequency.
    pub omega: f64,
    /// First Lyapunov coefficient.
    pub lyapunov: f64,
    /// `lyapunov > 0`: the cycles born there are unstable.
    pub subcritical: bool,
}

/// A stretch of p where the Hopf search could not decide
/// ([`ivt_hb::hopf_points`]): no equilibrium there, or a crossing that is
/// neither a simple Hopf point nor a real eigenvalue through zero.
#[derive(Debug, Clone, Serialize)]
pub struct UndecidedRecord {
    /// One end (the side of `p_from`).
    pub p_from: f64,
    /// The other end.
    pub p_to: f64,
    /// Why.
    pub reason: String,
}

/// A limit cycle of the branch.
#[derive(Debug, Clone, Serialize)]
pub struct CycleRecord {
    /// The parameter.
    pub p: f64,
    /// Response frequency ω.
    pub omega: f64,
    /// 2π/ω.
    pub period: f64,
    /// max |x| of DOF 0.
    pub amplitude: f64,
    /// All non-trivial multipliers inside the unit circle.
    pub stable: bool,
    /// Their class.
    pub stability: StabilityKind,
    /// Floquet multipliers `[[re, im], ...]` (the trivial +1 included).
    pub multipliers: Vec<[f64; 2]>,
    /// Coefficients of the orbit.
    pub coeffs: Array<f64>,
}

impl CycleRecord {
    fn new(p: f64, c: &LimitCycle) -> Self {
        Self {
            p,
            omega: c.omega(),
            period: c.period(),
            amplitude: c.solution.amplitude(0),
            stable: c.stable(),
            stability: c.kind,
            multipliers: pairs(&c.multipliers),
            coeffs: Array(c.solution.coeffs.clone()),
        }
    }
}

/// A fold of the cycle branch.
#[derive(Debug, Clone, Serialize)]
pub struct CycleFold {
    /// Always [`BifurcationKind::Fold`].
    pub kind: BifurcationKind,
    /// Where.
    pub p: f64,
    /// Its ω.
    pub omega: f64,
    /// max |x| of DOF 0.
    pub amplitude: f64,
    /// Its coefficients.
    pub coeffs: Array<f64>,
}

/// The keys of `ivt.hb.cycle_branch` and `ivt hb cycle-branch --json`.
#[derive(Debug, Clone, Serialize)]
pub struct CycleBranchResult {
    /// Hopf points in order of p from `p_from`: each place where a complex
    /// pair of the equilibria's eigenvalues crosses the imaginary axis.
    pub hopf: Vec<HopfRecord>,
    /// Where the search could not decide (empty: every Hopf point on the
    /// grid's resolution found).
    pub hopf_undecided: Vec<UndecidedRecord>,
    /// The branch from the first Hopf point, in path order.
    pub points: Vec<CycleRecord>,
    /// Its folds.
    pub bifurcations: Vec<CycleFold>,
    /// The cycles at each p of `at`.
    pub at: Vec<CycleRecord>,
    /// The folds (`"fold"`) and cycles at `at` (`"at"`, with the value) the
    /// branch passed but that could not be located, each with the reason
    /// and the path point the locator started from (`angle` absent).
    pub unlocated: Vec<UnlocatedPoint>,
    /// Why tracing stopped (None: no Hopf point).
    pub termination: Option<Termination>,
}

/// The Hopf points of `family(p)` and the cycle branch of the first.
///
/// # Errors
/// [`CycleBranchRequest::validate`]'s and [`ivt_hb::cycle_branch()`]'s.
pub fn cycle_branch<'p, P, F>(
    family: F,
    hb: &HbOptions,
    req: &CycleBranchRequest,
) -> Result<CycleBranchResult, HbError>
where
    P: PeriodicProblem + 'p,
    F: Fn(f64) -> Result<P, HbError>,
{
    cycle_branch_of(&boxed_family(family), hb, req)
}

/// [`cycle_branch`] on the boxed family.
fn cycle_branch_of(
    family: &BoxedFamily<'_, '_>,
    hb: &HbOptions,
    req: &CycleBranchRequest,
) -> Result<CycleBranchResult, HbError> {
    req.validate()?;
    let opts = CycleBranchOptions {
        samples: req.grid,
        offset: req.offset,
        continuation: req.path()?,
        stability_steps: stability_steps(hb.harmonics),
        at: req.at.clone(),
    };
    let branch = trace_cycles(family, hb, req.p_from, req.p_to, &opts)?;
    let cycles = |list: &[(f64, LimitCycle)]| {
        list.iter()
            .map(|(p, c)| CycleRecord::new(*p, c))
            .collect::<Vec<_>>()
    };
    Ok(CycleBranchResult {
        hopf: branch
            .hopf
            .iter()
            .map(|h| HopfRecord {
                p: h.p,
                omega: h.omega,
                lyapunov: h.lyapunov,
                subcritical: h.subcritical(),
            })
            .collect(),
        hopf_undecided: branch
            .undecided
            .iter()
            .map(|u| UndecidedRecord {
                p_from: u.p_from,
                p_to: u.p_to,
                reason: u.reason.clone(),
            })
            .collect(),
        points: cycles(&branch.points),
        bifurcations: branch
            .folds
            .iter()
            .map(|(p, orbit)| CycleFold {
                kind: BifurcationKind::Fold,
                p: *p,
                omega: orbit.omega_f,
                amplitude: orbit.amplitude(0),
                coeffs: Array(orbit.coeffs.clone()),
            })
            .collect(),
        at: cycles(&branch.at),
        unlocated: unlocated_points(&branch.unlocated, |(p, orbit)| CurveFoldPoint {
            omega: orbit.omega_f,
            p: *p,
            amplitude: orbit.amplitude(0),
            coeffs: Array(orbit.coeffs.clone()),
            angle: None,
        }),
        termination: branch.termination,
    })
}
