//! Command-line interface (SPEC §6). Every subcommand takes `--json` and then
//! prints exactly one JSON object on stdout; errors print `{"error": ...}`
//! under `--json` and exit with status 2.
//!
//! One module per command group; each exposes a clap `Args`/`Subcommand`
//! type and a `run` returning an [`Output`].

use clap::{Parser, Subcommand};
use std::process::ExitCode;

pub mod bench;
pub mod ctrl;
pub mod hb;
pub mod kin;
pub mod ol;
pub mod reproduce;
pub mod rig;
pub mod sim;
pub mod stability;
pub mod string;

/// Result of a command: the JSON object for `--json` and the text for humans.
pub struct Output {
    /// The object printed under `--json`.
    pub json: serde_json::Value,
    /// What a person reads on the terminal.
    pub human: String,
}

/// A command-line failure, reported as one line.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// Bad user input (argument out of range, malformed file, ...).
    #[error("{0}")]
    Input(String),
    /// A computation that failed (no convergence, I/O, ...).
    #[error("{0}")]
    Failed(String),
}

#[derive(Parser)]
#[command(
    name = "ivt",
    version,
    about = "IVT toolkit: kinematics, harmonic balance, controller and simulator (Wang 2017)"
)]
struct Cli {
    /// Print exactly one JSON object on stdout instead of text.
    #[arg(long, global = true)]
    json: bool,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Kinematics of the GIVT, SGIVT and its variant (Chapter 2).
    #[command(subcommand)]
    Kin(kin::KinCommand),
    /// Simulate a scene (TOML): plant, sensors, controller, outputs.
    Sim(sim::SimArgs),
    /// Benchmarks (work–precision of the plant integrators).
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// Open-loop law from the model: IHB steady state, grid table, refit (§4.2.1).
    #[command(subcommand)]
    Ol(ol::OlCommand),
    /// Floquet multipliers of the time-delay loop at one point (§4.3).
    Stability(stability::StabilityArgs),
    /// Max |multiplier| over a grid (Fig. 42 analogue).
    StabilityMap(stability::MapArgs),
    /// The rig controller (ivt-ctrl): offline replay of pulse logs.
    #[command(subcommand)]
    Ctrl(ctrl::CtrlCommand),
    /// Harmonic balance: Duffing, frequency response, Mathieu–Duffing (Chapter 3).
    #[command(subcommand)]
    Hb(hb::HbCommand),
    /// The rig: record firmware telemetry into MCAP.
    #[command(subcommand)]
    Rig(rig::RigCommand),
    /// Regenerate the thesis's computable figures and numbers (REPRODUCTION.md).
    Reproduce(reproduce::ReproduceArgs),
}

/// Parse the process arguments, run, print, and map errors to exit codes.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Kin(cmd)) => kin::run(cmd),
        Some(Command::Sim(args)) => sim::run_file(&args, cli.json),
        Some(Command::Bench(cmd)) => bench::run(cmd),
        Some(Command::Ol(cmd)) => ol::run(cmd),
        Some(Command::Stability(a)) => stability::run(a),
        Some(Command::StabilityMap(a)) => stability::run_map(a),
        Some(Command::Ctrl(cmd)) => ctrl::run(cmd),
        Some(Command::Rig(cmd)) => rig::run(cmd),
        Some(Command::Hb(cmd)) => hb::run(cmd),
        Some(Command::Reproduce(args)) => reproduce::run(args, cli.json),
        None => sim::run_default(cli.json),
    };
    match result {
        Ok(out) => {
            if cli.json {
                println!("{}", out.json);
            } else {
                print!("{}", out.human);
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            if cli.json {
                println!("{}", serde_json::json!({ "error": e.to_string() }));
            }
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
