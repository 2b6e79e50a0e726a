//! `ivt hb vdp-torus`: where the periodic response of the forced Van der Pol
//! oscillator `ẍ − μ(1 − x²)ẋ + x = F cos ω_f t` gives way to a torus — its
//! Neimark–Sacker curve in (ω_f, F) from the NS point of the FRC at `--force`
//! to its 1:1 end on the fold curve and up to `--force-to`, by the job
//! [`ivt_jobs::fold_curve`] that `ivt.hb.continue_bifurcation` runs.

use super::autonomous::Resolution;
use super::{to_json, CliError, Output};
use clap::Args;
use ivt_hb::{BifurcationKind, GeneralProblem, HbError, PeriodicProblem};
use ivt_jobs::{self as jobs, FoldCurveRequest, FoldStart};
use ivt_kin::params::Typed;
use std::path::PathBuf;

/// `ivt hb vdp-torus` (defaults: μ = 0.2 from the point
/// (0.94525643, 0.2)).
#[derive(Args)]
pub struct TorusArgs {
    #[command(flatten)]
    resolution: Resolution,
    /// The damping parameter μ.
    #[arg(long, default_value_t = 0.2)]
    mu: f64,
    /// Forcing amplitude F where the curve starts.
    #[arg(long, default_value_t = 0.2)]
    force: f64,
    /// The FRC searched for the start: from this ω_f …
    #[arg(long, default_value_t = 0.5)]
    from: f64,
    /// … to this one; the NS point of largest ω_f starts the curve.
    #[arg(long, default_value_t = 1.6)]
    to: f64,
    /// The curve goes first towards this force, then from the start the
    /// other way …
    #[arg(long, default_value_t = 0.0)]
    force_from: f64,
    /// … and ends where F leaves [force_from, force_to].
    #[arg(long, default_value_t = 0.4)]
    force_to: f64,
    /// Forces at which the NS points are located exactly (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [0.2, 0.3, 0.4])]
    at: Vec<f64>,
    /// Write a PNG of the curve in (ω_f, F) with its resonances and the points at `--at`.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// The forced Van der Pol oscillator at F.
pub(super) fn van_der_pol(mu: f64, force: f64) -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![-mu],
        vec![1.0],
        move |x: &[f64], v: &[f64], _t: f64, g: &mut [f64]| {
            if let (Some(g), Some(x), Some(v)) = (g.first_mut(), x.first(), v.first()) {
                *g = mu * x * x * v;
            }
        },
        move |t: f64, out: &mut [f64]| out.iter_mut().for_each(|o| *o = force * t.cos()),
    )
}

/// Run `ivt hb vdp-torus`: the JSON holds the curve with `p` = F.
///
/// # Errors
/// [`CliError::Input`] for bad parameters or an FRC without a located
/// Neimark–Sacker point, [`CliError::Failed`] when a solve does not converge.
pub fn run(a: TorusArgs) -> Result<Output, CliError> {
    let hb = a.resolution.options()?;
    if !a.mu.is_finite() {
        return Err(CliError::Input(format!(
            "--mu must be finite, got {}",
            Typed(a.mu)
        )));
    }
    let req = FoldCurveRequest {
        kind: BifurcationKind::NeimarkSacker,
        start: FoldStart::Search {
            from: a.from,
            to: a.to,
        },
        p_start: a.force,
        p_from: a.force_from,
        p_to: a.force_to,
        at: a.at.clone(),
        steps: ivt_jobs::Steps {
            ds: Some(0.01),
            ds_max: Some(0.02),
            ..ivt_jobs::Steps::default()
        },
    };
    let mu = a.mu;
    let family = |f: f64| Ok::<_, HbError>(van_der_pol(mu, f));
    let curve = jobs::fold_curve(family, &hb, &req)?;
    if let Some(path) = &a.plot {
        let title = format!("Neimark–Sacker curve of the forced Van der Pol oscillator, μ = {mu}");
        super::figure::curve2(title, "F", &curve).draw(path)?;
    }
    let termination = curve.termination.as_str();
    let mut human = format!(
        "Neimark–Sacker curve of the forced Van der Pol oscillator (μ = {mu}) from F = {} (ω_f = {:.8}): {} points, {termination}\n",
        a.force,
        curve.start_omega,
        curve.points.len()
    );
    let special = to_json(&curve.special)?;
    for (c, json) in curve
        .special
        .iter()
        .zip(special.as_array().into_iter().flatten())
    {
        let kind = json
            .get("kind")
            .and_then(|k| k.as_str())
            .unwrap_or("special");
        human += &format!(
            "  {kind} at F = {:.10}, ω_f = {:.8}\n",
            c.point.p, c.point.omega
        );
    }
    for p in &curve.at {
        human += &format!(
            "  Neimark–Sacker point at F = {}: ω_f = {:.10}\n",
            p.p, p.omega
        );
    }
    human += &super::unlocated_lines(&curve.unlocated, "F");
    Ok(Output {
        json: to_json(&curve)?,
        human,
    })
}
