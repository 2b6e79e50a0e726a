//! STM32F411 rig image (placeholder while the board layer is written).
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use defmt_rtt as _;

#[entry]
fn main() -> ! {
    defmt::info!("ivt-fw-rig");
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {
        cortex_m::asm::udf();
    }
}
