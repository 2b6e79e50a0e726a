//! `ivt stability` and `ivt stability-map`: Floquet multipliers of the
//! linearized time-delay loop (thesis §4.3, Eq. 174–179). Gains are given in
//! the thesis's printed unit (mm·rad⁻¹, read as mm of r per rad of θ per rad/s;
//! `k_SI = 1e-3 k`, the same reading as ivt-ctrl) unless `--si` is passed.

use super::ol::PlantArg;
use super::{CliError, Output};
use clap::Args;
use ivt_design::delay::{delay_stability, DelayOptions, FeedbackGains};
use ivt_design::gains::grid_stability_map;
use ivt_design::sweep::{axis, Grid};
use ivt_design::{rpm_to_rad_s, OperatingPoint};
use ivt_kin::params::Typed;
use serde_json::json;

/// Arguments of `ivt stability`.
#[derive(Args)]
pub struct StabilityArgs {
    /// Motor voltage V_m [V].
    #[arg(long, allow_hyphen_values = true)]
    vm: f64,
    /// Brake torque T_U [N·m].
    #[arg(long, allow_hyphen_values = true)]
    tu: f64,
    #[command(flatten)]
    common: Common,
    /// Gain design: search k ∈ [0, K_MAX], k2 ∈ [0, K2_MAX] (same unit as --k)
    /// for the smallest max |multiplier| at this point (grid + one refinement).
    #[arg(long, num_args = 2, value_names = ["K_MAX", "K2_MAX"])]
    design: Option<Vec<f64>>,
    /// Grid points per axis for --design.
    #[arg(long, default_value_t = 9)]
    design_steps: usize,
}

/// Gains and discretization shared by both commands.
#[derive(Args)]
pub struct Common {
    /// Integral gain k (thesis mm·rad⁻¹ unless --si).
    #[arg(long, default_value_t = 0.01)]
    k: f64,
    /// Damping gain k2 (thesis mm·rad⁻¹ unless --si).
    #[arg(long, default_value_t = 0.02)]
    k2: f64,
    /// Gains are SI (m·s/rad²).
    #[arg(long)]
    si: bool,
    /// Chebyshev order N (even).
    #[arg(long, default_value_t = 16)]
    n: usize,
    /// Target mean speed [rpm].
    #[arg(long, default_value_t = 100.0, allow_hyphen_values = true)]
    omega0_rpm: f64,
    #[command(flatten)]
    plant: PlantArg,
}

impl Common {
    /// The gains, each checked through its key (thesis mm·rad⁻¹, or SI
    /// under `--si`).
    fn gains(&self) -> Result<FeedbackGains, CliError> {
        let (k, k2) = if self.si {
            ("controller.k_si", "controller.k2_si")
        } else {
            ("controller.k_mm_per_rad", "controller.k2_mm_per_rad")
        };
        super::check_flag("--k", k, self.k)?;
        super::check_flag("--k2", k2, self.k2)?;
        Ok(if self.si {
            FeedbackGains {
                k: self.k,
                k2: self.k2,
            }
        } else {
            FeedbackGains::from_thesis_mm_per_rad(self.k, self.k2)
        })
    }
    /// The discretization, validated ([`DelayOptions::validate`]).
    fn opts(&self) -> Result<DelayOptions, CliError> {
        let opts = DelayOptions {
            chebyshev_order: self.n,
            ..Default::default()
        };
        opts.validate()?;
        Ok(opts)
    }
    fn omega0(&self) -> Result<f64, CliError> {
        super::check_flag("--omega0-rpm", "controller.omega0_rpm", self.omega0_rpm)?;
        Ok(rpm_to_rad_s(self.omega0_rpm))
    }
}

/// Arguments of `ivt stability-map` (grid as in `ivt ol table`).
#[derive(Args)]
pub struct MapArgs {
    #[command(flatten)]
    common: Common,
    /// V_m from:step:to [V].
    #[arg(long, num_args = 3, default_values_t = [2.0, 0.4, 12.0])]
    vm: Vec<f64>,
    /// T_U from:step:to [N·m].
    #[arg(long, num_args = 3, default_values_t = [1.5, 0.5, 9.0])]
    tu: Vec<f64>,
    /// Only points with a feasible r̄ (0 ≤ r̄ ≤ r_max).
    #[arg(long)]
    feasible_only: bool,
    /// Write a PNG heat map (Fig. 42 analogue): blue 0 → yellow 1, red ≥ 1,
    /// grey = skipped/failed.
    #[arg(long)]
    plot: Option<std::path::PathBuf>,
}

