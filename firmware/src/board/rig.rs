//! STM32F411CE rig board (e.g. WeAct "Black Pill", 25 MHz HSE, SYSCLK 100 MHz).
//! Pins, timers and scaling are constants here; the wiring table is in the
//! guide, docs/guide/src/rig/firmware.md.

use ivt_ctrl::{Config, REFIT};

/// SYSCLK \[Hz\].
pub const SYSCLK_HZ: u32 = 100_000_000;
/// TIM2 (32-bit) counts at this rate; its CH1 input capture timestamps the
/// encoder edges, so it is the controller's `f_timer_hz`. 10 MHz: 0.1 µs
/// resolution, wraps every 429 s (the controller's wrapping arithmetic
/// handles it).
pub const F_TIMER_HZ: u32 = 10_000_000;
/// TIM3 update rate that runs the step generator \[Hz\]. A step pulse is
/// high for one tick, so the fastest step rate is half of this.
pub const STEP_TICK_HZ: u32 = 50_000;
/// Period of the ADC reading / `update_inputs` loop \[ms\].
pub const INPUT_PERIOD_MS: u32 = 1;
/// A telemetry frame every this many input periods (100 Hz).
pub const TELEMETRY_EVERY: u32 = 10;
/// USART1 telemetry baud rate.
pub const TELEMETRY_BAUD: u32 = 921_600;

/// Linear ADC scaling: `value = counts · gain + offset` (12-bit ADC, 3.3 V
/// reference).
#[derive(Clone, Copy, Debug)]
pub struct AdcScale {
    /// Units per ADC count.
    pub gain: f32,
    /// Value at zero counts.
    pub offset: f32,
}

impl AdcScale {
    /// Converts a raw 12-bit reading.
    pub fn apply(&self, counts: u16) -> f32 {
        counts as f32 * self.gain + self.offset
    }
}

/// V_m through a 10 kΩ / 1 kΩ divider (÷11): 0–36.3 V full scale.
pub const V_M_SCALE: AdcScale = AdcScale {
    gain: 3.3 / 4095.0 * 11.0,
    offset: 0.0,
};

/// T_U from a torque transducer amplifier with 0–3.3 V ↔ 0–20 N·m.
pub const T_U_SCALE: AdcScale = AdcScale {
    gain: 20.0 / 4095.0,
    offset: 0.0,
};

/// The controller configuration of the rig image: the library defaults
/// (thesis setup) on this board's timer, with the open-loop law refitted on
/// the printed plant (`REFIT`, also the library default; named here so that
/// the flashed law is visible in the board file — SPEC §5).
pub fn config() -> Config {
    Config {
        f_timer_hz: F_TIMER_HZ as f32,
        open_loop: REFIT,
        ..Config::default()
    }
}
