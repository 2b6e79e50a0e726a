//! Processor in the loop: the QEMU firmware (`firmware/`, image
//! `ivt-fw-qemu`) runs the controller; each pulse and each reading goes over
//! its UART (a Unix socket on the host side, frames of `ivt-wire`) and the
//! firmware's `ControlOutput` comes back bit-exact. The firmware is built for
//! one PPR (`firmware/src/app.rs`, 1200); a scene with another PPR is refused
//! at start with the firmware's and the scene's values.

use ivt_ctrl::{Config, ControlOutput};
use ivt_wire::host::{PilError, QemuOptions, QemuPil};

use crate::backend::{BackendError, ControllerBackend};

/// The QEMU firmware as a controller backend.
pub struct Pil {
    link: Option<QemuPil>,
}

impl Pil {
    /// Starts QEMU (options from [`QemuOptions::from_env`]: `$IVT_FW_ELF` or
    /// the image built by `firmware/run-qemu.sh build`) and loads `config`.
    ///
    /// # Errors
    /// [`BackendError::Io`] if QEMU or the image is missing or does not
    /// answer; [`BackendError::Protocol`] if the firmware's PPR differs.
    pub fn start(ppr: usize, config: &Config) -> Result<Self, BackendError> {
        Self::start_with(&QemuOptions::from_env(), ppr, config)
    }

    /// As [`Pil::start`] with explicit QEMU options.
    ///
    /// # Errors
    /// As [`Pil::start`].
    pub fn start_with(
        opts: &QemuOptions,
        ppr: usize,
        config: &Config,
    ) -> Result<Self, BackendError> {
        let mut link = QemuPil::start(opts, ppr as u32).map_err(to_backend)?;
        link.configure(config).map_err(to_backend)?;
        Ok(Self { link: Some(link) })
    }

    fn link(&mut self) -> Result<&mut QemuPil, BackendError> {
        self.link
            .as_mut()
            .ok_or_else(|| BackendError::Io("PIL session already finished".into()))
    }

    /// Ends the session cleanly (QEMU exits 0) and returns the firmware's
    /// report (pulses served, stack high-water mark).
    ///
    /// # Errors
    /// As [`Pil::start`].
    pub fn finish(&mut self) -> Result<ivt_wire::host::FirmwareReport, BackendError> {
        match self.link.take() {
            Some(link) => link.finish().map_err(to_backend),
            None => Err(BackendError::Io("PIL session already finished".into())),
        }
    }
}

fn to_backend(e: PilError) -> BackendError {
    match e {
        PilError::Protocol { .. } | PilError::Incompatible { .. } | PilError::Wire(_) => {
            BackendError::Protocol(e.to_string())
        }
        _ => BackendError::Io(e.to_string()),
    }
}

impl ControllerBackend for Pil {
    fn on_pulse(&mut self, ticks: u32) -> Result<ControlOutput, BackendError> {
        self.link()?.on_pulse(ticks).map_err(to_backend)
    }

    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), BackendError> {
        self.link()?.update_inputs(v_m, t_u).map_err(to_backend)
    }
}
