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

    /// Reject empty axes and non-finite entries.
    ///
    /// # Errors
    /// [`IvtError::EmptyGrid`] or [`IvtError::Input`].
    pub fn validate(&self) -> Result<(), IvtError> {
        if self.v_m.is_empty() {
            return Err(IvtError::EmptyGrid("no V_m values"));
        }
        if self.t_u.is_empty() {
            return Err(IvtError::EmptyGrid("no T_U values"));
        }
        for &v in &self.v_m {
            OperatingPoint {
                v_m: v,
                t_u: self.t_u[0],
                omega0: self.omega0,
            }
            .validate()?;
        }
        for &t in &self.t_u {
            OperatingPoint {
                v_m: self.v_m[0],
                t_u: t,
                omega0: self.omega0,
            }
            .validate()?;
        }
        Ok(())
    }
}

/// `from:step:to` inclusive (MATLAB style), robust to rounding at the end.
/// Empty if step ≤ 0 or to < from.
pub fn range(from: f64, step: f64, to: f64) -> Vec<f64> {
    if !(step > 0.0 && to >= from && from.is_finite() && to.is_finite()) {
        return Vec::new();
    }
    let n = ((to - from) / step + 1e-9).floor() as usize;
    (0..=n).map(|i| from + i as f64 * step).collect()
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
    let rows: Vec<Vec<SweepPoint>> = grid
        .t_u
        .par_iter()
        .map(|&t_u| sweep_row(plant, grid, t_u, opts, &progress))
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
    Ok(grid
        .t_u
        .iter()
        .flat_map(|&t_u| sweep_row(plant, grid, t_u, opts, &|| ()))
        .collect())
}

fn sweep_row(
    plant: &PlantParams,
    grid: &Grid,
    t_u: f64,
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
