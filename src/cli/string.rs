//! `ivt hb string ...`: frequency–response curve of
//! the nonlinear string by STHB (thesis §3.3, Figs. 34–36).

use super::{CliError, Output};
use clap::{Args, ValueEnum};
use ivt_hb::sthb::frc::{frequency_response, StringFrcOptions};
use ivt_hb::sthb::{Boundary, StringHb, StringParams};
use ivt_hb::FrcPoint;
use serde_json::json;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

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
    /// Largest arclength step.
    #[arg(long, default_value_t = 0.05)]
    step_max: f64,
    /// Draw ‖a‖ against ω into this PNG (stable solid, unstable dashed).
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// Trace the curve and report `{"points": [{"omega", "norm", "stable"}...]}`.
///
/// # Errors
/// [`CliError::Input`] for invalid parameters, [`CliError::Failed`] when the
/// solver does not converge.
pub fn run(args: StringArgs) -> Result<Output, CliError> {
    let boundary = match args.boundary {
        BoundaryArg::Fixed => Boundary::Fixed,
        BoundaryArg::Spring => Boundary::Spring { k0: args.k0 },
    };
    let params = StringParams {
        kd: args.kd,
        cd: args.cd,
        y0: args.y0,
        modes: args.modes,
        harmonics: args.harmonics,
        ns: args.ns,
        ms: args.ms,
        boundary,
    };
    params
        .validate()
        .map_err(|e| CliError::Input(e.to_string()))?;
    if !(args.from > 0.0 && args.to > args.from && args.to.is_finite() && args.step_max > 0.0) {
        return Err(CliError::Input(format!(
            "need 0 < --from < --to and --step-max > 0, got {} .. {}",
            args.from, args.to
        )));
    }
    let t0 = std::time::Instant::now();
    let mut human = format!(
        "# STHB string, k_d = {}, N = {}, M = {}, {:?}\n# omega norm stable\n",
        args.kd, args.modes, args.harmonics, args.boundary
    );
    // Both boundaries: Newton arclength with the exact (Tau) Jacobian. The
    // engine's Broyden continuation (`spring_frequency_response`, §3.3.5) gives
    // the same spring curve but ~50× slower (crates/ivt-hb/README.md, STHB).
    let mut hb = StringHb::new(params).map_err(|e| CliError::Input(e.to_string()))?;
    let mut opts = StringFrcOptions::default();
    opts.continuation.ds_max = args.step_max;
    let curve = frequency_response(&mut hb, args.from, args.to, &opts)
        .map_err(|e| CliError::Failed(e.to_string()))?;
    let solve_time_s = t0.elapsed().as_secs_f64();
    let frc = &curve.frc;
    let points: Vec<_> = frc
        .points
        .iter()
        .zip(&curve.methods)
        .map(|(p, method)| {
            let _ = writeln!(human, "{:.6} {:.6e} {}", p.omega_f, p.amplitude, p.stable());
            json!({"omega": p.omega_f, "norm": p.amplitude, "stable": p.stable(),
                   "kind": format!("{:?}", p.kind), "max_multiplier": p.multipliers.first().map(|m| m.norm()),
                   "method": format!("{method:?}")})
        })
        .collect();
    let mut extra = json!({"jacobians": curve.jacobians, "hill_calls": curve.hill_calls,
                       "stop": format!("{:?}", frc.termination)});
    if let Boundary::Spring { k0 } = boundary {
        if k0 > 1.0 {
            let note = format!(
                "Eq. 132 as printed (k0 w = +w_x) is a negative spring: for k0 > 1 the continuous \
                 string has a growing mode (tanh γ = γ/k0). `stable` is the verdict of the \
                 {}-mode Tau model, which resolves that mode only when N > (k0 − 1)/2; \
                 a restoring spring of stiffness k is --k0=-k",
                args.modes
            );
            let _ = writeln!(human, "# note: {note}");
            if let Some(o) = extra.as_object_mut() {
                o.insert("boundary_note".into(), json!(note));
            }
        }
    }
    if let Some(path) = &args.plot {
        let title = format!(
            "STHB string, k_d = {}, N = {}, M = {}, {}",
            args.kd,
            args.modes,
            args.harmonics,
            match boundary {
                Boundary::Fixed => "fixed–fixed".to_string(),
                Boundary::Spring { k0 } => format!("spring k0 = {k0}"),
            }
        );
        plot(path, &title, &frc.points)?;
        let _ = writeln!(human, "# plot: {}", path.display());
    }
    let mut obj = json!({"points": points, "solve_time_s": solve_time_s});
    if let (Some(o), Some(e)) = (obj.as_object_mut(), extra.as_object()) {
        o.extend(e.clone());
    }
    Ok(Output { json: obj, human })
}

/// ‖a‖(ω) with the stable stretches solid and the unstable ones dashed; each
/// change of verdict repeats the boundary point in both series so the curve
/// stays connected (NaN breaks the other series there).
fn plot(path: &Path, title: &str, points: &[FrcPoint]) -> Result<(), CliError> {
    let stable = FrcPoint::stable;
    let (mut solid, mut dashed) = (Vec::new(), Vec::new());
    let mut previous: Option<&FrcPoint> = None;
    for p in points {
        let xy = (p.omega_f, p.amplitude);
        let gap = (f64::NAN, f64::NAN);
        let (own, other) = if stable(p) {
            (&mut solid, &mut dashed)
        } else {
            (&mut dashed, &mut solid)
        };
        own.push(xy);
        if previous.is_some_and(|q| stable(q) != stable(p)) {
            // Close the other style's stretch at this point, then break it.
            other.push(xy);
        }
        other.push(gap);
        previous = Some(p);
    }
    let mut series = vec![ivt_plot::Series {
        label: "stable",
        points: &solid,
        style: ivt_plot::Style::Line,
    }];
    if dashed.iter().any(|p| p.0.is_finite()) {
        series.push(ivt_plot::Series {
            label: "unstable",
            points: &dashed,
            style: ivt_plot::Style::Dashed,
        });
    }
    let figure = ivt_plot::Figure {
        title,
        x_label: "ω (normalized excitation frequency)",
        y_label: "||a|| (Eq. 114)",
        series,
    };
    super::write_figure(path, |tmp| ivt_plot::line_plot(tmp, &figure))
}
