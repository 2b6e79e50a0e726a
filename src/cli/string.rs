//! `ivt hb string ...`: frequency–response curve of
//! the nonlinear string by STHB (thesis §3.3, Figs. 34–36).

use super::{CliError, Output};
use clap::{Args, ValueEnum};
use ivt_jobs::{self as jobs, StringRequest};
use ivt_sthb::{Boundary, StringParams};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Boundary at `x = 1`.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum BoundaryArg {
    /// Fixed–fixed, Eq. 104 (Newton + Hill/monodromy stability).
    Fixed,
    /// Spring `k0 w(1) = w_x(1)`, Eq. 132 (Tau method; stability with the
    /// boundary row eliminated).
    Spring,
}

/// Arguments of `ivt hb string`.
#[derive(Args, Debug)]
pub struct StringArgs {
    /// Nonlinear stiffness k_d (Eq. 103).
    #[arg(long, default_value_t = 10.0)]
    kd: f64,
    /// Sine trial functions N.
    #[arg(long, default_value_t = 5)]
    modes: usize,
    /// Harmonics M.
    #[arg(long, default_value_t = 19)]
    harmonics: usize,
    /// Start frequency ω.
    #[arg(long, default_value_t = 1.0)]
    from: f64,
    /// End frequency ω.
    #[arg(long, default_value_t = 6.0)]
    to: f64,
    /// Damping c_d.
    #[arg(long, default_value_t = 0.8)]
    cd: f64,
    /// Excitation amplitude y0.
    #[arg(long, default_value_t = 0.5)]
    y0: f64,
    /// Spatial grid N_s.
    #[arg(long, default_value_t = 64)]
    ns: usize,
    /// Temporal samples M_s.
    #[arg(long, default_value_t = 128)]
    ms: usize,
    /// Boundary condition at x = 1.
    #[arg(long, value_enum, default_value_t = BoundaryArg::Fixed)]
    boundary: BoundaryArg,
    /// Spring stiffness k0 (with --boundary spring).
    #[arg(long, default_value_t = 10.0)]
    k0: f64,
    /// Largest arclength step (default 0.05; `--step-max` is its old name).
    #[arg(long, alias = "step-max")]
    ds_max: Option<f64>,
    /// Draw ‖a‖ against ω into this PNG (stable solid, unstable dashed,
    /// folds marked).
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// Trace the curve (the job [`ivt_jobs::string()`]) and report
/// `{"points": [{"omega", "norm", "stable", "kind", "max_multiplier",
/// "method"}...], "folds": [{"omega", "norm", "located", "index"}...],
/// "jacobians", "hill_calls", "stop", "solve_time_s"}` (and
/// `boundary_note` for a spring of k0 > 1).
///
/// # Errors
/// [`CliError::Input`] for invalid parameters, [`CliError::Failed`] when the
/// solver does not converge.
pub fn run(args: StringArgs) -> Result<Output, CliError> {
    let boundary = match args.boundary {
        BoundaryArg::Fixed => Boundary::Fixed,
        BoundaryArg::Spring => Boundary::Spring { k0: args.k0 },
    };
    let req = StringRequest {
        params: StringParams {
            kd: args.kd,
            cd: args.cd,
            y0: args.y0,
            modes: args.modes,
            harmonics: args.harmonics,
            ns: args.ns,
            ms: args.ms,
            boundary,
        },
        from: args.from,
        to: args.to,
        steps: ivt_jobs::Steps {
            ds_max: args.ds_max,
            ..ivt_jobs::Steps::default()
        },
    };
    let curve = jobs::string(&req)?;
    let mut human = format!(
        "# STHB string, k_d = {}, N = {}, M = {}, {}\n# omega norm stable\n",
        args.kd,
        args.modes,
        args.harmonics,
        boundary_name(boundary)
    );
    for p in &curve.points {
        let _ = writeln!(human, "{:.6} {:.6e} {}", p.omega, p.norm, p.stable);
    }
    if let Some(note) = &curve.boundary_note {
        let _ = writeln!(human, "# note: {note}");
    }
    if let Some(path) = &args.plot {
        let title = format!(
            "STHB string, k_d = {}, N = {}, M = {}, {}",
            args.kd,
            args.modes,
            args.harmonics,
            boundary_name(boundary)
        );
        let points: Vec<_> = curve
            .points
            .iter()
            .map(|p| (p.omega, p.norm, p.stable))
            .collect();
        let folds: Vec<_> = curve
            .folds
            .iter()
            .map(|f| ("fold".to_owned(), (f.omega, f.norm)))
            .collect();
        super::hb::figure::response(title, "||a|| (Eq. 114)", &points, &folds).draw(path)?;
        let _ = writeln!(human, "# plot: {}", path.display());
    }
    let json = serde_json::to_value(&curve).map_err(|e| CliError::Failed(e.to_string()))?;
    Ok(Output { json, human })
}

/// The boundary at x = 1 in words.
fn boundary_name(boundary: Boundary) -> String {
    match boundary {
        Boundary::Fixed => "fixed–fixed".to_string(),
        Boundary::Spring { k0 } => format!("spring k0 = {k0}"),
    }
}
