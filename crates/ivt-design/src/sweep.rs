//! r̄ over a (V_m, T_U) grid (thesis Fig. 38(a)): one IHB plan per row (fixed
//! T_U), warm starts from the previous V_m along the row, rows in parallel
//! with rayon.

use super::steady::{IhbOptions, IhbSolver, SteadyState};
use super::{check_plant, IvtError, OperatingPoint};
use ivt_kin::plant::PlantParams;
use rayon::prelude::*;

/// A rectangular grid of operating points.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Motor voltages \[V\].
    pub v_m: Vec<f64>,
    /// Brake torques \[N·m\].
    pub t_u: Vec<f64>,
    /// Target mean speed ω0 \[rad/s\].
    pub omega0: f64,
}

impl Grid {
    /// Every (V_m, T_U) point at ω0, V_m fastest (row by row in T_U).
    pub fn operating_points(&self) -> Vec<OperatingPoint> {
        self.t_u
            .iter()
            .flat_map(|&t_u| {
                self.v_m.iter().map(move |&v_m| OperatingPoint {
                    v_m,
                    t_u,
                    omega0: self.omega0,
                })
            })
            .collect()
    }

    /// The thesis grid: V_m ∈ 2:0.4:12 (26), T_U ∈ 1.5:0.5:9 (16), ω0 = 100 rpm.
    pub fn thesis() -> Self {
        Self {
            v_m: range(2.0, 0.4, 12.0),
            t_u: range(1.5, 0.5, 9.0),
            omega0: super::thesis_omega0(),
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.v_m.len() * self.t_u.len()
    }

    /// Whether the grid has no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Reject empty axes, non-finite entries and grids of more than
    /// [`MAX_GRID_POINTS`] points.
    ///
    /// # Errors
    /// [`IvtError::EmptyGrid`] or [`IvtError::Input`].
    pub fn validate(&self) -> Result<(), IvtError> {
        if self.len() > MAX_GRID_POINTS {
            return Err(IvtError::Input {
                name: "grid",
                value: self.len() as f64,
                requirement: "at most 100000 points (MAX_GRID_POINTS)",
            });
        }
        let Some(&v_m0) = self.v_m.first() else {
            return Err(IvtError::EmptyGrid("no V_m values"));
        };
        let Some(&t_u0) = self.t_u.first() else {
            return Err(IvtError::EmptyGrid("no T_U values"));
        };
        for &v in &self.v_m {
            OperatingPoint {
                v_m: v,
                t_u: t_u0,
                omega0: self.omega0,
            }
            .validate()?;
        }
        for &t in &self.t_u {
            OperatingPoint {
                v_m: v_m0,
                t_u: t,
                omega0: self.omega0,
            }
            .validate()?;
        }
        Ok(())
    }
}

/// Most values one grid axis may hold. A stability-map or sweep point costs
/// 0.1–10 ms, so 10 000 values along one axis are already minutes of work;
/// the limit is checked before the axis is allocated, so a step such as
/// 1e-300 is refused instead of asking for 10^300 values.
pub const MAX_AXIS_POINTS: usize = 10_000;

/// Most points of a whole grid (both axes): 100 000 solves, minutes to an hour.
pub const MAX_GRID_POINTS: usize = 100_000;

/// `from:step:to` inclusive (MATLAB style), robust to rounding at the end.
/// Empty if step ≤ 0, to < from, any value is not finite, or the axis would
/// hold more than [`MAX_AXIS_POINTS`] values (use [`axis`] for the reason).
pub fn range(from: f64, step: f64, to: f64) -> Vec<f64> {
    axis("range", from, step, to).unwrap_or_default()
}

/// `from:step:to` inclusive, or why not: non-finite ends, step ≤ 0, to < from,
/// or more than [`MAX_AXIS_POINTS`] values. `name` is the argument reported.
///
/// # Errors
/// [`IvtError::Input`] naming `name`.
pub fn axis(name: &'static str, from: f64, step: f64, to: f64) -> Result<Vec<f64>, IvtError> {
    let bad = |value, requirement| IvtError::Input {
        name,
        value,
        requirement,
    };
    if !from.is_finite() {
        return Err(bad(from, "finite (range start)"));
    }
    if !to.is_finite() || to < from {
        return Err(bad(to, "finite and ≥ the range start (range end)"));
    }
    if !(step.is_finite() && step > 0.0) {
        return Err(bad(step, "finite and > 0 (range step)"));
    }
    let steps = ((to - from) / step + 1e-9).floor();
    if steps.is_nan() || steps >= MAX_AXIS_POINTS as f64 {
        return Err(bad(
            step,
            "large enough for at most 10000 values (MAX_AXIS_POINTS; range step)",
        ));
    }
    let n = steps as usize;
    Ok((0..=n).map(|i| from + i as f64 * step).collect())
}

/// One grid point's result.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepPoint {
    /// The operating point.
    pub op: OperatingPoint,
    /// The IHB steady state, or why it failed.
    pub result: Result<SteadyState, String>,
}

