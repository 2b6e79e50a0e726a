//! `ivt hb ...`: harmonic balance (thesis §3.2) — Duffing by modified/classic IHB
//! with Floquet stability, the Duffing frequency-response curve, and the
//! Mathieu–Duffing period-doubling cascade. `--plot FILE.png` draws the curves.

mod folds;

use super::{CliError, Output};
use clap::{Args, Subcommand, ValueEnum};
use ivt_hb::aft::eval_series;
use ivt_hb::{
    frequency_response, period_doubling_cascade, CascadeOptions, ClassicIhb, Duffing, FrcOptions,
    HbOptions, HsuRule, ModifiedIhb, StabilityAnalyzer,
};
use serde_json::json;
use std::f64::consts::PI;
use std::path::PathBuf;

/// Harmonic-balance subcommands.
#[derive(Subcommand)]
pub enum HbCommand {
    /// Periodic solution of Duffing's equation Eq. 49 (Fig. 28) with Floquet multipliers.
    Duffing(DuffingArgs),
    /// Frequency-response curve of Duffing's equation with stability (Fig. 29).
    DuffingFrc(FrcArgs),
    /// The folds of Duffing's frequency response followed in the force F, through the cusp.
    DuffingFolds(folds::FoldsArgs),
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
                self.tol
            )));
        }
        Ok(HbOptions::new(self.n, self.samples).with_tol(self.tol))
    }
}

/// Which IHB variant.
#[derive(ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// §3.2.2: AFT + Broyden seeded with the linear Jacobian.
    Modified,
    /// §3.2.1: Newton with the Galerkin Jacobian.
    Classic,
}

/// `ivt hb duffing`.
#[derive(Args)]
pub struct DuffingArgs {
    #[command(flatten)]
    params: DuffingParams,
    /// Excitation frequency ω_f.
    #[arg(long, default_value_t = 0.4)]
    omega_f: f64,
    /// IHB variant.
    #[arg(long, value_enum, default_value_t = Method::Modified)]
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
    /// Write a PNG of amplitude vs ω_f (stable solid, unstable red).
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
        HbCommand::Duffing(a) => duffing(a),
        HbCommand::DuffingFrc(a) => duffing_frc(a),
        HbCommand::DuffingFolds(a) => folds::run(a),
        HbCommand::MathieuDuffing(a) => mathieu(a),
        HbCommand::String(a) => super::string::run(a),
    }
}

fn hb_err(e: ivt_hb::HbError) -> CliError {
    match e {
        ivt_hb::HbError::Solve(s) => {
            CliError::Failed(format!("{s}; ‖r‖ history {:?}", s.history()))
        }
        e @ (ivt_hb::HbError::ContinuationStart { .. } | ivt_hb::HbError::SingularStart { .. }) => {
            CliError::Failed(e.to_string())
        }
        other => CliError::Input(other.to_string()),
    }
}

fn duffing(a: DuffingArgs) -> Result<Output, CliError> {
    let problem = a.params.problem()?;
    let opts = a.params.options()?;
    let t0 = std::time::Instant::now();
    let sol = match a.method {
        Method::Modified => {
            ModifiedIhb::new(problem.clone(), opts).and_then(|mut s| s.solve(a.omega_f, None))
        }
        Method::Classic => {
            ClassicIhb::new(problem.clone(), opts).and_then(|mut s| s.solve(a.omega_f, None))
        }
    }
    .map_err(hb_err)?;
    let solve_time_s = t0.elapsed().as_secs_f64();
    let steps = (8 * a.params.n).max(256);
    let floquet = StabilityAnalyzer::new(&problem, a.params.n, steps)
        .map_err(|e| CliError::Input(e.to_string()))?
        .hsu(&problem, &sol, HsuRule::Magnus4);
    if !floquet
        .multipliers
        .iter()
        .all(|m| m.re.is_finite() && m.im.is_finite())
    {
        return Err(CliError::Failed(format!(
            "the Floquet multipliers at ω_f = {} are not finite (Hsu's method over {steps} steps \
             of one period 2π/ω_f); the stability of this solution is unknown",
            a.omega_f
        )));
    }
    let mults: Vec<[f64; 2]> = floquet.multipliers.iter().map(|m| [m.re, m.im]).collect();
    let json = json!({
        "coeffs": sol.coeffs,
        "iterations": sol.stats.iterations,
        "residual_norm": sol.stats.residual_norm,
        "solve_time_s": solve_time_s,
        "floquet": mults,
        "stable": floquet.stable(),
        "stability": floquet.kind.name(),
        "amplitude": sol.amplitude(0),
        "omega_f": a.omega_f,
    });
    if let Some(path) = &a.plot {
        let period = 2.0 * PI / sol.omega();
        let pts: Vec<(f64, f64)> = (0..=400)
            .map(|i| {
                let t = period * i as f64 / 400.0;
                (t, sol.x_at(0, t))
            })
            .collect();
        draw(
            path,
            &format!("Duffing, ω_f = {}", a.omega_f),
            "t",
            "x",
            &[("HB", pts)],
        )?;
    }
    let human = format!(
        "Duffing ω_f = {}: {} iterations, ‖r‖ = {:.2e}, {:.1} µs, amplitude {:.6}, {} (|μ|max = {:.6})\n",
        a.omega_f,
        sol.stats.iterations,
        sol.stats.residual_norm,
        solve_time_s * 1e6,
        sol.amplitude(0),
        floquet.kind.name(),
        floquet.max_modulus()
    );
    Ok(Output { json, human })
}

