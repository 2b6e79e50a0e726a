//! `ivt rig record --port DEV --out run.mcap`: telemetry of the rig firmware
//! (or the QEMU image's UART1 on a pty) into the simulator's MCAP channels;
//! `ivt rig commission` is in `rig_commission.rs`.

use super::rig_port::{open_port, record_live};
use super::{CliError, Output};
use clap::{Args, Subcommand};
use serde_json::json;
use std::path::PathBuf;
use std::time::Duration;

/// `ivt rig ...`
#[derive(Subcommand)]
pub enum RigCommand {
    /// Record telemetry frames from a serial port into an MCAP file.
    Record(RecordArgs),
    /// Identify the plant from a commissioning recording (`rig_identify.rs`).
    Identify(super::rig_identify::IdentifyArgs),
    /// Run the commissioning sequences (Fig. 47, 48, 50, 51) on a rig or
    /// against the simulated one, into an MCAP recording.
    Commission(super::rig_commission::CommissionArgs),
}

/// Arguments of `ivt rig record`.
#[derive(Args)]
pub struct RecordArgs {
    /// Serial device (the rig's USART1 adapter, or a QEMU pty).
    #[arg(long)]
    pub port: String,
    /// Output MCAP file.
    #[arg(long)]
    pub out: PathBuf,
    /// Baud rate (the rig firmware sends at 921600).
    #[arg(long, default_value_t = 921_600)]
    pub baud: u32,
    /// Timer rate of the firmware's timestamps in Hz (rig: 10 MHz).
    #[arg(long, default_value_t = 10.0e6)]
    pub f_timer_hz: f64,
    /// Stop after this many frames (default: until the port closes or idles).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Stop after this many seconds without a byte.
    #[arg(long, default_value_t = 2.0)]
    pub idle_timeout_s: f64,
}

/// Run a `rig` subcommand.
///
/// # Errors
/// Port or output failures as [`CliError::Failed`].
pub fn run(cmd: RigCommand) -> Result<Output, CliError> {
    match cmd {
        RigCommand::Record(a) => record_cmd(&a),
        RigCommand::Identify(a) => super::rig_identify::run(&a),
        RigCommand::Commission(a) => super::rig_commission::commission_cmd(&a),
    }
}

/// Longest `--idle-timeout-s`: one day (a recorder idle longer is stopped
/// with Ctrl-C, which closes the MCAP cleanly).
const MAX_IDLE_TIMEOUT: Duration = Duration::from_secs(86_400);

fn record_cmd(a: &RecordArgs) -> Result<Output, CliError> {
    super::check_flag("--f-timer-hz", "encoder.f_timer_hz", a.f_timer_hz)?;
    let idle_timeout = Duration::try_from_secs_f64(a.idle_timeout_s)
        .ok()
        .filter(|d| !d.is_zero() && *d <= MAX_IDLE_TIMEOUT)
        .ok_or_else(|| {
            CliError::Input(format!(
                "--idle-timeout-s must be in (0, {}] s, got {:?}",
                MAX_IDLE_TIMEOUT.as_secs(),
                a.idle_timeout_s
            ))
        })?;
    let port = open_port(&a.port, a.baud)?;
    // Tell whoever waits (a test driving the firmware) that the port is open.
    super::note(&format!("recording from {}", a.port));
    let s = record_live(port, &a.out, a.f_timer_hz, a.frames, idle_timeout)?;
    let human = format!(
        "{} telemetry frames ({} bad) over {:.3} s → {}\n",
        s.frames,
        s.bad_frames,
        s.duration_s,
        s.out.display()
    );
    Ok(Output {
        json: json!({
            "frames": s.frames,
            "bad_frames": s.bad_frames,
            "first_bad_offset": s.first_bad_offset,
            "frame_version": s.frame_version,
            "duration_s": s.duration_s,
            "channels": s.channels,
            "out": s.out.display().to_string(),
        }),
        human,
    })
}