/// Solve every grid point. Rows (fixed T_U) run in parallel; within a row the
/// previous solution seeds the next V_m. `progress` is called once per point.
///
/// # Errors
/// Bad grid or plant; per-point solver failures are kept in the points.
pub fn sweep<P: Fn() + Sync>(
    plant: &PlantParams,
    grid: &Grid,
    opts: IhbOptions,
    progress: P,
) -> Result<Vec<SweepPoint>, IvtError> {
    check_plant(plant)?;
    grid.validate()?;
    IhbSolver::new(opts)?;
    // one token for the whole sweep: a row started after a cancellation stops too
    let token = ivt_num::cancel::Token::now();
    let rows: Vec<Vec<SweepPoint>> = grid
        .t_u
        .par_iter()
        .map(|&t_u| sweep_row(plant, grid, (t_u, token), opts, &progress))
        .collect();
    Ok(rows.into_iter().flatten().collect())
}

/// Single-threaded sweep (for benchmarks and reproducible timing).
///
/// # Errors
/// As [`sweep`].
pub fn sweep_serial(
    plant: &PlantParams,
    grid: &Grid,
    opts: IhbOptions,
) -> Result<Vec<SweepPoint>, IvtError> {
    check_plant(plant)?;
    grid.validate()?;
    IhbSolver::new(opts)?;
    let token = ivt_num::cancel::Token::now();
    Ok(grid
        .t_u
        .iter()
        .flat_map(|&t_u| sweep_row(plant, grid, (t_u, token), opts, &|| ()))
        .collect())
}

/// A sweep with no solved point has no answer to report.
///
/// # Errors
/// [`IvtError::AllFailed`] (with the first point's failure) when every point failed.
pub fn require_some_solved(points: &[SweepPoint]) -> Result<(), IvtError> {
    IvtError::unless_some_solved(points.iter().map(|p| &p.result))
}

fn sweep_row(
    plant: &PlantParams,
    grid: &Grid,
    (t_u, token): (f64, ivt_num::cancel::Token),
    opts: IhbOptions,
    progress: &(impl Fn() + Sync),
) -> Vec<SweepPoint> {
    let Ok(mut solver) = IhbSolver::new(opts) else {
        return Vec::new(); // checked by the caller
    };
    let mut warm: Option<(f64, Vec<f64>)> = None;
    grid.v_m
        .iter()
        .map(|&v_m| {
            let op = OperatingPoint {
                v_m,
                t_u,
                omega0: grid.omega0,
            };
            if token.cancelled() {
                return SweepPoint {
                    op,
                    result: Err(ivt_num::cancel::CANCELLED.to_string()),
                };
            }
            let seed = warm.as_ref().map(|(r, q)| (*r, q.as_slice()));
            let mut res = solver.solve(plant, &op, seed);
            if res.is_err() && seed.is_some() {
                res = solver.solve(plant, &op, None); // cold restart
            }
            warm = res.as_ref().ok().map(|s| (s.r, s.q.clone()));
            progress();
            SweepPoint {
                op,
                result: res.map_err(|e| e.to_string()),
            }
        })
        .collect()
}
