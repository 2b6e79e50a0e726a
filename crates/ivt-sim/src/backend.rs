//! The controller as the closed loop sees it: software in the loop (the
//! in-process `ivt-ctrl` [`Controller`]) or, later, processor in the loop (the
//! QEMU firmware over a UART, `pil.rs`). The step generator runs inside the
//! backend; the simulator reads `stepper_target` and moves its own stepper
//! model (with rate limits and missed steps) towards it.

use ivt_ctrl::{Config, ControlOutput, Controller};

/// A backend failure (transport, protocol, a dead firmware...).
#[derive(Debug, thiserror::Error, Clone, PartialEq, Eq)]
pub enum BackendError {
    /// The requested encoder resolution has no compiled controller.
    #[error("no SIL controller compiled for PPR {0} (supported: {SUPPORTED_PPR:?})")]
    UnsupportedPpr(usize),
    /// The backend's link failed.
    #[error("controller backend I/O: {0}")]
    Io(String),
    /// The backend answered something that is not a valid reply.
    #[error("controller backend protocol: {0}")]
    Protocol(String),
}

/// What the closed loop calls; implemented by the in-process ivt-ctrl Controller (SIL)
/// and by the QEMU firmware over a UART (PIL, written by the `fw` helper in
/// crates/ivt-sim/src/pil.rs).
pub trait ControllerBackend {
    /// One encoder pulse with its timer timestamp.
    fn on_pulse(&mut self, ticks: u32) -> Result<ivt_ctrl::ControlOutput, BackendError>;
    /// Slow readings V_m \[V\], T_U \[N·m\].
    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), BackendError>;
}

/// Software in the loop: the `ivt-ctrl` controller in this process.
pub struct Sil<const PPR: usize>(pub Controller<PPR>);

impl<const PPR: usize> ControllerBackend for Sil<PPR> {
    fn on_pulse(&mut self, ticks: u32) -> Result<ControlOutput, BackendError> {
        Ok(self.0.on_pulse(ticks))
    }
    fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), BackendError> {
        self.0.update_inputs(v_m, t_u);
        Ok(())
    }
}

/// Controller resolutions (samples per revolution of θ) with a compiled SIL
/// controller; `Controller<PPR>` takes PPR as a const generic.
pub const SUPPORTED_PPR: [usize; 12] = [16, 32, 64, 100, 128, 256, 360, 500, 512, 1000, 1024, 1200];

/// A boxed SIL backend for a run-time PPR.
///
/// # Errors
/// [`BackendError::UnsupportedPpr`] if `ppr` is not in [`SUPPORTED_PPR`].
pub fn sil(ppr: usize, config: Config) -> Result<Box<dyn ControllerBackend>, BackendError> {
    macro_rules! pick {
        ($($n:literal),*) => {
            match ppr {
                $($n => Ok(Box::new(Sil::<$n>(Controller::<$n>::new(config)))),)*
                _ => Err(BackendError::UnsupportedPpr(ppr)),
            }
        };
    }
    pick!(16, 32, 64, 100, 128, 256, 360, 500, 512, 1000, 1024, 1200)
}
