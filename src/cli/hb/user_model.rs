//! `ivt hb frc MODEL.toml` and `ivt hb solve MODEL.toml --omega W`: a user's
//! model file ([`super::model_file`]) through the jobs of `ivt.hb.frc` and
//! `ivt.hb.solve` (`jobs::frc` with the Newton–chord corrector,
//! `jobs::orbit` at ω_f); the JSON is their dicts, key for key.

use super::model_file::{self, Model};
use super::{orbit_summary, to_json};
use crate::cli::{CliError, Output};
use clap::Args;
use ivt_hb::{AtFrequency, Corrector, FrcOptions};
use ivt_jobs::{self as jobs, FrcRequest, OrbitRequest};
use std::path::PathBuf;

/// `ivt hb frc`.
#[derive(Args)]
pub struct FrcArgs {
    /// The model file (TOML: `[model]` M, C, K inline or as Matrix Market
    /// files, `[[element]]`, `[forcing]`, `[range]`, `[options]`).
    model: PathBuf,
    /// Start frequency ω_f (overrides `[range] from`).
    #[arg(long)]
    from: Option<f64>,
    /// End frequency ω_f (overrides `[range] to`).
    #[arg(long)]
    to: Option<f64>,
}

/// `ivt hb solve`.
#[derive(Args)]
pub struct SolveArgs {
    /// The model file (as for `ivt hb frc`; `[range]` is not used).
    model: PathBuf,
    /// Excitation frequency ω_f.
    #[arg(long)]
    omega: f64,
}

/// `v` if it is a finite positive frequency, else the error naming `what`.
fn frequency(what: &str, v: f64) -> Result<f64, CliError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(CliError::Input(format!(
            "{what} = {v:?}: must be finite and > 0"
        )))
    }
}

/// The frequency-response curve of the model, as `ivt.hb.frc(m, c, k, g, f,
/// from, to)` traces it.
///
/// # Errors
/// The model file's ([`model_file::load`]), a missing or bad range, and the
/// job's.
pub fn frc(a: FrcArgs) -> Result<Output, CliError> {
    let Model {
        problem,
        options,
        range,
        events,
        ..
    } = model_file::load(&a.model)?;
    let pick = |flag: Option<f64>, file: Option<f64>, name: &str| match (flag, file) {
        (Some(v), _) => frequency(&format!("--{name}"), v),
        (None, Some(v)) => Ok(v),
        (None, None) => Err(CliError::Input(format!(
            "{}: no start/end frequency: give `range.{name}` in the file or --{name}",
            a.model.display()
        ))),
    };
    let (from, to) = (pick(a.from, range.0, "from")?, pick(a.to, range.1, "to")?);
    if from == to {
        return Err(CliError::Input(format!(
            "the range from ω_f = {from} to {to} is empty: the ends must differ"
        )));
    }
    let req = FrcRequest {
        options: FrcOptions::sweep(from, to, Corrector::Newton),
        events,
    };
    let curve = jobs::frc(&problem, &options, &req)?;
    let human = format!(
        "{} points from ω_f = {from} to {to}, {} folds, {} events, {:.1} ms\n",
        curve.points.len(),
        curve.folds.len(),
        curve.bifurcations.len(),
        curve.time_s * 1e3
    );
    Ok(Output {
        json: to_json(&curve)?,
        human,
    })
}

/// The periodic solution of the model at `--omega`, as `ivt.hb.solve(m, c,
/// k, g, omega_f, f)` finds it.
///
/// # Errors
/// The model file's ([`model_file::load`]), a bad `--omega`, and the job's.
pub fn solve(a: SolveArgs) -> Result<Output, CliError> {
    let model = model_file::load(&a.model)?;
    let req = OrbitRequest {
        omega_f: frequency("--omega", a.omega)?,
        method: model.method,
        guess: None,
        stability: true,
    };
    let orbit = jobs::orbit(
        &AtFrequency::new(&model.problem, req.omega_f),
        &model.options,
        &req,
    )?;
    let human = format!("ω_f = {}: {}", a.omega, orbit_summary(&orbit));
    Ok(Output {
        json: to_json(&orbit)?,
        human,
    })
}
