//! The rig's serial port, shared by `ivt rig record` (`rig.rs`) and
//! `ivt rig commission` (`rig_commission.rs`): opening it and recording its
//! telemetry into an MCAP file.

use super::CliError;
use ivt_sim::telemetry::{record, RecordOptions, RecordSummary, FIRMWARE_PPR};
use std::io::Read;
use std::path::Path;
use std::time::Duration;

/// Opens the rig's serial port (reads time out after 100 ms, so that the
/// recorder sees the port idle).
pub(super) fn open_port(
    port: &str,
    baud: u32,
) -> Result<Box<dyn serialport::SerialPort>, CliError> {
    serialport::new(port, baud)
        .timeout(Duration::from_millis(100))
        .open()
        .map_err(|e| CliError::Io(format!("{port}: {e}")))
}

/// Records a live port's telemetry into `out`: the firmware's PPR in the
/// metadata, bad frames counted and skipped (not `strict`).
pub(super) fn record_live<R: Read>(
    src: R,
    out: &Path,
    f_timer_hz: f64,
    max_frames: Option<u64>,
    idle_timeout: Duration,
) -> Result<RecordSummary, CliError> {
    let opts = RecordOptions {
        f_timer_hz,
        max_frames,
        idle_timeout,
        ppr: FIRMWARE_PPR,
        strict: false,
    };
    Ok(record(src, out, &opts)?)
}
