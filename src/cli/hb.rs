//! `ivt hb ...`: harmonic balance (thesis §3.2) — Duffing by modified/classic IHB
//! with Floquet stability, the Duffing frequency-response curve, and the
//! Mathieu–Duffing period-doubling cascade, the fold curve in (ω, F), limit
//! cycles and the Duffing backbone; `frc` and `solve` on a user's model file. `--plot FILE.png` draws the result
//! (`figure.rs`: the pictures of `ivt.plot`).
//! Each command parses its arguments, runs an `ivt_jobs` job and prints
//! its serialized result (the keys of `ivt.hb`'s dicts).

mod all_solutions;
mod autonomous;
mod cycle_branch;
mod diagram;
pub(super) mod figure;
mod folds;
mod matrix_market;
mod model_file;
mod switch;
mod torus;
mod torus_branch;
mod user_model;

use super::{CliError, Output};
use clap::{Args, Subcommand};
use figure::Picture;
use ivt_hb::orbit::aft::eval_series;
use ivt_hb::{Duffing, FrcOptions, HbOptions};
use ivt_jobs::{self as jobs, CascadeRequest, FrcRequest, Method, OrbitRequest};
use ivt_kin::params::Typed;
use ivt_plot::Style;
use std::f64::consts::PI;
use std::path::PathBuf;

/// Harmonic-balance subcommands.
#[derive(Subcommand)]
pub enum HbCommand {
    /// Frequency-response curve of a user's model file (M, C, K, elements,
    /// forcing; the JSON of `ivt.hb.frc`).
    Frc(user_model::FrcArgs),
    /// Periodic solution of a user's model file at one ω_f (the JSON of `ivt.hb.solve`).
    Solve(user_model::SolveArgs),
    /// Periodic solution of Duffing's equation Eq. 49 (Fig. 28) with Floquet multipliers.
    Duffing(DuffingArgs),
    /// Frequency-response curve of Duffing's equation with stability (Fig. 29).
    DuffingFrc(FrcArgs),
    /// The folds of Duffing's frequency response followed in the force F, through the cusp.
    DuffingFolds(folds::FoldsArgs),
    /// The Neimark–Sacker curve of the forced Van der Pol oscillator in (ω_f, F), to its 1:1 end.
    VdpTorus(torus::TorusArgs),
    /// The quasi-periodic torus of the forced Van der Pol oscillator from its Neimark–Sacker point.
    Torus(torus_branch::TorusBranchArgs),
    /// The automatic bifurcation diagram of the 2-DOF cubic chain.
    Diagram(diagram::DiagramArgs),
    /// Limit cycle of Van der Pol's or Rayleigh's oscillator (ω unknown, §3.2.4) with its multipliers.
    LimitCycle(autonomous::LimitCycleArgs),
    /// Backbone curve (nonlinear normal mode) of the free Duffing oscillator u'' + αu + εu³ = 0.
    DuffingBackbone(autonomous::BackboneArgs),
    /// Hopf point and limit-cycle branch of ẍ − (μ + x² − x⁴)ẋ + x = 0, with stability and folds.
    CycleBranch(cycle_branch::CycleBranchArgs),
    /// Every period-one orbit of Duffing's equation at one ω_f (deflated Newton), with stability.
    AllSolutions(all_solutions::AllSolutionsArgs),
    /// Branch switching at a period doubling of the Duffing oscillator in a well: its period-2 branch.
    Switch(switch::SwitchArgs),
    /// Period-doubling cascade of the Mathieu–Duffing equation (§3.2.5).
    MathieuDuffing(MathieuArgs),
    /// Nonlinear string by STHB (§3.3): frequency–response curve with stability (Figs. 34–36).
    String(super::string::StringArgs),
}

/// Duffing parameters shared by `duffing` and `duffing-frc` (defaults: Fig. 28).
#[derive(Args, Clone)]
pub struct DuffingParams {
    /// Harmonics n.
    #[arg(long, default_value_t = 20)]
    n: usize,
    /// Half the number of AFT samples N (2N samples, N > n).
    #[arg(long, default_value_t = 64)]
    samples: usize,
    /// Damping ratio ξ.
    #[arg(long, default_value_t = 0.02)]
    xi: f64,
    /// Linear stiffness α.
    #[arg(long, default_value_t = 1.0)]
    alpha: f64,
    /// Cubic stiffness ε.
    #[arg(long, default_value_t = 1.0)]
    eps: f64,
    /// Forcing amplitude F.
    #[arg(long, default_value_t = 0.1)]
    force: f64,
    /// Absolute residual tolerance on ‖r‖₂.
    #[arg(long, default_value_t = 1e-10)]
    tol: f64,
}

