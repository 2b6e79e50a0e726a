//! `ivt hb torus`: the quasi-periodic response of the forced Van der Pol
//! oscillator `ẍ − μ(1 − x²)ẋ + x = F cos ω_f t` born at the Neimark–Sacker
//! point of its frequency response, followed in ω_f with the tori at `--at`
//! solved and refined, by the job [`ivt_jobs::torus()`] that
//! `ivt.hb.torus_branch` runs.

use super::autonomous::Resolution;
use super::torus::van_der_pol;
use super::{to_json, CliError, Output};
use clap::Args;
use ivt_hb::branches::torus::{TorusOptions, Truncation};
use ivt_hb::{c64, BifurcationKind, FrcOptions};
use ivt_jobs::{self as jobs, FrcRequest, TorusRequest};
use ivt_kin::params::Typed;

/// The smallest μ `ivt hb torus` takes.
const MU_MIN: f64 = 1e-3;

/// `ivt hb torus` (defaults: μ = F = 0.2, the tori at 0.93 and 0.90).
#[derive(Args)]
pub struct TorusBranchArgs {
    #[command(flatten)]
    resolution: Resolution,
    /// The damping parameter μ (≥ 1e-3).
    #[arg(long, default_value_t = 0.2)]
    mu: f64,
    /// Forcing amplitude F.
    #[arg(long, default_value_t = 0.2)]
    force: f64,
    /// The FRC searched for the Neimark–Sacker point: from this ω_f …
    #[arg(long, default_value_t = 0.6)]
    from: f64,
    /// … to this one (its first located point starts the torus).
    #[arg(long, default_value_t = 1.6)]
    to: f64,
    /// The torus branch is followed to this ω_f.
    #[arg(long, default_value_t = 0.89)]
    omega_to: f64,
    /// ω_f at which the torus is solved and refined (comma-separated).
    #[arg(long, value_delimiter = ',', default_values_t = [0.93, 0.9])]
    at: Vec<f64>,
    /// Harmonics of the first frequency kept: |k₁| ≤ h1 …
    #[arg(long, default_value_t = 7)]
    h1: usize,
    /// … and of the second: |k₂| ≤ h2.
    #[arg(long, default_value_t = 20)]
    h2: usize,
    /// The `at` tori are refined until their error estimate is at most this.
    #[arg(long, default_value_t = 1e-7)]
    tol: f64,
}

/// Run `ivt hb torus`: the JSON holds the keys of `ivt.hb.torus_branch`.
///
/// # Errors
/// [`CliError::Input`] for bad parameters or an FRC without a located
/// Neimark–Sacker point, [`CliError::Failed`] when a solve does not converge.
pub fn run(a: TorusBranchArgs) -> Result<Output, CliError> {
    let hb = a.resolution.options()?;
    if !(a.mu.is_finite() && a.force.is_finite()) {
        return Err(CliError::Input(format!(
            "--mu = {} and --force = {} must be finite",
            Typed(a.mu),
            Typed(a.force)
        )));
    }
    // The FRC's resonance amplitude grows as (4F/μ)^{1/3} (the only damping
    // at large x is μx²ẋ): at μ = 1e-3, F = 0.2 the job took 25 s under load
    // (measured, not asserted); at μ = 1e-300 the path climbs towards 1e100.
    if a.mu < MU_MIN {
        return Err(CliError::Input(format!(
            "--mu = {} must be ≥ {MU_MIN:?}: the forced response's resonance amplitude grows as \
             (4F/μ)^(1/3), and its frequency response would be followed up to it",
            Typed(a.mu)
        )));
    }
    let problem = van_der_pol(a.mu, a.force);
    let frc = jobs::frc(
        &problem,
        &hb,
        &FrcRequest {
            options: FrcOptions {
                from: a.from,
                to: a.to,
                ..FrcOptions::default()
            },
            events: true,
        },
    )?;
    let ns = frc
        .bifurcations
        .iter()
        .find(|e| e.kind == BifurcationKind::NeimarkSacker && e.located)
        .ok_or_else(|| {
            CliError::Input(format!(
                "the FRC from ω_f = {} to {} has no located Neimark–Sacker point",
                Typed(a.from),
                Typed(a.to)
            ))
        })?;
    let (Some(omega), Some(coeffs), Some(multipliers)) = (ns.omega, &ns.coeffs, &ns.multipliers)
    else {
        return Err(CliError::Failed("a located event without its orbit".into()));
    };
    let req = TorusRequest {
        omega,
        coeffs: coeffs.0.clone(),
        multipliers: multipliers.iter().map(|m| c64::new(m[0], m[1])).collect(),
        omega_to: a.omega_to,
        at: a.at.clone(),
        torus: TorusOptions {
            truncation: Truncation::Box { h1: a.h1, h2: a.h2 },
            ..TorusOptions::default()
        },
        tol: a.tol,
        ..TorusRequest::default()
    };
    let curve = jobs::torus(&problem, &hb, &req)?;
    let mut human = format!(
        "torus of the forced Van der Pol oscillator (μ = {}, F = {}) from its Neimark–Sacker point \
         at ω_f = {omega:.8}: {} points, {}\n",
        a.mu,
        a.force,
        curve.points.len(),
        curve.termination.as_str()
    );
    for p in &curve.at {
        human += &format!(
            "  ω_f = {}: rotation number {:.10}, mean |x| {:.10}, max |x| {:.10} (error estimate {:.1e})\n",
            p.omega,
            p.rotation_number,
            p.amplitude_mean,
            p.amplitude_max,
            p.error_estimate.unwrap_or(f64::NAN)
        );
    }
    Ok(Output {
        json: to_json(&curve)?,
        human,
    })
}
