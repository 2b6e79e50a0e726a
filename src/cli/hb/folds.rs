//! `ivt hb duffing-folds`: how the folds of Duffing's frequency response
//! (Eq. 49) move with the force F — the fold curve in (ω, F) through the cusp
//! where the jump disappears, by the job [`ivt_jobs::fold_curve`] that
//! `ivt.hb.duffing_folds` and `ivt.hb.continue_bifurcation` run.

use super::{to_json, CliError, DuffingParams, Output};
use clap::Args;
use ivt_jobs::{self as jobs, FoldCurveRequest, FoldStart};
use std::path::PathBuf;

/// `ivt hb duffing-folds` (defaults: the thesis Duffing, from the F = 0.1 fold).
#[derive(Args)]
pub struct FoldsArgs {
    /// The model at the start (`--force` is where the curve starts).
    #[command(flatten)]
    params: DuffingParams,
    /// The FRC searched for the start fold: from this ω_f …
    #[arg(long, default_value_t = 0.5)]
    from: f64,
    /// … to this one; the fold of largest ω_f starts the curve.
    #[arg(long, default_value_t = 2.5)]
    to: f64,
    /// The curve goes first towards this force (down to the cusp), then from
    /// the start the other way …
    #[arg(long, default_value_t = 0.0)]
    force_from: f64,
    /// … and ends where F leaves [force_from, force_to].
    #[arg(long, default_value_t = 0.3)]
    force_to: f64,
    /// Forces at which the folds are located exactly (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [0.1, 0.2, 0.3])]
    at: Vec<f64>,
    /// Write a PNG of the curve in (ω_f, F) with its cusps and the folds at `--at`.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// Run `ivt hb duffing-folds`: the JSON holds the fold curve with the second
/// parameter `p` = F.
///
/// # Errors
/// [`CliError::Input`] for bad parameters or an FRC without a fold,
/// [`CliError::Failed`] when a solve does not converge.
pub fn run(a: FoldsArgs) -> Result<Output, CliError> {
    a.params.problem()?;
    let hb = a.params.options()?;
    let req = FoldCurveRequest {
        start: FoldStart::Search {
            from: a.from,
            to: a.to,
        },
        p_start: a.params.force,
        p_from: a.force_from,
        p_to: a.force_to,
        at: a.at.clone(),
        ..FoldCurveRequest::default()
    };
    let params = a.params.clone();
    let family = |f: f64| {
        let mut p = params.clone();
        p.force = f;
        p.problem()
            .map_err(|e| ivt_hb::HbError::InvalidInput(e.to_string()))
    };
    let curve = jobs::fold_curve(family, &hb, &req)?;
    if let Some(path) = &a.plot {
        super::figure::curve2("Folds of Duffing's response in (ω_f, F)", "F", &curve).draw(path)?;
    }
    let termination = curve.termination.as_str();
    let mut human = format!(
        "fold curve of Duffing from F = {} (ω_f = {:.8}): {} points, {termination}\n",
        a.params.force,
        curve.start_omega,
        curve.points.len()
    );
    for c in &curve.special {
        human += &format!(
            "  cusp at F = {:.10}, ω_f = {:.8}\n",
            c.point.p, c.point.omega
        );
    }
    for p in &curve.at {
        human += &format!("  fold at F = {}: ω_f = {:.10}\n", p.p, p.omega);
    }
    human += &super::unlocated_lines(&curve.unlocated, "F");
    Ok(Output {
        json: to_json(&curve)?,
        human,
    })
}
