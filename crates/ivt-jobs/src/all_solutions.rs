//! Every periodic solution at one excitation frequency that deflated Newton
//! finds within bounded starts ([`ivt_hb::all_solutions()`]), each with its
//! Floquet multipliers (Hsu, Eq. 78) and verdict, and the search's bounds.

use super::{finite, pairs, stability_steps, Array};
use ivt_hb::analyses::deflation::{all_solutions as deflated, SearchOptions};
use ivt_hb::orbit::ihb::HbOptions;
use ivt_hb::problem::PeriodicProblem;
use ivt_hb::stability::StabilityKind;
use ivt_hb::HbError;
use serde::Serialize;

/// The frequency and the search's bounds.
#[derive(Debug, Clone, PartialEq)]
pub struct AllSolutionsRequest {
    /// Excitation frequency ω_f.
    pub omega: f64,
    /// The box `max |coefficient| ≤ max_amplitude` (and the starts' scale).
    pub max_amplitude: f64,
    /// Start amplitudes per phase.
    pub amplitudes: usize,
    /// Newton steps per deflated run.
    pub newton_steps: usize,
}

impl Default for AllSolutionsRequest {
    /// ω_f = 1.4 (three orbits of the thesis Duffing), the box 10, 6
    /// amplitudes, 60 Newton steps.
    fn default() -> Self {
        let s = SearchOptions::default();
        Self {
            omega: 1.4,
            max_amplitude: s.max_amplitude,
            amplitudes: s.amplitudes,
            newton_steps: s.max_iter,
        }
    }
}

/// One orbit found.
#[derive(Debug, Clone, Serialize)]
pub struct FoundOrbit {
    /// Its coefficients.
    pub coeffs: Array<f64>,
    /// max |x| of DOF 0.
    pub amplitude: f64,
    /// Floquet multipliers `[[re, im], ...]`.
    pub multipliers: Vec<[f64; 2]>,
    /// All multipliers inside the unit circle.
    pub stable: bool,
    /// Their class.
    pub stability: StabilityKind,
}

/// How the search was bounded and how it ended.
#[derive(Debug, Clone, Serialize)]
pub struct SearchBounds {
    /// Starts tried.
    pub starts: usize,
    /// Deflated Newton runs.
    pub runs: usize,
    /// The box.
    pub max_amplitude: f64,
    /// Newton steps per run.
    pub newton_steps: usize,
    /// Every start's last run found nothing new within the bounds.
    pub exhausted: bool,
    /// Failed runs that end the search from one start.
    pub failures_per_start: usize,
    /// Orbits dropped as time-shifted copies of another (autonomous problems).
    pub copies_merged: usize,
    /// The bound `exhausted` refers to, in words.
    pub bound: String,
}

/// The keys of `ivt hb all-solutions --json` (`ivt.hb.all_solutions`: the
/// list `solutions` with the attribute `search`).
#[derive(Debug, Clone, Serialize)]
pub struct AllSolutionsResult {
    /// The orbits by increasing size.
    pub solutions: Vec<FoundOrbit>,
    /// The search.
    pub search: SearchBounds,
}

/// Every solution of `problem` at `req.omega` that the bounded search finds.
///
/// # Errors
/// [`HbError::InvalidInput`] for a non-finite frequency or box;
/// [`ivt_hb::all_solutions()`]'s.
pub fn all_solutions(
    problem: &dyn PeriodicProblem,
    hb: &HbOptions,
    req: &AllSolutionsRequest,
) -> Result<AllSolutionsResult, HbError> {
    let search = SearchOptions {
        max_amplitude: finite("max_amplitude", req.max_amplitude)?,
        amplitudes: req.amplitudes,
        max_iter: req.newton_steps,
        stability_steps: stability_steps(hb.harmonics),
        ..SearchOptions::default()
    };
    let all = deflated(problem, hb, finite("omega", req.omega)?, &search)?;
    Ok(AllSolutionsResult {
        solutions: all
            .solutions
            .iter()
            .map(|s| FoundOrbit {
                coeffs: Array(s.solution.coeffs.clone()),
                amplitude: s.solution.amplitude(0),
                multipliers: pairs(&s.multipliers),
                stable: s.kind == StabilityKind::Stable,
                stability: s.kind,
            })
            .collect(),
        search: SearchBounds {
            starts: all.report.starts,
            runs: all.report.runs,
            max_amplitude: all.report.max_amplitude,
            newton_steps: all.report.max_iter,
            exhausted: all.report.exhausted,
            failures_per_start: all.report.failures_per_start,
            copies_merged: all.report.copies_merged,
            bound: all.report.bound.clone(),
        },
    })
}
