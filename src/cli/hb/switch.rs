//! `ivt hb switch`: branch switching at the first period doubling of the
//! twin-well Duffing oscillator about its well (ẍ + cẋ + 2x + 3x² + x³ =
//! F cos ω_f t, x = u − 1 of ü + cu̇ − u + u³ = F cos ω_f t) onto its
//! period-2 branch, by the job [`ivt_jobs::switch()`] that
//! `ivt.hb.switch_branch` runs.

use super::autonomous::Resolution;
use super::{to_json, CliError, Output};
use clap::Args;
use ivt_hb::{BifurcationKind, Corrector, FrcOptions, GeneralProblem, PeriodicProblem};
use ivt_jobs::{self as jobs, FrcRequest, SwitchRequest, SwitchStart};
use ivt_kin::params::Typed;
use std::path::PathBuf;

/// `ivt hb switch` (defaults: c = 0.1, F = 0.5, the FRC from ω_f = 3.6 down
/// to 2.2, the period-2 branch to 2.2).
#[derive(Args)]
pub struct SwitchArgs {
    #[command(flatten)]
    resolution: Resolution,
    /// Damping c.
    #[arg(long, default_value_t = 0.1)]
    damping: f64,
    /// Forcing amplitude F.
    #[arg(long, default_value_t = 0.5)]
    force: f64,
    /// The FRC searched for the first period doubling or branch point: from
    /// this ω_f …
    #[arg(long, default_value_t = 3.6)]
    from: f64,
    /// … to this one.
    #[arg(long, default_value_t = 2.2)]
    to: f64,
    /// The new branch is continued to this ω_f.
    #[arg(long, default_value_t = 2.2)]
    branch_to: f64,
    /// Its first point's distance from the bifurcation, relative to the
    /// orbit's ‖coefficients‖₂.
    #[arg(long, default_value_t = 0.05)]
    step: f64,
    /// Write a PNG of the new branch: unstable dashed, its events marked.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// The well model: M = 1, C = `c`, K = 2, g = x²(3 + x), f = F cos θ (the
/// arithmetic of the Python callbacks `x * x * (3.0 + x)`, `F * math.cos(th)`).
fn well(c: f64, force: f64) -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![c],
        vec![2.0],
        |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
            if let (Some(x), Some(g)) = (x.first(), g.first_mut()) {
                *g = x * x * (3.0 + x);
            }
        },
        move |t: f64, f: &mut [f64]| {
            if let Some(f) = f.first_mut() {
                *f = force * t.cos();
            }
        },
    )
    .with_velocity_dependent(false)
}

/// Run `ivt hb switch`: the JSON holds the period-2 branch with the keys of
/// `ivt.hb.switch_branch`.
///
/// # Errors
/// [`CliError::Input`] for bad parameters, an FRC without a period doubling
/// or a `--branch-to` on the side the branch does not go;
/// [`CliError::Failed`] when a solve does not converge.
pub fn run(a: SwitchArgs) -> Result<Output, CliError> {
    if !(a.damping.is_finite() && a.force.is_finite()) {
        return Err(CliError::Input(format!(
            "--damping = {} and --force = {} must be finite",
            Typed(a.damping),
            Typed(a.force)
        )));
    }
    let hb = a.resolution.options()?;
    let req = SwitchRequest {
        start: SwitchStart::Search(FrcRequest {
            options: FrcOptions::sweep(a.from, a.to, Corrector::Newton),
            events: true,
        }),
        to: a.branch_to,
        step: a.step,
        corrector: Corrector::Newton,
        steps: ivt_jobs::Steps::default(),
    };
    let branch = jobs::switch(&well(a.damping, a.force), &hb, &req)?;
    let curve = &branch.curve;
    if let Some(path) = &a.plot {
        let title = format!(
            "Branch switched at the {} at ω_f = {:.6}",
            word(branch.kind).replace('_', " "),
            branch.start_omega
        );
        super::figure::frc(title, curve).draw(path)?;
    }
    let mut human = format!(
        "switched at the {} at ω_f = {:.10}: {} points (subharmonic {}) to ω_f = {}, {}\n",
        word(branch.kind),
        branch.start_omega,
        curve.points.len(),
        branch.subharmonic,
        a.branch_to,
        curve.termination.as_str()
    );
    for e in &curve.bifurcations {
        let at = e.omega.map_or("?".into(), |w| format!("{w:.10}"));
        human += &format!("  {} at ω_f = {at}\n", word(e.kind));
    }
    Ok(Output {
        json: to_json(&branch)?,
        human,
    })
}

/// The JSON word of a bifurcation kind (`period_doubling`, …).
fn word(kind: BifurcationKind) -> String {
    serde_json::to_value(kind)
        .ok()
        .and_then(|v| v.as_str().map(str::to_owned))
        .unwrap_or_default()
}
