//! `ivt bench ...`: benchmarks whose numbers go into the READMEs.

use super::{CliError, Output};
use clap::Subcommand;
use ivt_kin::params::Typed;
use serde_json::json;

/// Benchmark subcommands.
#[derive(Subcommand)]
pub enum BenchCommand {
    /// Error in ω_a after ≈ 10 s vs run time for the plant integrators (DP5 over
    /// tolerances 1e-3…1e-12, RK4 over angle steps); bench/work_precision.py adds scipy.
    WorkPrecision {
        /// Timing budget per row, in seconds (best-of-N within it, N ≥ 3).
        #[arg(long, default_value_t = 0.2)]
        budget: f64,
    },
}

/// Run a benchmark.
///
/// # Errors
/// A non-positive or non-finite budget.
pub fn run(cmd: BenchCommand) -> Result<Output, CliError> {
    match cmd {
        BenchCommand::WorkPrecision { budget } => {
            if !(budget.is_finite() && budget > 0.0 && budget <= 60.0) {
                return Err(CliError::Input(format!(
                    "--budget must be in (0, 60] s, got {}",
                    Typed(budget)
                )));
            }
            let s = ivt_sim::work_precision::study(budget);
            let mut human = format!(
                "work–precision: ω_a over the last revolution at θ = {} rad (V_m = {} V, T_U = {} N·m, r = {} m)\n\
                 reference ω_a = {:.15} rad/s (check {:.1e})\n{:<6} {:>10} {:>12} {:>10} {:>8}\n",
                s.problem.theta_end, s.problem.v_m, s.problem.t_u, s.problem.r, s.reference, s.reference_check,
                "method", "tol/h", "time [s]", "error", "steps"
            );
            for r in &s.rows {
                human.push_str(&format!(
                    "{:<6} {:>10.1e} {:>12.3e} {:>10.2e} {:>8}\n",
                    r.method, r.tolerance, r.run_time_s, r.error, r.steps
                ));
            }
            Ok(Output {
                json: json!(s),
                human,
            })
        }
    }
}
