//! Processor in the loop: the QEMU firmware (`firmware/`, image
//! `ivt-fw-qemu`) runs the controller; each pulse and each reading goes over
//! its UART (a Unix socket on the host side, frames of `ivt-wire`) and the
//! firmware's `ControlOutput` comes back bit-exact. The firmware is built for
//! one PPR (`firmware/src/app.rs`, 1200); a scene with another PPR is refused
//! at start with the firmware's and the scene's values.

use ivt_ctrl::{Config, ControlOutput};
use ivt_wire::host::{PilError, QemuOptions, QemuPil};

use crate::backend::ControllerBackend;
use crate::error::SimError;

/// The QEMU firmware as a controller backend.
pub struct Pil {
    link: Option<QemuPil>,
}

impl Pil {
    /// Starts QEMU (options from [`QemuOptions::from_env`]: `$IVT_FW_ELF` or
    /// the image built by `firmware/run-qemu.sh build`) and loads `config`.
    ///
    /// # Errors
    /// [`SimError::BackendIo`] if QEMU or the image is missing or does not
    /// answer; [`SimError::BackendProtocol`] if the firmware's PPR differs.
    pub fn start(ppr: usize, config: &Config) -> Result<Self, SimError> {
        Self::start_with(&QemuOptions::from_env(), ppr, config)
    }

    /// As [`Pil::start`] with explicit QEMU options.
    ///
    /// # Errors
    /// As [`Pil::start`].
    pub fn start_with(opts: &QemuOptions, ppr: usize, config: &Config) -> Result<Self, SimError> {
        let mut link = QemuPil::start(opts, ppr as u32).map_err(to_backend)?;
        link.configure(config).map_err(to_backend)?;
        Ok(Self { link: Some(link) })
    }

    fn link(&mut self) -> Result<&mut QemuPil, SimError> {
        self.link
            .as_mut()
            .ok_or_else(|| SimError::BackendIo("PIL session already finished".into()))
    }

    /// Ends the session cleanly (QEMU exits 0) and returns the firmware's
    /// report (pulses served, stack high-water mark).
    ///
    /// # Errors
    /// As [`Pil::start`].
    pub fn finish(&mut self) -> Result<ivt_wire::host::FirmwareReport, SimError> {
        match self.link.take() {
            Some(link) => link.finish().map_err(to_backend),
            None => Err(SimError::BackendIo("PIL session already finished".into())),
        }
    }
}

fn to_backend(e: PilError) -> SimError {
    match e {
        PilError::Protocol { .. } | PilError::Incompatible { .. } | PilError::Wire(_) => {
            SimError::BackendProtocol(e.to_string())
        }
        _ => SimError::BackendIo(e.to_string()),
    }
}

impl ControllerBackend for Pil {
    fn on_pulse(&mut self, ticks: u32) -> Result<ControlOutput, SimError> {
        self.link()?.on_pulse(ticks).map_err(to_backend)
    }

    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), SimError> {
        self.link()?.update_inputs(v_m, t_u).map_err(to_backend)
    }
}

impl crate::commission::SequencedBackend for Pil {
    fn sequenced_pulse(&mut self, ticks: u32) -> Result<crate::commission::Sequenced, SimError> {
        match self.link()?.sequenced_pulse(ticks).map_err(to_backend)? {
            ivt_wire::Reply::Sequenced {
                out,
                stage,
                started,
                pulse_log,
                ..
            } => Ok(crate::commission::Sequenced {
                out,
                stage,
                started,
                pulse_log,
            }),
            got => Err(SimError::BackendProtocol(format!(
                "expected Sequenced, got {got:?}"
            ))),
        }
    }

    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), SimError> {
        self.link()?.update_inputs(v_m, t_u).map_err(to_backend)
    }
}

/// Runs the commissioning plan of `opts` with the QEMU firmware driving the
/// sequence (`ivt rig commission --sim --pil`): the SIL run of
/// [`crate::commission::run_sil`] with the firmware's sequencer and
/// controller; the recording is the same bit for bit. The QEMU session is
/// ended cleanly afterwards.
///
/// # Errors
/// As [`crate::commission::run_sil`], and the backend's start or end.
pub fn run_pil_commission(
    opts: &crate::commission::CommissionOptions,
    out: &std::path::Path,
) -> Result<crate::commission::CommissionSummary, SimError> {
    let scene = crate::commission::scene(opts)?;
    let config = crate::commission::rig_config(&scene)?;
    let mut pil = Pil::start(scene.encoder.ppr, &config)?;
    pil.link()?
        .commission(opts.selection, &opts.plan)
        .map_err(to_backend)?;
    let (summary, mut pil) = crate::commission::run_with(opts, &scene, pil, out)?;
    pil.finish()?;
    Ok(summary)
}

/// Runs a scene with the QEMU firmware as the controller (`ivt sim SCENE
/// --pil`): the same closed loop as [`crate::run::Simulation::run`] with the [`Pil`]
/// backend in place of the in-process one. The QEMU session is ended cleanly
/// afterwards (a firmware that died mid-run surfaces as a backend error).
///
/// # Errors
/// Scene, integration and backend failures, as [`crate::run::Simulation::run`].
pub fn run_pil(
    scene: &crate::scene::Scene,
    progress: &mut dyn FnMut(f64),
) -> Result<crate::run::RunResult, SimError> {
    let params = scene
        .plant_params()
        .map_err(|e| SimError::Scene(e.to_string()))?;
    let Some(config) = crate::run::controller_config(scene, params.r_max) else {
        return Err(SimError::Scene(
            "`controller.law = \"none\"` has no controller to put in the loop".into(),
        ));
    };
    let backend = Shared::new(Pil::start(scene.encoder.ppr, &config)?);
    let result = crate::run::Simulation::new(scene)
        .backend(Box::new(backend.clone()))
        .progress(progress)
        .run()?;
    backend.finish()?;
    Ok(result)
}

/// A [`Pil`] the run loop can own as a boxed backend while the caller keeps a
/// handle to end the session afterwards.
#[derive(Clone)]
struct Shared(std::rc::Rc<std::cell::RefCell<Pil>>);

impl Shared {
    fn new(pil: Pil) -> Self {
        Self(std::rc::Rc::new(std::cell::RefCell::new(pil)))
    }

    fn finish(&self) -> Result<ivt_wire::host::FirmwareReport, SimError> {
        self.0.borrow_mut().finish()
    }
}

impl ControllerBackend for Shared {
    fn on_pulse(&mut self, ticks: u32) -> Result<ControlOutput, SimError> {
        self.0.borrow_mut().on_pulse(ticks)
    }

    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), SimError> {
        self.0.borrow_mut().update_inputs(v_m, t_u)
    }
}
