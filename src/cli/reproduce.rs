//! `ivt reproduce --out DIR [--quick]`: figures, CSVs and `REPRODUCTION.md`
//! (see [`crate::reproduce`]). JSON: `{"report", "figures", "rows", ...}`.

use super::{CliError, Output};
use crate::reproduce::{self, Options, Verdict};
use clap::Args;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `ivt reproduce`.
#[derive(Args)]
pub struct ReproduceArgs {
    /// Output directory (created if missing).
    #[arg(long, default_value = "reproduction")]
    pub out: PathBuf,
    /// Coarser grids and sweeps (used by the test); same rows and figures.
    #[arg(long)]
    pub quick: bool,
}

/// Run the reproduction; the progress bar is shown unless `json`.
///
/// # Errors
/// I/O or drawing failures.
pub fn run(args: ReproduceArgs, json: bool) -> Result<Output, CliError> {
    let report = reproduce::run(
        &args.out,
        Options {
            quick: args.quick,
            progress: !json,
        },
    )?;
    let count = |v: Verdict| report.rows.iter().filter(|r| r.verdict == v).count();
    let mut human = String::new();
    let _ = writeln!(
        human,
        "wrote {} in {:.1} s: {} rows ({} reproduced, {} differ, {} not computable), {} of {} figures",
        report.report.display(),
        report.elapsed_s,
        report.rows.len(),
        count(Verdict::Reproduced),
        count(Verdict::Differs),
        count(Verdict::NotComputable),
        report.figures.iter().filter(|f| f.png.is_some()).count(),
        report.figures.len()
    );
    for r in &report.rows {
        let _ = writeln!(
            human,
            "  {:<16} {:<44} {}",
            r.verdict.as_str(),
            r.quantity,
            r.ours
        );
    }
    let json = serde_json::to_value(&report).map_err(|e| CliError::Failed(e.to_string()))?;
    Ok(Output { json, human })
}
