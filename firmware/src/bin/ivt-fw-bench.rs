//! QEMU measurement image (not flashed anywhere): drives the pulse path with a
//! synthetic encoder stream so that `run-qemu.sh budgets` can count the
//! instructions of each `ivt_fw_pulse` call from QEMU's exec trace, measures
//! the stack of the pulse path by painting, and carries a deliberate panic
//! path (`ivt_fw_canary`) as the positive control of the panic-reachability
//! check.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use ivt_firmware::app::{ivt_fw_pulse, PPR};
use ivt_firmware::board::qemu;
use ivt_firmware::stack;

/// Pulses driven: two revolutions to fill the ring, then the measured ones.
const PULSES: u32 = 2 * PPR as u32 + 400;

/// Positive control for `scripts/panic_reach.py`: indexing with a run-time
/// index keeps a bounds check, whose failure path is the panic handler.
#[no_mangle]
#[inline(never)]
pub fn ivt_fw_canary(table: &[u32; 4], i: usize) -> u32 {
    table[i]
}

#[entry]
fn main() -> ! {
    let ctrl = qemu::boot();
    let table = [1, 2, 3, 4];
    let i = core::hint::black_box(2usize);
    let canary = ivt_fw_canary(&table, i);
    // Stack of start-up (controller construction), then of the pulse path alone.
    let stack_init = stack::high_water();
    stack::paint();
    // ~100 rpm of θ on a 1 MHz timer with a ±10 % ripple (integer pattern,
    // no trig in the image) and a load step half way.
    let mut t: u32 = 0xFFF0_0000;
    let mut faults = 0u32;
    for k in 0..PULSES {
        if k % 100 == 0 {
            let t_u = if k < PULSES / 2 { 4.0 } else { 7.5 };
            ctrl.update_inputs(8.0, t_u);
        }
        let ripple = (k % 50) as i32 - 25; // ±25 ticks of 500
        t = t.wrapping_add((500 + ripple) as u32);
        let out = ivt_fw_pulse(ctrl, t);
        faults += (out.fault != ivt_ctrl::Fault::None) as u32;
    }
    qemu::report(&[
        ("pulses", PULSES as usize),
        ("faults", faults as usize),
        ("canary", canary as usize),
        ("stack_init_bytes", stack_init),
        ("stack_high_water_bytes", stack::high_water()),
        ("static_ram_bytes", stack::static_bytes()),
    ]);
    qemu::exit(true)
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    qemu::exit(false)
}
