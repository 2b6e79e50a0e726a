//! `ivt hb all-solutions`: every period-one orbit of Duffing's equation
//! (Eq. 49, the thesis's ξ = 0.02, α = ε = 1, F = 0.1) at one ω_f by
//! deflated Newton, with stability, by the job
//! [`ivt_jobs::all_solutions()`] that `ivt.hb.all_solutions` runs.

use super::{to_json, CliError, DuffingParams, Output};
use clap::Args;
use ivt_hb::{GeneralProblem, PeriodicProblem};
use ivt_jobs::{self as jobs, AllSolutionsRequest};
use std::path::PathBuf;

/// `ivt hb all-solutions` (defaults: the thesis Duffing at ω_f = 1.4).
#[derive(Args)]
pub struct AllSolutionsArgs {
    /// The model and the resolution (`--tol` absolute).
    #[command(flatten)]
    params: DuffingParams,
    /// Excitation frequency ω_f.
    #[arg(long, default_value_t = 1.4)]
    omega: f64,
    /// The search box: max |coefficient|.
    #[arg(long, default_value_t = 10.0)]
    max_amplitude: f64,
    /// Write a PNG of the orbits' amplitudes at ω_f, stable and unstable apart.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// Duffing as a user system: M = 1, C = 2ξ, K = α, g = ε x³, f = F cos θ
/// (the arithmetic of the Python callbacks `eps * x * x * x`,
/// `F * math.cos(th)`).
fn duffing(xi: f64, alpha: f64, eps: f64, force: f64) -> impl PeriodicProblem {
    GeneralProblem::new(
        1,
        vec![1.0],
        vec![2.0 * xi],
        vec![alpha],
        move |x: &[f64], _v: &[f64], _t: f64, g: &mut [f64]| {
            if let (Some(x), Some(g)) = (x.first(), g.first_mut()) {
                *g = eps * x * x * x;
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

/// Run `ivt hb all-solutions`.
///
/// # Errors
/// [`CliError::Input`] for bad parameters, [`CliError::Failed`] for a
/// failed stability analysis.
pub fn run(a: AllSolutionsArgs) -> Result<Output, CliError> {
    let p = &a.params;
    p.problem()?;
    let req = AllSolutionsRequest {
        omega: a.omega,
        max_amplitude: a.max_amplitude,
        ..AllSolutionsRequest::default()
    };
    let problem = duffing(p.xi, p.alpha, p.eps, p.force);
    let all = jobs::all_solutions(&problem, &p.options()?, &req)?;
    if let Some(path) = &a.plot {
        let title = format!("Period-one orbits of Duffing at ω_f = {}", a.omega);
        super::figure::solutions(title, a.omega, &all).draw(path)?;
    }
    let mut human = format!(
        "{} orbit(s) at ω_f = {} ({} starts, {} runs, {})\n",
        all.solutions.len(),
        a.omega,
        all.search.starts,
        all.search.runs,
        if all.search.exhausted {
            "nothing more within the bounds"
        } else {
            "search not exhausted"
        }
    );
    for s in &all.solutions {
        human += &format!("  amplitude {:.8}: {}\n", s.amplitude, s.stability.name());
    }
    Ok(Output {
        json: to_json(&all)?,
        human,
    })
}
