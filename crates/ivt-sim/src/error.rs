//! The one error type of the simulator: every failure of a scene, the plant
//! integrator, the controller backend, the IHB route, an output file or the
//! telemetry recorder, each variant with the values that locate it.

use crate::plant::DIM;
use ivt_ctrl::UnsupportedPpr;
use ivt_design::IvtError;
use std::path::{Path, PathBuf};

/// A failure of the simulator.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The scene is inconsistent.
    #[error("scene: {0}")]
    Scene(String),
    /// The adaptive step fell below the resolution of x.
    #[error(
        "step size underflow at t = {t:?} s, θ = {theta:?} rad, ω = {omega:?} rad/s (h = {h:e})"
    )]
    StepUnderflow {
        /// Time.
        t: f64,
        /// Angle.
        theta: f64,
        /// Speed.
        omega: f64,
        /// Last tried step.
        h: f64,
    },
    /// An advance of the plant needed more steps than
    /// [`crate::integrate::MAX_STEPS_PER_ADVANCE`] (a very stiff plant, e.g. a
    /// tiny L_a, or an absurd tolerance).
    #[error("no progress: {steps} steps without reaching the next event at t = {t:?} s, θ = {theta:?} rad, ω = {omega:?} rad/s (stiff plant or tolerance too tight?)")]
    TooManySteps {
        /// Time.
        t: f64,
        /// Angle.
        theta: f64,
        /// Speed.
        omega: f64,
        /// The budget that ran out.
        steps: u64,
    },
    /// The plant state became NaN or infinite.
    #[error("state not finite at t = {t:?} s: {state:?}")]
    NotFinite {
        /// Time.
        t: f64,
        /// `[θ, ω, i_a]`.
        state: [f64; DIM],
    },
    /// The requested encoder resolution has no compiled controller.
    #[error("{0}")]
    UnsupportedPpr(UnsupportedPpr),
    /// The controller backend's link failed.
    #[error("controller backend I/O: {0}")]
    BackendIo(String),
    /// The controller backend answered something that is not a valid reply.
    #[error("controller backend protocol: {0}")]
    BackendProtocol(String),
    /// The harmonic-balance solve of the IHB route failed (with its residual
    /// history).
    #[error("IHB steady state: {0}")]
    Ihb(#[from] IvtError),
    /// Creating, writing or renaming a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// The MCAP writer failed.
    #[error("{path}: MCAP: {msg}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// The error.
        msg: String,
    },
    /// Drawing a plot failed.
    #[error("{path}: plot: {msg}")]
    Plot {
        /// The file.
        path: PathBuf,
        /// The error.
        msg: String,
    },
    /// Reading the telemetry stream failed.
    #[error("reading telemetry: {0}")]
    TelemetryRead(std::io::Error),
    /// A telemetry stream with a truncated or corrupt frame (strict reading).
    #[error("telemetry: {0}")]
    TelemetryStream(ivt_wire::telemetry::StreamError),
    /// The run would exceed its work budget ([`crate::scene::DEFAULT_MAX_EVENTS`]);
    /// the message carries the estimate and the limit.
    #[error("work budget: {0}")]
    Budget(String),
    /// The telemetry timer rate is not a positive finite number.
    #[error("f_timer_hz must be positive and finite, got {0:?}")]
    BadTimer(f64),
}

/// Maps an I/O error on `path` to [`SimError::Io`].
pub(crate) fn io_at(path: &Path) -> impl FnOnce(std::io::Error) -> SimError + '_ {
    move |source| SimError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Maps an MCAP writer error on `path` to [`SimError::Mcap`].
pub(crate) fn mcap_at(path: &Path) -> impl Fn(mcap::McapError) -> SimError + '_ {
    move |e| SimError::Mcap {
        path: path.to_path_buf(),
        msg: e.to_string(),
    }
}
