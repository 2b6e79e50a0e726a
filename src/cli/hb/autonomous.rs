//! `ivt hb limit-cycle` and `ivt hb duffing-backbone`: periodic orbits with
//! the frequency an unknown (§3.2.4) — the limit cycle of a self-excited
//! oscillator and the backbone of the free Duffing oscillator — through the
//! jobs [`ivt_jobs::limit_cycle`] and [`ivt_jobs::backbone`] that
//! `ivt.hb.limit_cycle` and `ivt.hb.backbone` run.

use super::{to_json, CliError, Output};
use clap::Args;
use ivt_hb::Oscillator;
use ivt_hb::{BackboneOptions, HbOptions};
use ivt_jobs::{self as jobs, BackboneRequest, LimitCycleRequest};
use ivt_kin::params::Typed;
use std::path::PathBuf;

/// Harmonics and samples of the autonomous jobs (Python's defaults and
/// tolerances: ‖r‖₂ ≤ 1e-9 relative to the force scale).
#[derive(Args)]
pub struct Resolution {
    /// Harmonics n.
    #[arg(long, default_value_t = 20)]
    n: usize,
    /// Half the number of AFT samples N (2N samples, N > n) [default: 64,
    /// or 3.2·n from n = 20 on, so that --n alone suffices]
    #[arg(long)]
    samples: Option<usize>,
}

impl Resolution {
    pub(super) fn options(&self) -> Result<HbOptions, CliError> {
        let samples = self.samples.unwrap_or_else(|| {
            if self.n < 20 {
                64
            } else {
                (16 * self.n).div_ceil(5)
            }
        });
        if self.n == 0 || samples <= self.n {
            return Err(CliError::Input(format!(
                "--n must be ≥ 1 and --samples > --n, got n = {}, samples = {samples}",
                self.n
            )));
        }
        Ok(HbOptions::new(self.n, samples))
    }
}

/// `ivt hb limit-cycle` (defaults: Van der Pol, μ = 1, from x = 1).
#[derive(Args)]
pub struct LimitCycleArgs {
    #[command(flatten)]
    resolution: Resolution,
    /// The oscillator: `van-der-pol` (ẍ − μ(1 − x²)ẋ + x = 0) or `rayleigh`
    /// (ẍ − μ(ẋ − ẋ³/3) + x = 0).
    #[arg(long, default_value = "van-der-pol")]
    model: Oscillator,
    /// Its parameter μ.
    #[arg(long, default_value_t = 1.0)]
    mu: f64,
    /// x of the start state (x, 0) of the transient that settles onto the cycle.
    #[arg(long, default_value_t = 1.0)]
    amplitude: f64,
    /// Relative accuracy of ω and the coefficients: n grows by half from
    /// --n until the error estimate meets it (up to 160); 0: n as given.
    #[arg(long, default_value_t = jobs::DEFAULT_TOL)]
    tol: f64,
    /// Write a PNG of the cycle's phase portrait (x, dx/dt).
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// `ivt hb duffing-backbone` (defaults: the thesis α = ε = 1).
#[derive(Args)]
pub struct BackboneArgs {
    #[command(flatten)]
    resolution: Resolution,
    /// Linear stiffness α (> 0; the linear mode has ω₀ = √α).
    #[arg(long, default_value_t = 1.0)]
    alpha: f64,
    /// Cubic stiffness ε.
    #[arg(long, default_value_t = 1.0)]
    eps: f64,
    /// First amplitude a1.
    #[arg(long, default_value_t = 0.01)]
    from: f64,
    /// Last amplitude a1.
    #[arg(long, default_value_t = 1.0)]
    to: f64,
    /// Write a PNG of the backbone: ω against max |x|.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// Run `ivt hb limit-cycle`.
///
/// # Errors
/// [`CliError::Input`] for bad parameters, [`CliError::Failed`] when the
/// transient comes to rest or Newton does not converge.
pub fn limit_cycle(a: LimitCycleArgs) -> Result<Output, CliError> {
    if !a.mu.is_finite() {
        return Err(CliError::Input(format!(
            "--mu = {} must be finite",
            Typed(a.mu)
        )));
    }
    let req = LimitCycleRequest {
        amplitude: a.amplitude,
        tol: a.tol,
        ..LimitCycleRequest::default()
    };
    let problem = a.model.problem(a.mu);
    let hb = a.resolution.options()?;
    let cycle = jobs::limit_cycle(&problem, &hb, &req)?;
    if let Some(path) = &a.plot {
        let name = match a.model {
            Oscillator::VanDerPol => "Van der Pol",
            Oscillator::Rayleigh => "Rayleigh",
        };
        let title = format!("Limit cycle of the {name} oscillator, μ = {}", a.mu);
        super::figure::phase_portrait(title, &cycle, cycle.harmonics).draw(path)?;
    }
    let human = format!(
        "limit cycle, μ = {}: ω = {:.10}, period {:.10}, {} ({} Newton steps, ‖r‖ = {:.1e}); \
         n = {}, error estimate {}, accuracy {} (tol {:e})\n",
        a.mu,
        cycle.omega,
        cycle.period,
        cycle.stability.name(),
        cycle.iterations,
        cycle.residual_norm,
        cycle.harmonics,
        cycle
            .error_estimate
            .map_or_else(|| "unknown".to_string(), |e| format!("{e:.1e}")),
        cycle.accuracy,
        cycle.tol
    );
    Ok(Output {
        json: to_json(&cycle)?,
        human,
    })
}

/// Run `ivt hb duffing-backbone`.
///
/// # Errors
/// [`CliError::Input`] for bad parameters, [`CliError::Failed`] when the
/// path cannot start.
pub fn backbone(a: BackboneArgs) -> Result<Output, CliError> {
    if !(a.alpha.is_finite() && a.alpha > 0.0 && a.eps.is_finite()) {
        return Err(CliError::Input(format!(
            "--alpha = {} must be finite and > 0, --eps = {} finite",
            Typed(a.alpha),
            Typed(a.eps)
        )));
    }
    let defaults = BackboneRequest::default();
    let req = BackboneRequest {
        omega0: a.alpha.sqrt(),
        options: BackboneOptions {
            amplitude_from: a.from,
            amplitude_to: a.to,
            ..defaults.options
        },
        ..defaults
    };
    let problem = jobs::free_duffing(a.alpha, a.eps);
    let curve = jobs::backbone(&problem, &a.resolution.options()?, &req)?;
    if let Some(path) = &a.plot {
        let title = format!("Backbone of u'' + {}u + {}u³ = 0", a.alpha, a.eps);
        super::figure::backbone(title, &curve).draw(path)?;
    }
    let last = curve.points.last();
    let human = format!(
        "Duffing backbone: {} points, a1 {} → {:?}, ω {:?}, {}\n",
        curve.points.len(),
        a.from,
        last.map(|p| p.amplitude),
        last.map(|p| p.omega),
        curve.termination.as_str()
    );
    Ok(Output {
        json: to_json(&curve)?,
        human,
    })
}
