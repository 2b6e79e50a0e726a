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
pub mod rig_commission;
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

/// A command-line failure, reported as one line and, under `--json`, as
/// `{"error": message, "kind": kind}` (SPEC §6).
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// Bad user input (argument out of range, malformed file, ...).
    #[error("{0}")]
    Input(String),
    /// A computation that failed (no convergence, no admissible answer, ...).
    #[error("{0}")]
    Failed(String),
    /// Reading or writing a file or stream failed; the message names the path.
    #[error("{0}")]
    Io(String),
}

impl CliError {
    /// The `kind` of the JSON error object: `input`, `failed` or `io`
    /// (`usage` is used for argument-parse errors, before any command runs).
    pub fn kind(&self) -> &'static str {
        match self {
            CliError::Input(_) => "input",
            CliError::Failed(_) => "failed",
            CliError::Io(_) => "io",
        }
    }

    /// An I/O failure on `path`.
    pub fn io(path: &std::path::Path, e: impl std::fmt::Display) -> Self {
        CliError::Io(format!("{}: {e}", path.display()))
    }
}

/// A design-crate error: bad inputs (out-of-range or non-finite arguments,
/// plant parameters, empty grids) are `input`, solver failures `failed`.
impl From<ivt_design::IvtError> for CliError {
    fn from(e: ivt_design::IvtError) -> Self {
        use ivt_design::IvtError as E;
        match e {
            E::Input { .. } | E::Plant(_) | E::EmptyGrid(_) => CliError::Input(e.to_string()),
            E::Stall { .. } | E::NoConvergence { .. } | E::AllFailed { .. } => {
                CliError::Failed(e.to_string())
            }
        }
    }
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

/// Write `bytes` to `path` atomically: into a temporary file in the same
/// directory, renamed over `path` once complete, so that a failure (full disk,
/// interruption) never leaves a partial file behind.
///
/// # Errors
/// [`CliError::Io`] naming the path.
pub fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> Result<(), CliError> {
    ivt_sim::atomic::write_atomic(path, bytes).map_err(|e| CliError::io(path, e))
}

/// Exit status of every failure (argument, input, numerical, I/O).
const EXIT_FAILURE: u8 = 2;

/// Parse the process arguments, run, print, and map errors to exit codes:
/// 0 on success (and for `--help`/`--version`), 2 for every failure. Under
/// `--json` a failure prints exactly one `{"error", "kind"}` object on stdout,
/// argument-parse errors included. A closed stdout (EPIPE) ends quietly with
/// status 2; any other write error (ENOSPC, ...) is reported on stderr.
pub fn main() -> ExitCode {
    install_interrupt_handler();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return parse_failure(&e),
    };
    let json = cli.json;
    let result = match cli.command {
        Some(Command::Kin(cmd)) => kin::run(cmd),
        Some(Command::Sim(args)) => sim::run_file(&args, json),
        Some(Command::Bench(cmd)) => bench::run(cmd),
        Some(Command::Ol(cmd)) => ol::run(cmd),
        Some(Command::Stability(a)) => stability::run(a),
        Some(Command::StabilityMap(a)) => stability::run_map(a),
        Some(Command::Ctrl(cmd)) => ctrl::run(cmd),
        Some(Command::Rig(cmd)) => rig::run(cmd),
        Some(Command::Hb(cmd)) => hb::run(cmd),
        Some(Command::Reproduce(args)) => reproduce::run(args, json),
        None => sim::run_default(json),
    };
    match result {
        Ok(out) if json => finish(print_stdout(&format!("{}\n", out.json))),
        Ok(out) => finish(print_stdout(&out.human)),
        Err(e) => report_error(json, &e.to_string(), e.kind()),
    }
}

/// Exit status after SIGINT/SIGTERM (128 + SIGINT, the shell's convention).
const EXIT_INTERRUPTED: i32 = 130;

/// On SIGINT/SIGTERM, delete every staged (incomplete) output file and exit
/// 130, or — while the rig recorder is running — let it stop reading and
/// close its MCAP with a valid footer ([`ivt_sim::atomic::on_interrupt`]).
fn install_interrupt_handler() {
    let installed = ctrlc::set_handler(|| {
        if !ivt_sim::atomic::on_interrupt() {
            std::process::exit(EXIT_INTERRUPTED);
        }
    });
    if let Err(e) = installed {
        note(&format!("warning: no interrupt handler: {e}"));
    }
}

/// `--help`/`--version` print and succeed; every other parse error is a
/// `usage` error (JSON object under `--json`, which is looked up in the raw
/// arguments because parsing failed).
fn parse_failure(e: &clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
        return finish(print_stdout(&e.render().to_string()));
    }
    let json = std::env::args_os()
        .take_while(|a| a != "--")
        .any(|a| a == "--json");
    let rendered = e.render().to_string();
    let message = if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
        "a subcommand is required (see --help)".to_string()
    } else {
        // clap's message up to the usage line, on one line.
        rendered
            .lines()
            .take_while(|l| !l.starts_with("Usage:"))
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect::<Vec<_>>()
            .join(" ")
            .trim_start_matches("error: ")
            .to_string()
    };
    if json {
        report_error(true, &message, "usage")
    } else {
        note(rendered.trim_end());
        ExitCode::from(EXIT_FAILURE)
    }
}

/// Print a failure: one JSON object on stdout under `--json`, and always one
/// line on stderr.
fn report_error(json: bool, message: &str, kind: &str) -> ExitCode {
    if json {
        let object = serde_json::json!({ "error": message, "kind": kind });
        if let Err(e) = print_stdout(&format!("{object}\n")) {
            if e.kind() != std::io::ErrorKind::BrokenPipe {
                note(&format!("error: writing stdout: {e}"));
            }
        }
    }
    note(&format!("error: {message}"));
    ExitCode::from(EXIT_FAILURE)
}

/// Exit status after printing the result: 0, or 2 when stdout failed
/// (quietly for a closed pipe, with the reason otherwise).
fn finish(printed: std::io::Result<()>) -> ExitCode {
    match printed {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::from(EXIT_FAILURE),
        Err(e) => {
            note(&format!("error: writing stdout: {e}"));
            ExitCode::from(EXIT_FAILURE)
        }
    }
}

/// Write `text` to stdout and flush, returning the error instead of
/// panicking as `print!` does on a closed pipe or a full disk.
fn print_stdout(text: &str) -> std::io::Result<()> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())?;
    out.flush()
}

/// One line on stderr for people; a closed stderr is ignored (never a panic).
pub fn note(line: &str) {
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}
