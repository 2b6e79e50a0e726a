//! `ivt hb duffing-folds`: how the folds of Duffing's frequency response
//! (Eq. 49) move with the force F — the fold curve in (ω, F) through the cusp
//! where the jump disappears (ivt_hb::fold_curve).

use super::{CliError, DuffingParams, Output};
use clap::Args;
use ivt_hb::{fold_curve, frequency_response, ContinuationOptions, FoldPoint, FrcOptions};
use serde_json::json;

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
    /// The curve goes first towards this force (down to the cusp) …
    #[arg(long, default_value_t = 0.0)]
    force_from: f64,
    /// … and ends where F leaves [force_from, force_to].
    #[arg(long, default_value_t = 0.3)]
    force_to: f64,
    /// Forces at which the folds are located exactly (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [0.1, 0.2, 0.3])]
    at: Vec<f64>,
}

/// One fold as JSON.
fn fold_json(p: &FoldPoint) -> serde_json::Value {
    json!({"omega": p.omega, "force": p.p, "coeffs": p.coeffs})
}

/// Run `ivt hb duffing-folds`.
///
/// # Errors
/// [`CliError::Input`] for bad parameters or an FRC without a fold,
/// [`CliError::Failed`] when a solve does not converge.
pub fn run(a: FoldsArgs) -> Result<Output, CliError> {
    let problem = a.params.problem()?;
    let hb = a.params.options()?;
    let frc_opts = FrcOptions {
        from: a.from,
        to: a.to,
        ..FrcOptions::default()
    };
    let frc = frequency_response(&problem, &hb, &frc_opts)?;
    let start = frc
        .folds
        .iter()
        .filter(|f| f.located)
        .max_by(|x, y| x.omega_f.total_cmp(&y.omega_f))
        .ok_or_else(|| {
            CliError::Input(format!(
                "the FRC from ω_f = {} to {} at F = {} has no located fold to start from",
                a.from, a.to, a.params.force
            ))
        })?;
    let params = a.params.clone();
    let family = |f: f64| {
        let mut p = params.clone();
        p.force = f;
        p.problem()
            .map_err(|e| ivt_hb::HbError::InvalidInput(e.to_string()))
    };
    let t0 = std::time::Instant::now();
    let curve = fold_curve(
        family,
        &hb,
        &start.coeffs,
        start.omega_f,
        a.params.force,
        a.force_from,
        a.force_to,
        &a.at,
        &ContinuationOptions {
            ds: 0.02,
            ds_max: 0.05,
            max_points: 5000,
            ..ContinuationOptions::default()
        },
    )?;
    let time = t0.elapsed().as_secs_f64();
    let termination = curve.termination.as_str();
    let special: Vec<_> = curve
        .cusps
        .iter()
        .map(|c| json!({"kind": "cusp", "omega": c.omega, "force": c.p}))
        .collect();
    let json = json!({
        "kind": "fold",
        "points": curve.points.iter().map(|p| json!({"omega": p.omega, "force": p.p})).collect::<Vec<_>>(),
        "at": curve.at.iter().map(fold_json).collect::<Vec<_>>(),
        "special": special,
        "termination": termination,
        "time_s": time,
    });
    let mut human = format!(
        "fold curve of Duffing from F = {} (ω_f = {:.8}): {} points, {termination}\n",
        a.params.force,
        start.omega_f,
        curve.points.len()
    );
    for c in &curve.cusps {
        human += &format!("  cusp at F = {:.10}, ω_f = {:.8}\n", c.p, c.omega);
    }
    for p in &curve.at {
        human += &format!("  fold at F = {}: ω_f = {:.10}\n", p.p, p.omega);
    }
    Ok(Output { json, human })
}