impl DuffingParams {
    fn problem(&self) -> Result<Duffing, CliError> {
        let d = Duffing::new(self.xi, self.alpha, self.eps, self.force);
        if !d.is_finite() {
            return Err(CliError::Input("Duffing parameters must be finite".into()));
        }
        Ok(d)
    }
    /// `--tol` is an absolute bound on ‖r‖₂ (no relative part), so it must be
    /// positive itself.
    fn options(&self) -> Result<HbOptions, CliError> {
        if !(self.tol.is_finite() && self.tol > 0.0) {
            return Err(CliError::Input(format!(
                "--tol must be finite and > 0, got {}",
                Typed(self.tol)
            )));
        }
        Ok(HbOptions::new(self.n, self.samples).with_tol(self.tol))
    }
}

/// `ivt hb duffing`.
#[derive(Args)]
pub struct DuffingArgs {
    #[command(flatten)]
    params: DuffingParams,
    /// Excitation frequency ω_f.
    #[arg(long, default_value_t = 0.4)]
    omega_f: f64,
    /// IHB variant: `modified` (§3.2.2, AFT + Broyden seeded with the linear
    /// Jacobian) or `classic` (§3.2.1, Newton with the Galerkin Jacobian).
    #[arg(long, default_value = "modified")]
    method: Method,
    /// Write a PNG of x(t) over one period.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// `ivt hb duffing-frc`.
#[derive(Args)]
pub struct FrcArgs {
    #[command(flatten)]
    params: DuffingParams,
    /// Start frequency.
    #[arg(long, default_value_t = 0.2)]
    from: f64,
    /// End frequency.
    #[arg(long, default_value_t = 3.0)]
    to: f64,
    /// Also locate period doublings, Neimark–Sacker and branch points (the
    /// start by the modified IHB, every event on its extended system).
    #[arg(long)]
    events: bool,
    /// Write a PNG of amplitude vs ω_f: stable solid, unstable dashed, the
    /// events marked and labelled (fold, PD, NS, BP).
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// `ivt hb mathieu-duffing` (defaults: §3.2.5).
#[derive(Args)]
pub struct MathieuArgs {
    /// Damping ratio ξ̂.
    #[arg(long, default_value_t = 0.125)]
    xi: f64,
    /// Stiffness α̂ (enters as −α̂).
    #[arg(long, default_value_t = 1.0)]
    alpha: f64,
    /// Parametric excitation frequency Ω.
    #[arg(long, default_value_t = 2.0)]
    omega: f64,
    /// Cubic stiffness γ.
    #[arg(long, default_value_t = 1.0)]
    gamma: f64,
    /// Harmonics of the period-1 solution (period 2^k uses 2^k n).
    #[arg(long, default_value_t = 12)]
    n: usize,
    /// Write a PNG of the critical period-1, -2 and -4 solutions.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// Run a harmonic-balance subcommand.
///
/// # Errors
/// [`CliError::Input`] for bad parameters, [`CliError::Failed`] when a solver
/// does not converge (the message carries the residual history summary).
pub fn run(cmd: HbCommand) -> Result<Output, CliError> {
    match cmd {
        HbCommand::Frc(a) => user_model::frc(a),
        HbCommand::Solve(a) => user_model::solve(a),
        HbCommand::Duffing(a) => duffing(a),
        HbCommand::DuffingFrc(a) => duffing_frc(a),
        HbCommand::DuffingFolds(a) => folds::run(a),
        HbCommand::VdpTorus(a) => torus::run(a),
        HbCommand::Torus(a) => torus_branch::run(a),
        HbCommand::Diagram(a) => diagram::run(a),
        HbCommand::LimitCycle(a) => autonomous::limit_cycle(a),
        HbCommand::DuffingBackbone(a) => autonomous::backbone(a),
        HbCommand::CycleBranch(a) => cycle_branch::run(a),
        HbCommand::AllSolutions(a) => all_solutions::run(a),
        HbCommand::Switch(a) => switch::run(a),
        HbCommand::MathieuDuffing(a) => mathieu(a),
        HbCommand::String(a) => super::string::run(a),
    }
}

/// One line on an orbit: iterations, residual, solve time, amplitude and
/// the Floquet verdict.
fn orbit_summary(orbit: &jobs::Orbit) -> String {
    format!(
        "{} iterations, ‖r‖ = {:.2e}, {:.1} µs, amplitude {:.6}, {} (|μ|max = {:.6})\n",
        orbit.iterations,
        orbit.residual_norm,
        orbit.solve_time_s * 1e6,
        orbit.amplitude,
        orbit.stability.map_or("unknown", |k| k.name()),
        orbit.max_modulus()
    )
}

/// One line per point a path passed but could not locate: what, the value
/// sought, the path parameter `p_name` where the locator started, the reason.
fn unlocated_lines(unlocated: &[jobs::UnlocatedPoint], p_name: &str) -> String {
    let mut out = String::new();
    for u in unlocated {
        let value = u
            .value
            .map_or(String::new(), |v| format!(" at {p_name} = {v}"));
        out += &format!(
            "  {}{value} not located (from {p_name} = {:.8}): {}\n",
            u.what, u.near.p, u.reason
        );
    }
    out
}

/// The JSON object of a job's result.
fn to_json<T: serde::Serialize>(result: &T) -> Result<serde_json::Value, CliError> {
    serde_json::to_value(result).map_err(|e| CliError::Failed(e.to_string()))
}

fn duffing(a: DuffingArgs) -> Result<Output, CliError> {
    let problem = a.params.problem()?;
    let req = OrbitRequest {
        omega_f: a.omega_f,
        method: a.method,
        ..OrbitRequest::default()
    };
    let orbit = jobs::orbit(&problem, &a.params.options()?, &req)?;
    if let Some(path) = &a.plot {
        let sol = &orbit.solution;
        let period = 2.0 * PI / sol.omega();
        let pts: Vec<(f64, f64)> = (0..=400)
            .map(|i| {
                let t = period * f64::from(i) / 400.0;
                (t, sol.x_at(0, t))
            })
            .collect();
        Picture::new(format!("Duffing, ω_f = {}", a.omega_f), "t", "x")
            .with("HB", pts, Style::Line)
            .draw(path)?;
    }
    let human = format!("Duffing ω_f = {}: {}", a.omega_f, orbit_summary(&orbit));
    Ok(Output {
        json: to_json(&orbit)?,
        human,
    })
}

fn duffing_frc(a: FrcArgs) -> Result<Output, CliError> {
    let problem = a.params.problem()?;
    let req = FrcRequest {
        options: FrcOptions {
            from: a.from,
            to: a.to,
            ..FrcOptions::default()
        },
        events: a.events,
    };
    let frc = jobs::frc(&problem, &a.params.options()?, &req)?.with_fold_omegas();
    if let Some(path) = &a.plot {
        figure::frc("Duffing frequency response", &frc).draw(path)?;
    }
    let human = format!(
        "{} points from ω_f = {} to {}, folds at {:?}, {} events, {:.1} ms\n",
        frc.points.len(),
        a.from,
        a.to,
        frc.folds,
        frc.bifurcations.len(),
        frc.time_s * 1e3
    );
    Ok(Output {
        json: to_json(&frc)?,
        human,
    })
}

fn mathieu(a: MathieuArgs) -> Result<Output, CliError> {
    let req = CascadeRequest {
        xi: a.xi,
        alpha: a.alpha,
        omega: a.omega,
        gamma: a.gamma,
        harmonics: a.n,
        ..CascadeRequest::default()
    };
    let cascade = jobs::cascade(&req)?;
    if let Some(path) = &a.plot {
        let names = ["period 1 at β1", "period 2 at β2", "period 4 at β4"];
        let portraits = cascade.doublings.iter().zip(names).map(|(p, name)| {
            let pts = (0..=800)
                .map(|j| {
                    let tau = 2.0 * PI * f64::from(j) / 800.0;
                    (
                        eval_series(p.solution.dof(0), tau, 0),
                        eval_series(p.solution.dof(0), tau, 1) * p.solution.omega(),
                    )
                })
                .collect();
            (name, pts)
        });
        portraits
            .fold(
                Picture::new("Mathieu–Duffing critical orbits", "x", "dx/dt"),
                |fig, (name, pts)| fig.with(name, pts, Style::Line),
            )
            .draw(path)?;
    }
    let human = format!(
        "period doubling at β = {:?} (thesis 4.825, 5.194, 5.253), {:.1} ms\n",
        cascade.period_doubling_beta,
        cascade.time_s * 1e3
    );
    Ok(Output {
        json: to_json(&cascade)?,
        human,
    })
}
