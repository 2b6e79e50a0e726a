//! QEMU mps2-an386 image: the processor-in-the-loop server on UART0 (protocol
//! in `ivt_wire::msg`), telemetry frames on UART1 (a v2 sample every pulse;
//! stage starts and logged edges while a commissioning sequence runs). Exits QEMU
//! with status 0 on the host's `Exit` request and prints the measured stack
//! high-water mark via semihosting.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use ivt_firmware::app::{PilServer, Session, TelemetryTx};
use ivt_firmware::board::qemu::{self, CmsdkUart};
use ivt_firmware::stack;

#[entry]
fn main() -> ! {
    let ctrl = qemu::boot();
    let mut pil = CmsdkUart::new(CmsdkUart::UART0);
    pil.enable_rx_wakeup();
    let mut telemetry = TelemetryTx::new(CmsdkUart::new(CmsdkUart::UART1));
    let mut server = PilServer::new();
    loop {
        let byte = pil.read_byte();
        let session = server.feed(byte, ctrl, &mut pil, |ev| {
            if let Some(stage) = &ev.started {
                telemetry.stage(stage, ev.ticks);
            }
            if ev.pulse_log {
                telemetry.log_pulse(ev.ticks);
            }
            // PIL has no stepper (the simulator models it): the commanded
            // target stands in for the position.
            telemetry.sample(ev.ticks, &ev.out, ev.inputs, ev.out.stepper_target);
        });
        if session == Session::Exit {
            telemetry.flush_pulses();
            qemu::report(&[
                ("pulses", server.pulses as usize),
                ("telemetry_frames", telemetry.frames as usize),
                ("stack_high_water_bytes", stack::high_water()),
                ("static_ram_bytes", stack::static_bytes()),
            ]);
            qemu::exit(true);
        }
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    qemu::exit(false)
}
