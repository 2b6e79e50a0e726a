//! QEMU image: hello world for now.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use ivt_firmware::board::qemu;

#[entry]
fn main() -> ! {
    qemu::log("ivt-fw-qemu: hello");
    let mut uart = qemu::CmsdkUart::new(qemu::CmsdkUart::UART0);
    for b in b"uart0 hello\n" {
        uart.write_byte(*b);
    }
    qemu::exit(true)
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    qemu::exit(false)
}
