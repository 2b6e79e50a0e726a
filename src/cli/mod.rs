//! Command-line interface (SPEC §6). Every subcommand takes `--json` and then
//! prints exactly one JSON object on stdout; errors print `{"error": ...}`
//! under `--json` and exit with status 2.
//!
//! One module per command group; each exposes a clap `Args`/`Subcommand`
//! type and a `run` returning an [`Output`].

use clap::{Parser, Subcommand};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

pub mod bench;
pub mod commissioning;
pub mod ctrl;
pub mod hb;
pub mod kin;
pub mod ol;
pub mod reproduce;
pub mod rig;
pub mod rig_commission;
pub mod rig_identify;
mod rig_port;
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
    /// A recording that does not determine the plant (`ivt rig identify`:
    /// a coefficient not excited, a residual far above the noise, a plant
    /// that is not physical); the message names the check and its numbers.
    #[error("{0}")]
    Unidentifiable(String),
}

impl CliError {
    /// The `kind` of the JSON error object: `input`, `failed`, `io` or
    /// `unidentifiable` (`usage` is used for argument-parse errors, before
    /// any command runs).
    pub fn kind(&self) -> &'static str {
        match self {
            CliError::Input(_) => "input",
            CliError::Failed(_) => "failed",
            CliError::Io(_) => "io",
            CliError::Unidentifiable(_) => "unidentifiable",
        }
    }

    /// An I/O failure on `path`.
    pub fn io(path: &std::path::Path, e: impl std::fmt::Display) -> Self {
        CliError::Io(format!("{}: {e}", path.display()))
    }
}

/// Check `value`, given as `flag`, against key `key` of the one description
/// of user-settable numbers ([`ivt_kin::params`]; the pair must be one of its
/// `ALIASES`): `--theta-ct = 3600.0000001 deg is outside [0, 3600] deg`.
///
/// # Errors
/// [`CliError::Input`] naming the flag and the value as typed.
pub fn check_flag(flag: &'static str, key: &str, value: f64) -> Result<(), CliError> {
    ivt_kin::params::check_as(ivt_kin::params::Boundary::Cli, flag, key, value)
        .map_err(|refused| CliError::Input(format!("{flag} {refused}")))
}

/// A scene or plant file error: `io` when the file could not be read
/// (missing, not a regular file, over its size budget), else `input`.
impl From<ivt_sim::scene::SceneError> for CliError {
    fn from(e: ivt_sim::scene::SceneError) -> Self {
        if e.unreadable {
            CliError::Io(e.message)
        } else {
            CliError::Input(e.message)
        }
    }
}

/// A simulator error: a work budget exceeded or a scene refused is the
/// user's input, a file that could not be written or read (an output, the
/// telemetry stream) `io`, the rest a failed run.
impl From<ivt_sim::SimError> for CliError {
    fn from(e: ivt_sim::SimError) -> Self {
        use ivt_sim::SimError as E;
        match e {
            E::Budget(_) | E::Scene(_) => CliError::Input(e.to_string()),
            E::Io { .. } | E::Mcap { .. } | E::TelemetryRead(_) => CliError::Io(e.to_string()),
            _ => CliError::Failed(e.to_string()),
        }
    }
}

/// The reproduction's error: a file it could not write is `io`, the rest
/// failed.
impl From<crate::reproduce::ReproError> for CliError {
    fn from(e: crate::reproduce::ReproError) -> Self {
        match e {
            crate::reproduce::ReproError::Io { .. } => CliError::Io(e.to_string()),
            _ => CliError::Failed(e.to_string()),
        }
    }
}