fn duffing_frc(a: FrcArgs) -> Result<Output, CliError> {
    let problem = a.params.problem()?;
    let opts = FrcOptions {
        from: a.from,
        to: a.to,
        ..FrcOptions::default()
    };
    let t0 = std::time::Instant::now();
    let frc = frequency_response(&problem, &a.params.options()?, &opts).map_err(hb_err)?;
    let time = t0.elapsed().as_secs_f64();
    let points: Vec<_> = frc
        .points
        .iter()
        .map(|p| json!({"omega": p.omega_f, "amplitude": p.amplitude, "stable": p.stable(), "kind": p.kind.name()}))
        .collect();
    let folds: Vec<f64> = frc.folds.iter().map(|f| f.omega_f).collect();
    let json = json!({ "points": points, "folds": folds, "time_s": time, "termination": format!("{:?}", frc.termination) });
    if let Some(path) = &a.plot {
        // One curve per stability; a NaN point breaks a curve where the other
        // takes over, and each run shares its end point with the next.
        let gap = (f64::NAN, f64::NAN);
        let (mut stable, mut unstable) = (Vec::new(), Vec::new());
        let mut prev: Option<((f64, f64), bool)> = None;
        for p in &frc.points {
            let (pt, s) = ((p.omega_f, p.amplitude), p.stable());
            if let Some((last, _)) = prev.filter(|&(_, was)| was != s) {
                let (into, other) = if s {
                    (&mut stable, &mut unstable)
                } else {
                    (&mut unstable, &mut stable)
                };
                into.push(last);
                other.push(gap);
            }
            if s {
                stable.push(pt)
            } else {
                unstable.push(pt)
            }
            prev = Some((pt, s));
        }
        draw(
            path,
            "Duffing frequency response",
            "ω_f",
            "max |x|",
            &[("stable", stable), ("unstable", unstable)],
        )?;
    }
    let human = format!(
        "{} points from ω_f = {} to {}, folds at {:?}, {:.1} ms\n",
        frc.points.len(),
        a.from,
        a.to,
        folds,
        time * 1e3
    );
    Ok(Output { json, human })
}

fn mathieu(a: MathieuArgs) -> Result<Output, CliError> {
    if ![a.xi, a.alpha, a.omega, a.gamma]
        .iter()
        .all(|v| v.is_finite())
        || a.omega <= 0.0
    {
        return Err(CliError::Input("parameters must be finite, Ω > 0".into()));
    }
    let opts = CascadeOptions {
        xi: a.xi,
        alpha: a.alpha,
        omega: a.omega,
        gamma: a.gamma,
        harmonics: a.n,
        ..CascadeOptions::default()
    };
    let t0 = std::time::Instant::now();
    let pds = period_doubling_cascade(&opts).map_err(hb_err)?;
    let time = t0.elapsed().as_secs_f64();
    let betas: Vec<f64> = pds.iter().map(|p| p.beta).collect();
    let json = json!({
        "period_doubling_beta": betas,
        "periods": pds.iter().map(|p| p.period).collect::<Vec<_>>(),
        "multipliers": pds.iter().map(|p| [p.multiplier.re, p.multiplier.im]).collect::<Vec<_>>(),
        "thesis": [4.825, 5.194, 5.253],
        "time_s": time,
    });
    if let Some(path) = &a.plot {
        let names = ["period 1 at β1", "period 2 at β2", "period 4 at β4"];
        let series: Vec<_> = pds
            .iter()
            .zip(names)
            .map(|(p, name)| {
                let pts = (0..=800)
                    .map(|j| {
                        let tau = 2.0 * PI * j as f64 / 800.0;
                        (
                            eval_series(p.solution.dof(0), tau, 0),
                            eval_series(p.solution.dof(0), tau, 1) * p.solution.omega(),
                        )
                    })
                    .collect();
                (name, pts)
            })
            .collect();
        draw(
            path,
            "Mathieu–Duffing critical orbits",
            "x",
            "dx/dt",
            &series,
        )?;
    }
    let human = format!(
        "period doubling at β = {:?} (thesis 4.825, 5.194, 5.253), {:.1} ms\n",
        betas,
        time * 1e3
    );
    Ok(Output { json, human })
}

/// Draw curves with the shared figure crate (embedded font, NaN breaks).
fn draw(
    path: &std::path::Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    curves: &[(&str, Vec<(f64, f64)>)],
) -> Result<(), CliError> {
    let series = curves
        .iter()
        .map(|(label, points)| ivt_plot::Series {
            label,
            points,
            style: ivt_plot::Style::Line,
        })
        .collect();
    let figure = ivt_plot::Figure {
        title,
        x_label,
        y_label,
        series,
    };
    ivt_plot::line_plot(path, &figure).map_err(|e| CliError::Failed(e.to_string()))
}
