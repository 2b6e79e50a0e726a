//! The encoder resolution chosen at run time.
//!
//! [`Controller`] takes the samples per revolution of θ (PPR) as a const
//! generic, so its timestamp ring is a fixed array (no heap, Eq. 180's
//! one-revolution delay is `PPR` pulses). Hosts that read PPR from a scene, a
//! command line or Python pick one of the compiled resolutions with
//! [`AnyController::new`]; [`SUPPORTED_PPR`] is the one list of them, used by
//! the simulator, the CLI, the Python bindings and (by a compile-time check)
//! the firmware.

use crate::commission::{SequenceStep, Sequencer};
use crate::controller::{Config, ControlOutput, Controller, StepTick};

macro_rules! any_controller {
    ($($ppr:literal => $var:ident),* $(,)?) => {
        /// Encoder resolutions (samples per revolution of θ) with a compiled
        /// controller, ascending.
        pub const SUPPORTED_PPR: &[usize] = &[$($ppr),*];

        /// A [`Controller`] for one of the [`SUPPORTED_PPR`] values, chosen
        /// at run time. Held inline (no heap): its size is that of the
        /// largest controller (box it where that matters).
        #[derive(Clone)]
        #[allow(clippy::large_enum_variant)] // no_std, no allocator: variants stay inline
        pub enum AnyController {
            $(
                #[doc = concat!("`Controller<", stringify!($ppr), ">`.")]
                $var(Controller<$ppr>),
            )*
        }

        impl AnyController {
            /// A controller for `ppr` and `config` ([`Controller::new`]:
            /// an invalid config gives the `Fault::Config` safe state).
            ///
            /// # Errors
            /// [`UnsupportedPpr`] if `ppr` is not in [`SUPPORTED_PPR`].
            pub fn new(ppr: usize, config: Config) -> Result<Self, UnsupportedPpr> {
                match ppr {
                    $($ppr => Ok(Self::$var(Controller::new(config))),)*
                    _ => Err(UnsupportedPpr(ppr)),
                }
            }

            /// The resolution this controller was built for.
            #[must_use]
            pub fn ppr(&self) -> usize {
                match self { $(Self::$var(_) => $ppr),* }
            }

            /// [`Controller::on_pulse`].
            pub fn on_pulse(&mut self, ticks: u32) -> ControlOutput {
                match self { $(Self::$var(c) => c.on_pulse(ticks)),* }
            }

            /// [`Controller::update_inputs`].
            pub fn update_inputs(&mut self, v_m: f32, t_u: f32) {
                match self { $(Self::$var(c) => c.update_inputs(v_m, t_u)),* }
            }

            /// [`Controller::step_tick`].
            pub fn step_tick(&mut self, now: u32) -> StepTick {
                match self { $(Self::$var(c) => c.step_tick(now)),* }
            }

            /// [`Controller::reset`].
            pub fn reset(&mut self, config: Config) {
                match self { $(Self::$var(c) => c.reset(config)),* }
            }

            /// [`Controller::output`].
            #[must_use]
            pub fn output(&self) -> ControlOutput {
                match self { $(Self::$var(c) => c.output()),* }
            }

            /// [`Sequencer::on_pulse`] on this controller.
            pub fn sequence_pulse(&mut self, seq: &mut Sequencer, ticks: u32) -> SequenceStep {
                match self { $(Self::$var(c) => seq.on_pulse(c, ticks)),* }
            }

            /// [`Controller::r_max`].
            #[must_use]
            pub fn r_max(&self) -> f32 {
                match self { $(Self::$var(c) => c.r_max()),* }
            }
        }
    };
}

any_controller!(
    16 => P16, 32 => P32, 64 => P64, 80 => P80, 100 => P100, 128 => P128, 200 => P200,
    256 => P256, 360 => P360, 400 => P400, 500 => P500, 512 => P512, 1000 => P1000,
    1024 => P1024, 1200 => P1200, 2000 => P2000, 2048 => P2048, 2400 => P2400, 4096 => P4096,
);

/// A resolution with no compiled controller.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnsupportedPpr(pub usize);

impl core::fmt::Display for UnsupportedPpr {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "no controller compiled for PPR {} (supported: {SUPPORTED_PPR:?})",
            self.0
        )
    }
}

/// True if `ppr` is in [`SUPPORTED_PPR`]; `const`, so a firmware build can
/// check its fixed resolution at compile time.
#[must_use]
pub const fn is_supported_ppr(ppr: usize) -> bool {
    let mut rest = SUPPORTED_PPR;
    while let [first, tail @ ..] = rest {
        if *first == ppr {
            return true;
        }
        rest = tail;
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_supported_ppr_builds_its_own_controller() {
        for &ppr in SUPPORTED_PPR {
            let c = AnyController::new(ppr, Config::default()).unwrap();
            assert_eq!(c.ppr(), ppr);
            assert!(is_supported_ppr(ppr));
        }
        assert!(SUPPORTED_PPR.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn unsupported_ppr_is_an_error_naming_it() {
        assert_eq!(
            AnyController::new(7, Config::default()).err(),
            Some(UnsupportedPpr(7))
        );
        assert!(!is_supported_ppr(7));
    }

    #[test]
    fn dispatch_gives_the_same_outputs_as_the_generic_controller() {
        let mut any = AnyController::new(100, Config::default()).unwrap();
        let mut c = Controller::<100>::new(Config::default());
        for k in 0..300u32 {
            let ticks = k * 5_000;
            assert_eq!(any.on_pulse(ticks), c.on_pulse(ticks));
        }
        any.update_inputs(8.0, 3.0);
        c.update_inputs(8.0, 3.0);
        assert_eq!(any.output(), c.output());
        assert_eq!(any.step_tick(1_600_000), c.step_tick(1_600_000));
    }
}
