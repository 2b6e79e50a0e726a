//! `ivt ol ...`: the open-loop law from the model (thesis §4.2.1): one IHB
//! steady state, the grid table, and the refit (with `--emit-rust`).

use super::{CliError, Output};
use clap::{Args, Subcommand};
use ivt_design::fit::{self, PolyForm};
use ivt_design::open_loop::fit_law;
use ivt_design::polish::{self, accurate_r};
use ivt_design::steady::IhbOptions;
use ivt_design::sweep::{self, Grid, SweepPoint};
use ivt_design::{rad_s_to_rpm, rpm_to_rad_s, OperatingPoint};
use ivt_kin::plant::{PlantParams, PlantPreset};
use serde_json::json;
use std::path::PathBuf;

/// `--plant printed|thesis-ch4` or `--plant-file P.toml` (SPEC §6), shared
/// by `ivt ol` and `ivt stability(-map)`.
#[derive(Args, Clone)]
pub struct PlantArg {
    /// Plant parameter set: `printed` (Table 1) or `thesis-ch4` (k_t, k_e ÷ 10).
    #[arg(long = "plant", default_value = "printed", value_parser = parse_plant)]
    pub preset: PlantPreset,
    /// A plant file: a `[plant]` table (preset + overrides) as in scenes,
    /// e.g. written by `ivt rig identify --out`. Replaces `--plant`.
    #[arg(long = "plant-file", conflicts_with = "preset")]
    pub file: Option<PathBuf>,
}

impl PlantArg {
    /// The plant's parameters: the preset, or the plant file's table.
    ///
    /// # Errors
    /// An unreadable plant file ([`CliError::Io`]) or an invalid one
    /// ([`CliError::Input`], naming the file, line and key).
    pub fn params(&self) -> Result<PlantParams, CliError> {
        match &self.file {
            None => Ok(self.preset.params()),
            Some(path) => ivt_sim::scene::PlantSection::from_file(path)?
                .params()
                .map_err(|e| CliError::Input(format!("{}: {e}", path.display()))),
        }
    }

    /// What JSON and emitted headers call the plant: the preset's name or
    /// the plant file's path.
    pub fn name(&self) -> String {
        match &self.file {
            None => self.preset.name().to_string(),
            Some(path) => path.display().to_string(),
        }
    }
}

fn parse_plant(name: &str) -> Result<PlantPreset, String> {
    PlantPreset::from_name(name).ok_or_else(|| {
        let names: Vec<_> = PlantPreset::ALL.iter().map(|p| p.name()).collect();
        format!(
            "unknown plant `{name}`, expected one of {}",
            names.join(", ")
        )
    })
}

/// Open-loop design subcommands.
#[derive(Subcommand)]
pub enum OlCommand {
    /// IVT steady state at one point: unconstrained r̄ and the verdict.
    Solve(SolveArgs),
    /// r̄ over the grid (thesis Fig. 38(a)).
    Table(GridArgs),
    /// Refit the Eq. 158 form (and Eq. 159 boundary) to the feasible grid points.
    Fit(FitArgs),
}

/// Arguments of `ivt ol solve`.
#[derive(Args)]
pub struct SolveArgs {
    /// Motor voltage V_m [V].
    #[arg(long, allow_hyphen_values = true)]
    vm: f64,
    /// Brake torque T_U [N·m].
    #[arg(long, allow_hyphen_values = true)]
    tu: f64,
    /// How r̄ is computed: `polish` (default) refines the IHB by θ-shooting
    /// (≤ 1e-9 relative); `ihb` reports the n-harmonic IHB alone (n = 7, the
    /// thesis's choice, is ~3 % off), with |r̄(n) − r̄(2n+1)| as its error estimate.
    #[arg(long, value_enum, default_value_t = MethodArg::Polish)]
    method: MethodArg,
    /// Target mean speed [rpm].
    #[arg(long, default_value_t = 100.0, allow_hyphen_values = true)]
    omega0_rpm: f64,
    /// Harmonics n of the IHB (thesis: 7).
    #[arg(long, default_value_t = 7)]
    harmonics: usize,
    #[command(flatten)]
    plant: PlantArg,
}