/// `ivt stability`.
///
/// # Errors
/// Bad input or solver failure.
pub fn run(a: StabilityArgs) -> Result<Output, CliError> {
    super::ol::operating_point_flags(a.vm, a.tu, a.common.omega0_rpm)?;
    let op = OperatingPoint {
        v_m: a.vm,
        t_u: a.tu,
        omega0: a.common.omega0()?,
    };
    op.validate()?;
    let g = a.common.gains()?;
    let plant = a.common.plant.params()?;
    let t0 = std::time::Instant::now();
    let s = delay_stability(&plant, &op, g, &a.common.opts()?)?;
    let dt = t0.elapsed().as_secs_f64();
    let design = match &a.design {
        Some(b) => {
            let scale = if a.common.si { 1.0 } else { 1e-3 };
            let (k_max, k2_max) = design_box(b, a.design_steps)?;
            let c = ivt_design::gains::best_gains(
                &plant,
                &op,
                (0.0, k_max * scale),
                (0.0, k2_max * scale),
                a.design_steps,
                &a.common.opts()?,
            )?;
            if c.max_abs_multiplier.is_nan() || c.max_abs_multiplier >= 1.0 {
                return Err(CliError::Failed(format!(
                    "no gains with k ≤ {k_max:e}, k2 ≤ {k2_max:e} give max |multiplier| < 1 \
                     (best found: k = {:e}, k2 = {:e}, max |multiplier| = {})",
                    c.gains.k / scale,
                    c.gains.k2 / scale,
                    c.max_abs_multiplier
                )));
            }
            Some(json!({"k_si": c.gains.k, "k2_si": c.gains.k2,
                        "k": c.gains.k / scale, "k2": c.gains.k2 / scale,
                        "max_abs_multiplier": c.max_abs_multiplier}))
        }
        None => None,
    };
    let json = json!({
        "design": design,
        "max_abs_multiplier": s.max_abs_multiplier, "structural": [s.structural.0, s.structural.1],
        "multipliers": s.multipliers.iter().map(|m| [m.0, m.1]).collect::<Vec<_>>(),
        "r_bar": s.orbit.r, "k_si": g.k, "k2_si": g.k2, "chebyshev_order": a.common.n,
        "stable": s.max_abs_multiplier < 1.0, "solve_time_s": dt,
        "plant": a.common.plant.name(),
    });
    let human = format!(
        "V_m = {} V, T_U = {} N·m, k = {:e}, k2 = {:e} m·s/rad² (N = {})\nr̄ = {:.6} m\nmax |multiplier| = {:.6} (structural one: {:.6}{:+.1e}i)\n",
        a.vm, a.tu, g.k, g.k2, a.common.n, s.orbit.r, s.max_abs_multiplier, s.structural.0, s.structural.1
    );
    Ok(Output { json, human })
}

/// `ivt stability-map`: [`grid_stability_map`] over the `--vm`/`--tu` grid.
///
/// # Errors
/// Bad input, an empty grid, or every point failed.
pub fn run_map(a: MapArgs) -> Result<Output, CliError> {
    let grid = Grid {
        v_m: grid_axis("--vm", "inputs.v_m[]", &a.vm)?,
        t_u: grid_axis("--tu", "inputs.t_u[]", &a.tu)?,
        omega0: a.common.omega0()?,
    };
    let plant = a.common.plant.params()?;
    let g = a.common.gains()?;
    let t0 = std::time::Instant::now();
    let map = grid_stability_map(&plant, &grid, a.feasible_only, g, &a.common.opts()?)?;
    let dt = t0.elapsed().as_secs_f64();
    let pts: Vec<_> = map
        .entries
        .iter()
        .map(|(op, r)| match r {
            Ok(m) => json!({"vm": op.v_m, "tu": op.t_u, "max_abs_multiplier": m}),
            Err(e) => json!({"vm": op.v_m, "tu": op.t_u, "error": e}),
        })
        .collect();
    let json = json!({"points": pts, "worst": map.worst, "failed": map.failed, "k_si": g.k,
                      "k2_si": g.k2, "solve_time_s": dt,
                      "plant": a.common.plant.name()});
    if let Some(path) = &a.plot {
        let values = map.values(&grid);
        let title = format!(
            "max |multiplier|, k = {:.3e}, k2 = {:.3e} m·s/rad² (N = {})",
            g.k, g.k2, a.common.n
        );
        let heat = ivt_plot::HeatMap {
            title: &title,
            x_label: "V_m [V]",
            y_label: "T_U [N·m]",
            value_label: "max |μ| (≥ 1 unstable)",
            xs: &grid.v_m,
            ys: &grid.t_u,
            values: &values,
        };
        super::write_figure(path, |tmp| ivt_plot::heat_map(tmp, &heat))?;
    }
    let human = format!(
        "{} points ({} failed), worst max |multiplier| = {:.6}, {:.2} s\n",
        map.entries.len(),
        map.failed,
        map.worst,
        dt
    );
    Ok(Output { json, human })
}

/// One `FROM STEP TO` axis of `stability-map`, refused by name when FROM or
/// TO is outside `key`'s range, or the axis is not increasing or longer than
/// [`ivt_design::sweep::MAX_AXIS_POINTS`].
fn grid_axis(name: &'static str, key: &str, v: &[f64]) -> Result<Vec<f64>, CliError> {
    let &[from, step, to] = v else {
        return Err(CliError::Input(format!("{name} takes FROM STEP TO")));
    };
    super::check_flag(name, key, from)?;
    super::check_flag(name, key, to)?;
    Ok(axis(name, from, step, to)?)
}

/// Most grid values per gain axis of `--design` (steps² solves per round).
const MAX_DESIGN_STEPS: usize = 64;

/// The `--design K_MAX K2_MAX` box, refused by name unless both bounds are
/// finite and > 0 and `--design-steps` is in 2..=[`MAX_DESIGN_STEPS`].
fn design_box(b: &[f64], steps: usize) -> Result<(f64, f64), CliError> {
    let &[k_max, k2_max] = b else {
        return Err(CliError::Input("--design takes K_MAX K2_MAX".into()));
    };
    for (name, v) in [("K_MAX", k_max), ("K2_MAX", k2_max)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(CliError::Input(format!(
                "--design {name} must be finite and > 0, got {}",
                Typed(v)
            )));
        }
    }
    if !(2..=MAX_DESIGN_STEPS).contains(&steps) {
        return Err(CliError::Input(format!(
            "--design-steps must be in 2..={MAX_DESIGN_STEPS} (steps² stability solves per round), got {steps}"
        )));
    }
    Ok((k_max, k2_max))
}
