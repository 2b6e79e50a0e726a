//! Gain design for the integral time-delay feedback (§4.3): the (k, k2) in a
//! box that minimise the max |multiplier| at one operating point, and the
//! worst case over a set of points (or a grid) for given gains.

use super::delay::{delay_stability_about, steady_orbit, DelayOptions, FeedbackGains};
use super::sweep::{sweep, Grid};
use super::{check_plant, IvtError, OperatingPoint};
use ivt_kin::plant::PlantParams;
use rayon::prelude::*;

/// One point of a stability map: the operating point and its max |multiplier|
/// (or why it could not be computed).
pub type MapEntry = (OperatingPoint, Result<f64, String>);

/// Best gains on a grid over the box, and the max |multiplier| they give.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GainChoice {
    /// The chosen gains (SI).
    pub gains: FeedbackGains,
    /// Max |multiplier| with them.
    pub max_abs_multiplier: f64,
}

/// Search a `steps × steps` grid of (k, k2) in [k_lo, k_hi] × [k2_lo, k2_hi]
/// (SI units) at `op`, then refine around the best cell once.
///
/// # Errors
/// Bad inputs or failures of the steady state.
pub fn best_gains(
    plant: &PlantParams,
    op: &OperatingPoint,
    k_box: (f64, f64),
    k2_box: (f64, f64),
    steps: usize,
    opts: &DelayOptions,
) -> Result<GainChoice, IvtError> {
    if steps < 2 {
        return Err(IvtError::EmptyGrid("gain grid needs >= 2 steps per axis"));
    }
    let orbit = steady_orbit(plant, op, None, opts)?;
    let mut kb = k_box;
    let mut k2b = k2_box;
    let mut best: Option<GainChoice> = None;
    for _round in 0..2 {
        let cand: Vec<FeedbackGains> = (0..steps)
            .flat_map(|i| {
                (0..steps).map(move |j| FeedbackGains {
                    k: kb.0 + (kb.1 - kb.0) * i as f64 / (steps - 1) as f64,
                    k2: k2b.0 + (k2b.1 - k2b.0) * j as f64 / (steps - 1) as f64,
                })
            })
            .collect();
        let scored: Vec<GainChoice> = cand
            .par_iter()
            .filter_map(|g| {
                delay_stability_about(plant, op, *g, &orbit, opts)
                    .ok()
                    .map(|s| GainChoice {
                        gains: *g,
                        max_abs_multiplier: s.max_abs_multiplier,
                    })
            })
            .collect();
        let round_best = scored
            .into_iter()
            .min_by(|a, b| a.max_abs_multiplier.total_cmp(&b.max_abs_multiplier));
        if let Some(b) = round_best {
            if best.is_none_or(|x| b.max_abs_multiplier < x.max_abs_multiplier) {
                best = Some(b);
            }
            let (dk, dk2) = (
                (kb.1 - kb.0) / (steps - 1) as f64,
                (k2b.1 - k2b.0) / (steps - 1) as f64,
            );
            kb = ((b.gains.k - dk).max(k_box.0), (b.gains.k + dk).min(k_box.1));
            k2b = (
                (b.gains.k2 - dk2).max(k2_box.0),
                (b.gains.k2 + dk2).min(k2_box.1),
            );
        }
    }
    best.ok_or(IvtError::EmptyGrid(
        "no gain in the box gave a stability result",
    ))
}

/// Stability over a set of points for fixed gains: per-point max |multiplier|
/// (rayon across points) and the worst one.
///
/// # Errors
/// [`IvtError::EmptyGrid`] for no points; per-point failures are returned as `Err` strings.
pub fn stability_map(
    plant: &PlantParams,
    points: &[OperatingPoint],
    gains: FeedbackGains,
    opts: &DelayOptions,
) -> Result<Vec<MapEntry>, IvtError> {
    if points.is_empty() {
        return Err(IvtError::EmptyGrid("no operating points"));
    }
    let token = ivt_num::cancel::Token::now();
    Ok(points
        .par_iter()
        .map(|op| {
            if token.cancelled() {
                return (*op, Err(ivt_num::cancel::CANCELLED.to_string()));
            }
            let r = super::delay::delay_stability(plant, op, gains, opts)
                .map(|s| s.max_abs_multiplier)
                .map_err(|e| e.to_string());
            (*op, r)
        })
        .collect())
}

/// A stability map over a (V_m, T_U) grid for fixed gains (thesis Fig. 42):
/// what `ivt stability-map` and `ivt.design.stability_map` report.
#[derive(Clone, Debug, PartialEq)]
pub struct GridMap {
    /// The points mapped, row by row in T_U (V_m fastest), each with its max
    /// |multiplier| or why it failed; with `feasible_only`, only the points
    /// whose r̄ lies in [0, r_max].
    pub entries: Vec<MapEntry>,
    /// Largest max |multiplier| over the solved points.
    pub worst: f64,
    /// Number of points that failed.
    pub failed: usize,
}

impl GridMap {
    /// The map over `grid` (the grid it was computed on), row-major over
    /// (T_U, V_m), NaN where a point failed or was skipped: a heat map's values.
    pub fn values(&self, grid: &Grid) -> Vec<f64> {
        let mut entries = self.entries.iter().peekable();
        grid.operating_points()
            .iter()
            .map(|op| match entries.next_if(|(e, _)| e == op) {
                Some((_, Ok(m))) => *m,
                _ => f64::NAN,
            })
            .collect()
    }
}

/// Stability (Eq. 174–179) of every point of `grid` for the gains (rayon
/// across points), or with `feasible_only` of the points whose IHB r̄
/// (default options) lies in [0, r_max].
///
/// # Errors
/// Bad grid, plant or options; [`IvtError::EmptyGrid`] when no point is
/// feasible; [`IvtError::AllFailed`] when every point failed (a map of
/// failures has no worst case to report).
pub fn grid_stability_map(
    plant: &PlantParams,
    grid: &Grid,
    feasible_only: bool,
    gains: FeedbackGains,
    opts: &DelayOptions,
) -> Result<GridMap, IvtError> {
    check_plant(plant)?;
    grid.validate()?;
    opts.validate()?;
    let ops: Vec<OperatingPoint> = if feasible_only {
        sweep(plant, grid, Default::default(), || ())?
            .into_iter()
            .filter(|p| {
                p.result
                    .as_ref()
                    .is_ok_and(|s| (0.0..=plant.r_max).contains(&s.r))
            })
            .map(|p| p.op)
            .collect()
    } else {
        grid.operating_points()
    };
    let entries = stability_map(plant, &ops, gains, opts)?;
    IvtError::unless_some_solved(entries.iter().map(|(_, r)| r))?;
    let solved = entries.iter().filter_map(|(_, r)| r.as_ref().ok());
    let worst = solved.clone().copied().fold(f64::NEG_INFINITY, f64::max);
    let failed = entries.len() - solved.count();
    Ok(GridMap {
        entries,
        worst,
        failed,
    })
}