/// How `ivt ol solve` computes r̄ ([`polish::SolveMethod`]).
#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum MethodArg {
    /// IHB seed polished by θ-shooting (Eq. 162 integrated in θ by RK6).
    Polish,
    /// The n-harmonic IHB alone (§4.2.1).
    Ihb,
}

impl From<MethodArg> for polish::SolveMethod {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Polish => polish::SolveMethod::Polish,
            MethodArg::Ihb => polish::SolveMethod::Ihb,
        }
    }
}

/// Grid arguments shared by `table` and `fit` (MATLAB-style from:step:to).
#[derive(Args)]
pub struct GridArgs {
    /// V_m from [V].
    #[arg(long, default_value_t = 2.0)]
    vm_from: f64,
    /// V_m step [V].
    #[arg(long, default_value_t = 0.4)]
    vm_step: f64,
    /// V_m to [V].
    #[arg(long, default_value_t = 12.0)]
    vm_to: f64,
    /// T_U from [N·m].
    #[arg(long, default_value_t = 1.5)]
    tu_from: f64,
    /// T_U step [N·m].
    #[arg(long, default_value_t = 0.5)]
    tu_step: f64,
    /// T_U to [N·m].
    #[arg(long, default_value_t = 9.0)]
    tu_to: f64,
    /// Target mean speed [rpm].
    #[arg(long, default_value_t = 100.0, allow_hyphen_values = true)]
    omega0_rpm: f64,
    /// Harmonics n of the IHB.
    #[arg(long, default_value_t = 7)]
    harmonics: usize,
    /// No progress bar on stderr.
    #[arg(long)]
    quiet: bool,
    #[command(flatten)]
    plant: PlantArg,
}

/// Arguments of `ivt ol fit`.
#[derive(Args)]
pub struct FitArgs {
    #[command(flatten)]
    grid: GridArgs,
    /// Use all 15 terms V^0..2 T^0..4 instead of the 10 of Eq. 158.
    #[arg(long)]
    full: bool,
    /// Write `pub const REFIT: OpenLoopCoeffs` for ivt-ctrl to this file.
    #[arg(long)]
    emit_rust: Option<std::path::PathBuf>,
}

/// Run an `ol` subcommand.
///
/// # Errors
/// Bad arguments ([`CliError::Input`]) or solver failures ([`CliError::Failed`]).
pub fn run(cmd: OlCommand) -> Result<Output, CliError> {
    match cmd {
        OlCommand::Solve(a) => solve(a),
        OlCommand::Table(a) => table(a),
        OlCommand::Fit(a) => fit_cmd(a),
    }
}

