//! The controller's entry points as `extern "C"` symbols, with a panic
//! handler that calls an undefined function: linking them with
//! `--gc-sections` fails if any panic path is reachable from them.
#![no_std]
#![allow(improper_ctypes_definitions)]

use ivt_ctrl::{Config, Controller, Plan, Selection, Sequencer};

/// The controller type the firmware runs for the thesis's 1200-line encoder.
pub type Ctrl = Controller<1200>;

/// `Controller::new` (config validation, stepper set-up with `sqrtf`).
#[no_mangle]
pub extern "C" fn ivt_check_new(c: &mut Ctrl, f_timer_hz: f32, omega0: f32, k: f32, k2: f32) {
    let mut cfg = Config {
        f_timer_hz,
        omega0,
        ..Config::default()
    };
    cfg.gains.k = k;
    cfg.gains.k2 = k2;
    *c = Controller::new(cfg);
}

/// The pulse path.
#[no_mangle]
pub extern "C" fn ivt_check_on_pulse(c: &mut Ctrl, ticks: u32) -> f32 {
    c.on_pulse(ticks).r
}

/// The slow input path (open-loop polynomial).
#[no_mangle]
pub extern "C" fn ivt_check_update_inputs(c: &mut Ctrl, v_m: f32, t_u: f32) {
    c.update_inputs(v_m, t_u);
}

/// The step generator.
#[no_mangle]
pub extern "C" fn ivt_check_step_tick(c: &mut Ctrl, now: u32) -> bool {
    c.step_tick(now).step
}

/// A commissioning pulse (`commission::Sequencer::on_pulse`: stage logic
/// with the plan's f32 → tick conversions, then the pulse path).
#[no_mangle]
pub extern "C" fn ivt_check_sequence_pulse(s: &mut Sequencer, c: &mut Ctrl, ticks: u32) -> f32 {
    s.on_pulse(c, ticks).out.r
}

/// A sequencer for any selection (`Sequencer::new`, the plan's stage table).
#[no_mangle]
pub extern "C" fn ivt_check_sequence_new(
    s: &mut Sequencer,
    sel: u8,
    f_timer_hz: f32,
    r_max: f32,
) -> f32 {
    *s = Sequencer::new(Plan::default(), Selection(sel), f_timer_hz);
    s.plan().duration_s(Selection(sel), r_max)
}

/// Self-test of the check: an out-of-bounds index must be detected.
#[cfg(feature = "canary")]
#[no_mangle]
pub extern "C" fn ivt_check_canary(xs: &[u32; 4], i: usize) -> u32 {
    xs[i]
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    extern "C" {
        fn ivt_ctrl_panic_path_reached() -> !;
    }
    // SAFETY: never defined; referencing it makes any reachable panic a link error.
    unsafe { ivt_ctrl_panic_path_reached() }
}
