//! The controller as the closed loop sees it: software in the loop (the
//! in-process `ivt-ctrl` controller) or processor in the loop (the QEMU
//! firmware over a UART, `pil.rs`). The step generator runs inside the
//! backend; the simulator reads `stepper_target` and moves its own stepper
//! model (with rate limits and missed steps) towards it.

use crate::error::SimError;
use ivt_ctrl::{AnyController, Config, ControlOutput};

/// What the closed loop calls; implemented by the in-process ivt-ctrl
/// controller (SIL, [`Sil`]) and by the QEMU firmware over a UART (PIL,
/// [`crate::pil::Pil`]).
pub trait ControllerBackend {
    /// One encoder pulse with its timer timestamp.
    fn on_pulse(&mut self, ticks: u32) -> Result<ControlOutput, SimError>;
    /// Slow readings V_m \[V\], T_U \[N·m\].
    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), SimError>;
}

/// Software in the loop: the `ivt-ctrl` controller in this process, for a
/// PPR chosen at run time (one of [`ivt_ctrl::SUPPORTED_PPR`]).
pub struct Sil(pub Box<AnyController>);

impl ControllerBackend for Sil {
    fn on_pulse(&mut self, ticks: u32) -> Result<ControlOutput, SimError> {
        Ok(self.0.on_pulse(ticks))
    }
    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), SimError> {
        self.0.update_inputs(v_m, t_u);
        Ok(())
    }
}

/// A boxed SIL backend for a run-time PPR.
///
/// # Errors
/// [`SimError::UnsupportedPpr`] if `ppr` is not in
/// [`ivt_ctrl::SUPPORTED_PPR`].
pub fn sil(ppr: usize, config: Config) -> Result<Box<dyn ControllerBackend>, SimError> {
    let c = AnyController::new(ppr, config).map_err(SimError::UnsupportedPpr)?;
    Ok(Box::new(Sil(Box::new(c))))
}