fn solve(a: SolveArgs) -> Result<Output, CliError> {
    operating_point_flags(a.vm, a.tu, a.omega0_rpm)?;
    let plant = a.plant.params()?;
    let op = OperatingPoint {
        v_m: a.vm,
        t_u: a.tu,
        omega0: rpm_to_rad_s(a.omega0_rpm),
    };
    op.validate()?;
    let opts = IhbOptions {
        harmonics: a.harmonics,
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let acc = accurate_r(&plant, &op, opts, a.method.into())?;
    let dt = t0.elapsed().as_secs_f64();
    let s = &acc.ihb;
    let verdict = ivt_design::Verdict::classify(acc.r, plant.r_max);
    let thesis_choice = a.method == MethodArg::Ihb && a.harmonics == 7;
    let json = json!({
        "r": acc.r, "feasible": verdict == ivt_design::Verdict::Feasible,
        "verdict": verdict.as_str(), "q": s.q, "omega_min": acc.omega_min,
        "omega_max": acc.omega_max, "solve_time_s": dt, "iterations": s.iterations,
        "residual_norm": s.residual_norm, "harmonics": a.harmonics, "r_max": plant.r_max,
        "omega0": op.omega0, "method": acc.method.label(), "r_ihb": s.r,
        "error_estimate": {"r_abs": acc.error_abs, "r_rel": acc.error_abs / acc.r.abs(),
                           "how": acc.how},
        "thesis_choice": thesis_choice,
        "plant": a.plant.name(),
    });
    let label = if thesis_choice {
        " — n = 7, the thesis's choice"
    } else {
        ""
    };
    let human = format!(
        "V_m = {} V, T_U = {} N·m, ω0 = {} rpm\nr̄ = {:.7} m ± {:.1e} ({}{label}; {}; r_max = {} m)\nω̄ ∈ [{:.2}, {:.2}] rpm\n{} Newton iterations, |R| = {:.1e}, {:.1} µs\n",
        a.vm, a.tu, a.omega0_rpm, acc.r, acc.error_abs, acc.method.label(), verdict.as_str(), plant.r_max,
        rad_s_to_rpm(acc.omega_min), rad_s_to_rpm(acc.omega_max), s.iterations, s.residual_norm, dt * 1e6
    );
    Ok(Output { json, human })
}

/// `--vm`, `--tu` and `--omega0-rpm` of one operating point, each checked
/// through its key (shared by `ol solve` and `stability`).
///
/// # Errors
/// [`CliError::Input`] naming the flag and the value as typed.
pub fn operating_point_flags(vm: f64, tu: f64, omega0_rpm: f64) -> Result<(), CliError> {
    super::check_flag("--vm", "inputs.v_m[]", vm)?;
    super::check_flag("--tu", "inputs.t_u[]", tu)?;
    super::check_flag("--omega0-rpm", "controller.omega0_rpm", omega0_rpm)
}

/// The grid of `table`/`fit` from its arguments, validated.
fn grid_of(a: &GridArgs) -> Result<Grid, CliError> {
    super::check_flag("--omega0-rpm", "controller.omega0_rpm", a.omega0_rpm)?;
    for (flag, v) in [("--vm-from", a.vm_from), ("--vm-to", a.vm_to)] {
        super::check_flag(flag, "inputs.v_m[]", v)?;
    }
    for (flag, v) in [("--tu-from", a.tu_from), ("--tu-to", a.tu_to)] {
        super::check_flag(flag, "inputs.t_u[]", v)?;
    }
    let grid = Grid {
        v_m: sweep::axis("--vm-step", a.vm_from, a.vm_step, a.vm_to)?,
        t_u: sweep::axis("--tu-step", a.tu_from, a.tu_step, a.tu_to)?,
        omega0: rpm_to_rad_s(a.omega0_rpm),
    };
    grid.validate()?;
    Ok(grid)
}

fn ihb_options(a: &GridArgs) -> IhbOptions {
    IhbOptions {
        harmonics: a.harmonics,
        ..Default::default()
    }
}

/// One tick per grid point on stderr, hidden under `--quiet`.
fn progress_bar(a: &GridArgs, grid: &Grid) -> indicatif::ProgressBar {
    if a.quiet {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(grid.len() as u64)
    }
}

fn point_json(p: &SweepPoint) -> serde_json::Value {
    match &p.result {
        Ok(s) => json!({"vm": p.op.v_m, "tu": p.op.t_u, "r": s.r, "verdict": s.verdict.as_str(),
                        "omega_min": s.omega_min, "omega_max": s.omega_max}),
        Err(e) => json!({"vm": p.op.v_m, "tu": p.op.t_u, "error": e}),
    }
}

fn table(a: GridArgs) -> Result<Output, CliError> {
    let grid = grid_of(&a)?;
    let bar = progress_bar(&a, &grid);
    let pts = sweep::sweep(&a.plant.params()?, &grid, ihb_options(&a), || bar.inc(1))?;
    bar.finish_and_clear();
    sweep::require_some_solved(&pts)?;
    let mut human = format!("r̄ [mm] (rows T_U, columns V_m = {:?})\n", grid.v_m);
    for row in pts.chunks(grid.v_m.len()) {
        let t_u = row.first().map_or(f64::NAN, |p| p.op.t_u);
        human.push_str(&format!("T_U {t_u:>4}:"));
        for p in row {
            match &p.result {
                Ok(s) => human.push_str(&format!(" {:7.2}", s.r * 1e3)),
                Err(_) => human.push_str("    fail"),
            }
        }
        human.push('\n');
    }
    let json = json!({"v_m": grid.v_m, "t_u": grid.t_u, "omega0": grid.omega0,
                      "plant": a.plant.name(),
                      "points": pts.iter().map(point_json).collect::<Vec<_>>()});
    Ok(Output { json, human })
}

fn fit_cmd(a: FitArgs) -> Result<Output, CliError> {
    let plant = a.grid.plant.params()?;
    let grid = grid_of(&a.grid)?;
    let form = if a.full {
        PolyForm::Full
    } else {
        PolyForm::Eq158
    };
    let bar = progress_bar(&a.grid, &grid);
    let rep = fit_law(&plant, &grid, form, ihb_options(&a.grid), || bar.inc(1))?;
    bar.finish_and_clear();
    let (pf, law, err, thesis_err) = (&rep.fit, &rep.law, &rep.law_error, &rep.thesis_error);
    let (alpha, beta, b_err) = (
        rep.overdrive.alpha,
        rep.overdrive.beta,
        rep.overdrive.max_dev_v,
    );
    let (alpha0, beta0) = (rep.underdrive.alpha, rep.underdrive.beta);
    if let Some(path) = &a.emit_rust {
        let header = format!(
            "Open-loop law refitted on the {} plant (Eq. 151) by `ivt ol fit{}`:\n\
             IHB (n = {}) over V_m ∈ {}:{}:{} V, T_U ∈ {}:{}:{} N·m, ω0 = {} rpm; {} feasible points.\n\
             Fit error in r: RMS {:.3e} m, max {:.3e} m. ω_a error of the clamped law: max {:.3} rpm, RMS {:.3} rpm.\n\
             Boundary r̄ = r_max: V_m = {:.4} T_U + {:.4} (max deviation {:.3} V).",
            a.grid.plant.name(), if a.full { " --full" } else { "" }, a.grid.harmonics,
            a.grid.vm_from, a.grid.vm_step, a.grid.vm_to, a.grid.tu_from, a.grid.tu_step, a.grid.tu_to,
            a.grid.omega0_rpm, pf.points, pf.rms_r, pf.max_r, err.max_abs_rpm, err.rms_rpm, alpha, beta, b_err
        );
        super::write_atomic(path, fit::emit_rust(law, "REFIT", &header).as_bytes())?;
    }
    let json = json!({
        "poly": pf.poly, "boundary": law.boundary, "r_max": law.r_max,
        "form": if a.full { "full" } else { "eq158" }, "points": pf.points,
        "plant": a.grid.plant.name(),
        "rms_r": pf.rms_r, "max_r": pf.max_r,
        "omega_a_error_rpm": {"max_abs": err.max_abs_rpm, "rms": err.rms_rpm},
        "thesis_omega_a_error_rpm": {"max_abs": thesis_err.max_abs_rpm, "rms": thesis_err.rms_rpm},
        "boundary_max_dev_v": b_err,
        "underdrive_boundary": {"alpha": alpha0, "beta": beta0},
        "emitted": a.emit_rust.as_ref().map(|p| p.display().to_string()),
    });
    let human = format!(
        "feasible points: {}\nfit error in r: RMS {:.3e} m, max {:.3e} m\n\
         ω_a error of refit law: max {:.3} rpm, RMS {:.3} rpm\n\
         ω_a error of THESIS law: max {:.3} rpm, RMS {:.3} rpm\n\
         over-drive boundary (r̄ = r_max): V_m = {:.4}·T_U + {:.4}\n\
         under-drive boundary (r̄ = 0):    V_m = {:.4}·T_U + {:.4}\npoly[i][j] (V^i T^j): {:?}\n",
        pf.points,
        pf.rms_r,
        pf.max_r,
        err.max_abs_rpm,
        err.rms_rpm,
        thesis_err.max_abs_rpm,
        thesis_err.rms_rpm,
        alpha,
        beta,
        alpha0,
        beta0,
        pf.poly
    );
    Ok(Output { json, human })
}
