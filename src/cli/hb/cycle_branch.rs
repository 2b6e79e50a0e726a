//! `ivt hb cycle-branch`: the Hopf point of ẍ − (μ + x² − x⁴)ẋ + x = 0
//! (issue 27: subcritical at μ = 0) and the limit-cycle branch born there,
//! with its stability and its fold, by the job
//! [`ivt_jobs::cycle_branch()`] that `ivt.hb.cycle_branch` runs.

use super::autonomous::Resolution;
use super::{to_json, CliError, Output};
use clap::Args;
use ivt_hb::{GeneralProblem, HbError, PeriodicProblem};
use ivt_jobs::{self as jobs, CycleBranchRequest};
use std::path::PathBuf;

/// `ivt hb cycle-branch` (defaults: μ from −0.2 to 0.1, the cycles at μ = −0.1).
#[derive(Args)]
pub struct CycleBranchArgs {
    #[command(flatten)]
    resolution: Resolution,
    /// The equilibria are followed from this μ …
    #[arg(long, default_value_t = -0.2, allow_negative_numbers = true)]
    mu_from: f64,
    /// … to this one.
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
    mu_to: f64,
    /// μ at which the cycles are solved exactly (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [-0.1], allow_negative_numbers = true)]
    at: Vec<f64>,
    /// Write a PNG of the cycles' amplitude against μ: unstable dashed, Hopf points and folds marked.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// The model at μ: M = 1, C = −μ, K = 1, g = (x⁴ − x²) ẋ (the arithmetic of
/// the Python callback `(x * x * (x * x) - x * x) * v`).
fn model(mu: f64) -> Result<impl PeriodicProblem, HbError> {
    if !mu.is_finite() {
        return Err(HbError::InvalidInput(format!("μ = {mu} must be finite")));
    }
    Ok(GeneralProblem::new(
        1,
        vec![1.0],
        vec![-mu],
        vec![1.0],
        |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| {
            if let (Some(x), Some(v), Some(g)) = (x.first(), v.first(), g.first_mut()) {
                *g = (x * x * (x * x) - x * x) * v;
            }
        },
        |_t: f64, f: &mut [f64]| f.fill(0.0),
    ))
}

/// Run `ivt hb cycle-branch`.
///
/// # Errors
/// [`CliError::Input`] for bad parameters, [`CliError::Failed`] when the
/// first cycle does not converge.
pub fn run(a: CycleBranchArgs) -> Result<Output, CliError> {
    let req = CycleBranchRequest {
        p_from: a.mu_from,
        p_to: a.mu_to,
        at: a.at.clone(),
        ..CycleBranchRequest::default()
    };
    let branch = jobs::cycle_branch(model, &a.resolution.options()?, &req)?;
    if let Some(path) = &a.plot {
        super::figure::cycles(
            "Limit cycles of x'' − (μ + x² − x^4)x' + x = 0",
            "μ",
            &branch,
        )
        .draw(path)?;
    }
    let mut human = format!(
        "{} Hopf point(s), {} cycles, {}\n",
        branch.hopf.len(),
        branch.points.len(),
        branch
            .termination
            .as_ref()
            .map_or("no branch", |t| t.as_str())
    );
    for h in &branch.hopf {
        let kind = if h.subcritical {
            "subcritical"
        } else {
            "supercritical"
        };
        human += &format!(
            "  Hopf at μ = {:.10}, ω = {:.10}, {kind} (l1 = {:.4e})\n",
            h.p, h.omega, h.lyapunov
        );
    }
    for u in &branch.hopf_undecided {
        human += &format!(
            "  Hopf search undecided for μ in [{}, {}]: {}\n",
            u.p_from, u.p_to, u.reason
        );
    }
    for f in &branch.bifurcations {
        human += &format!(
            "  fold of cycles at μ = {:.10}, amplitude {:.8}\n",
            f.p, f.amplitude
        );
    }
    for c in &branch.at {
        human += &format!(
            "  cycle at μ = {}: amplitude {:.8}, period {:.10}, {}\n",
            c.p,
            c.amplitude,
            c.period,
            c.stability.name()
        );
    }
    human += &super::unlocated_lines(&branch.unlocated, "μ");
    Ok(Output {
        json: to_json(&branch)?,
        human,
    })
}
