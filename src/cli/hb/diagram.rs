//! `ivt hb diagram`: the automatic bifurcation diagram of the 2-DOF cubic
//! chain (M = I, K = [[2, −1], [−1, 2]], C = 0.02 I, cubic springs 0.5 x_i³
//! on both DOFs) forced on DOF 1 or on both, by the job
//! [`ivt_jobs::diagram()`] that `ivt.hb.diagram` runs.

use super::autonomous::Resolution;
use super::{to_json, CliError, Output};
use clap::Args;
use ivt_hb::{GeneralProblem, PeriodicProblem};
use ivt_jobs::{self as jobs, DiagramRequest};
use ivt_kin::params::Typed;

/// `ivt hb diagram` (defaults: F = 0.1 on DOF 1, ω_f from 0.5 to 2.5).
#[derive(Args)]
pub struct DiagramArgs {
    #[command(flatten)]
    resolution: Resolution,
    /// Forcing amplitude F.
    #[arg(long, default_value_t = 0.1)]
    force: f64,
    /// Force both DOFs (in phase), not DOF 1 alone.
    #[arg(long)]
    both: bool,
    /// Start of the interval of ω_f.
    #[arg(long, default_value_t = 0.5)]
    from: f64,
    /// End of the interval of ω_f.
    #[arg(long, default_value_t = 2.5)]
    to: f64,
    /// Levels of branch switching.
    #[arg(long, default_value_t = 2)]
    depth: usize,
    /// ω_f at which every branch is solved (comma-separated).
    #[arg(long, value_delimiter = ',')]
    at: Vec<f64>,
}

/// The chain with cubic springs 0.5 x_i³, forced by F on DOF 1 (and 2).
fn chain(force: f64, both: bool) -> impl PeriodicProblem {
    GeneralProblem::new(
        2,
        vec![1.0, 0.0, 0.0, 1.0],
        vec![0.02, 0.0, 0.0, 0.02],
        vec![2.0, -1.0, -1.0, 2.0],
        |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
            for (g, x) in g.iter_mut().zip(x) {
                *g = 0.5 * x * x * x;
            }
        },
        move |t: f64, f: &mut [f64]| {
            for (i, f) in f.iter_mut().enumerate() {
                *f = if i == 0 || both { force * t.cos() } else { 0.0 };
            }
        },
    )
    .with_velocity_dependent(false)
}

/// Run `ivt hb diagram`: the JSON holds the keys of `ivt.hb.diagram`.
///
/// # Errors
/// [`CliError::Input`] for bad parameters, [`CliError::Failed`] when the
/// primary curve cannot be traced.
pub fn run(a: DiagramArgs) -> Result<Output, CliError> {
    let hb = a.resolution.options()?;
    if !a.force.is_finite() {
        return Err(CliError::Input(format!(
            "--force = {} must be finite",
            Typed(a.force)
        )));
    }
    let req = DiagramRequest {
        from: a.from,
        to: a.to,
        depth: a.depth,
        at: a.at.clone(),
        ..DiagramRequest::default()
    };
    let d = jobs::diagram(&chain(a.force, a.both), &hb, &req)?;
    let mut human = format!(
        "bifurcation diagram of the cubic chain (F = {} on {}) over ω_f ∈ [{}, {}]: {} branches in {:.1} s\n",
        a.force,
        if a.both { "both DOFs" } else { "DOF 1" },
        a.from,
        a.to,
        d.branches.len(),
        d.time_s
    );
    let kinds = to_json(&d.branches.iter().map(|b| b.kind).collect::<Vec<_>>())?;
    for ((i, b), kind) in d
        .branches
        .iter()
        .enumerate()
        .zip(kinds.as_array().into_iter().flatten())
    {
        human += &format!(
            "  {i}: {} (parent {:?}), {} points, {} events, {}\n",
            kind.as_str().unwrap_or("branch"),
            b.parent,
            b.points.len(),
            b.events.len(),
            b.termination.as_str()
        );
    }
    Ok(Output {
        json: to_json(&d)?,
        human,
    })
}