/// A harmonic-balance error: `input` or `failed` as
/// [`ivt_hb::HbError::kind`] says.
impl From<ivt_hb::HbError> for CliError {
    fn from(e: ivt_hb::HbError) -> Self {
        if e.kind() == "input" {
            CliError::Input(e.to_string())
        } else {
            CliError::Failed(e.to_string())
        }
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
    about = "IVT toolkit: kinematics, harmonic balance, controller and simulator (Wang 2017)",
    after_help = "Exit status: 0 success; 2 failure, under --json with one {\"error\", \"kind\"} \
                  object on stdout, kind \"usage\" | \"input\" | \"failed\" | \"io\" | \"unidentifiable\"; 130 \
                  stopped \
                  by SIGINT/SIGTERM (kind \"interrupted\"). Inputs are read from regular files only; \
                  no output replaces an input of the run. See the guide's Limits and errors."
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

/// Write `bytes` to `path` through the one output writer
/// ([`ivt_sim::atomic`]): into a fresh temporary file beside it, renamed over
/// `path` once complete, so that a failure (full disk, interruption) never
/// leaves a partial file behind; a `path` that is a symlink, a directory or a
/// device is refused.
///
/// # Errors
/// [`CliError::Io`] naming the path.
pub fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> Result<(), CliError> {
    ivt_sim::atomic::write_atomic(path, bytes).map_err(|e| CliError::io(path, e))
}

/// Draw a figure into `path` through the one output writer: `draw` renders
/// into the staged temporary PNG, which replaces `path` only when complete.
///
/// # Errors
/// [`CliError::Io`] for the file, [`CliError::Failed`] for the drawing, both
/// naming `path`.
pub fn write_figure(
    path: &std::path::Path,
    draw: impl FnOnce(&std::path::Path) -> Result<(), ivt_plot::PlotError>,
) -> Result<(), CliError> {
    let mut staged = ivt_sim::atomic::Staged::new();
    let tmp = staged.path(path).map_err(|e| CliError::io(path, e))?;
    draw(&tmp).map_err(|e| CliError::Failed(e.for_path(path).to_string()))?;
    staged.commit().map_err(|e| CliError::io(path, e))?;
    Ok(())
}

/// Parse `args` (program name first) as `ivt` does and, for the `kin`
/// commands (pure, bounded, writing no file), run the command: the fuzz
/// target of the argument vector (`fuzz/fuzz_targets/cli_args.rs`). Parse
/// and command errors are returned as text; a panic is the bug it hunts.
///
/// # Errors
/// The parse or command failure, one line.
#[doc(hidden)]
pub fn fuzz_args(args: &[std::ffi::OsString]) -> Result<(), String> {
    let cli = parse(args).map_err(|e| e.kind().to_string())?;
    match cli.command {
        Some(Command::Kin(cmd)) => kin::run(cmd).map(|_| ()).map_err(|e| e.to_string()),
        _ => Ok(()),
    }
}

/// The command line (`Cli`) with every option that takes a value accepting
/// a negative number (`--xi -0.5`, `--vm -8`), which clap otherwise reads as
/// a flag (`-0`); the command checks the value's range.
pub fn command() -> clap::Command {
    fn negative_numbers(cmd: clap::Command) -> clap::Command {
        cmd.mut_args(|a| {
            if a.get_action().takes_values() {
                a.allow_negative_numbers(true)
            } else {
                a
            }
        })
        .mut_subcommands(negative_numbers)
    }
    negative_numbers(<Cli as clap::CommandFactory>::command())
}

/// `args` (program name first) parsed by [`command`].
fn parse<I, T>(args: I) -> Result<Cli, clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let matches = command().try_get_matches_from(args)?;
    <Cli as clap::FromArgMatches>::from_arg_matches(&matches)
}

/// Exit status of every failure (argument, input, numerical, I/O).
const EXIT_FAILURE: u8 = 2;

/// Parse the process arguments, run, print, and map errors to exit codes:
/// 0 on success (and for `--help`/`--version`), 2 for every failure, 130
/// when SIGINT/SIGTERM stopped the run. Under `--json` a failure prints
/// exactly one `{"error", "kind"}` object on stdout, argument-parse errors
/// included. A reader that closed the pipe (EPIPE) ends the command quietly
/// with status 2; any other write error (ENOSPC, ...) is reported on stderr.
/// A stdout on `/dev/null` (`subprocess.DEVNULL`, `>/dev/null`) is written
/// to like any other: the command runs and writes its files. (A stdout
/// closed with `>&-` cannot be told from it: the Rust runtime reopens a
/// closed descriptor 1 on `/dev/null` read-write before `main`, as Python
/// opens `DEVNULL`.)
pub fn main() -> ExitCode {
    // Looked up in the raw arguments: the interrupt handler and a parse
    // failure need it before (or without) a parsed command line.
    let json = std::env::args_os()
        .take_while(|a| a != "--")
        .any(|a| a == "--json");
    JSON.store(json, Ordering::SeqCst);
    install_interrupt_handler();
    let cli = match parse(std::env::args_os()) {
        Ok(cli) => cli,
        Err(e) => return parse_failure(&e, json),
    };
    let json = cli.json;
    JSON.store(json, Ordering::SeqCst);
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

/// Exit status after SIGINT/SIGTERM, with or without `--json`: 128 +
/// SIGINT, the shell's convention for a run stopped by the user (an
/// interruption is not an error of the input or of the computation; under
/// `--json` its one `{"error", "kind": "interrupted"}` object says so).
const EXIT_INTERRUPTED: u8 = 130;

/// `--json` is on the command line.
static JSON: AtomicBool = AtomicBool::new(false);
/// Stdout, and whether the command's one object (or error) was printed on
/// it: the interrupt handler and the command never both print.
static STDOUT_DONE: Mutex<bool> = Mutex::new(false);

/// On SIGINT/SIGTERM, delete every staged (incomplete) output file and every
/// directory the run created, print the one `{"error", "kind":
/// "interrupted"}` object under `--json`, and exit with
/// [`EXIT_INTERRUPTED`] — or, while the rig recorder is running, let it stop
/// reading and close its MCAP with a valid footer
/// ([`ivt_sim::atomic::on_interrupt`]).
fn install_interrupt_handler() {
    let installed = ctrlc::set_handler(|| {
        if ivt_sim::atomic::on_interrupt() {
            return;
        }
        let message = "interrupted (SIGINT/SIGTERM); the outputs of this run were removed";
        let mut done = STDOUT_DONE
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let json = JSON.load(Ordering::SeqCst);
        if !*done && json {
            let object = serde_json::json!({ "error": message, "kind": "interrupted" });
            let _ = write_stdout(&format!("{object}\n"));
        }
        *done = true;
        note(&format!("error: {message}"));
        // exits with the lock held: nothing else reaches stdout
        std::process::exit(i32::from(EXIT_INTERRUPTED));
    });
    if let Err(e) = installed {
        note(&format!("warning: no interrupt handler: {e}"));
    }
}

/// `--help`/`--version` (and `help`) print and succeed — under `--json` as
/// one object, `{"help": text}` or `{"name", "version"}`; every other parse
/// error is a `usage` error (a JSON object under `--json`).
fn parse_failure(e: &clap::Error, json: bool) -> ExitCode {
    use clap::error::ErrorKind;
    match (e.kind(), json) {
        (ErrorKind::DisplayVersion, true) => {
            let object = serde_json::json!({
                "name": env!("CARGO_PKG_NAME"),
                "version": env!("CARGO_PKG_VERSION"),
            });
            return finish(print_stdout(&format!("{object}\n")));
        }
        (ErrorKind::DisplayHelp, true) => {
            let object = serde_json::json!({ "help": e.render().to_string() });
            return finish(print_stdout(&format!("{object}\n")));
        }
        (ErrorKind::DisplayHelp | ErrorKind::DisplayVersion, false) => {
            return finish(print_stdout(&e.render().to_string()));
        }
        _ => {}
    }
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

/// Write the command's one answer to stdout and flush, returning the error
/// instead of panicking as `print!` does on a closed pipe or a full disk;
/// nothing is printed after an interruption was reported.
fn print_stdout(text: &str) -> std::io::Result<()> {
    let mut done = STDOUT_DONE
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if *done {
        return Ok(());
    }
    *done = true;
    write_stdout(text)
}

fn write_stdout(text: &str) -> std::io::Result<()> {
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
