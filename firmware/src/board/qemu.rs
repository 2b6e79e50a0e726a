//! QEMU `mps2-an386` board layer: CMSDK APB UART0 and semihosting.

use crate::app::{take_controller, Ctrl};
use crate::stack;
use cortex_m_semihosting::{debug, hprintln};
use ivt_ctrl::Config;

/// CMSDK APB UART (ARM DDI 0479, §4.3): DATA, STATE, CTRL, INTSTATUS, BAUDDIV.
pub struct CmsdkUart {
    base: usize,
    rx_irq: u16,
}

/// An external interrupt number of the board.
#[derive(Clone, Copy)]
struct Irq(u16);

// SAFETY: the numbers come from the AN385/AN386 interrupt map.
unsafe impl cortex_m::interrupt::InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const INTSTATUS: usize = 0x0C;
const BAUDDIV: usize = 0x10;
const CTRL_RX_INT: u32 = 1 << 3;
const INT_RX: u32 = 1 << 1;
const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;

impl CmsdkUart {
    /// UART0 of the AN385/AN386 memory map.
    pub const UART0: usize = 0x4000_4000;
    /// UART1 of the AN385/AN386 memory map.
    pub const UART1: usize = 0x4000_5000;

    /// Enables TX and RX. QEMU refuses to move bytes while BAUDDIV < 16.
    pub fn new(base: usize) -> Self {
        // RX interrupt numbers of UART0/UART1 in the AN385/AN386 map.
        let rx_irq = if base == Self::UART1 { 2 } else { 0 };
        let uart = Self { base, rx_irq };
        uart.write_reg(BAUDDIV, 16);
        uart.write_reg(CTRL, 0b11);
        uart
    }

    fn read_reg(&self, off: usize) -> u32 {
        // SAFETY: `base` is one of the UART blocks of the board's memory map.
        unsafe { core::ptr::read_volatile((self.base + off) as *const u32) }
    }

    fn write_reg(&self, off: usize, v: u32) {
        // SAFETY: as above.
        unsafe { core::ptr::write_volatile((self.base + off) as *mut u32, v) }
    }

    /// Blocks until the transmit buffer has room, then sends one byte.
    pub fn write_byte(&mut self, b: u8) {
        while self.read_reg(STATE) & STATE_TX_FULL != 0 {}
        self.write_reg(DATA, b as u32);
    }

    /// Blocks until a byte arrives, sleeping in WFI between bytes (see
    /// [`CmsdkUart::enable_rx_wakeup`]).
    pub fn read_byte(&mut self) -> u8 {
        while self.read_reg(STATE) & STATE_RX_FULL == 0 {
            cortex_m::asm::wfi();
        }
        let b = self.read_reg(DATA) as u8;
        self.write_reg(INTSTATUS, INT_RX);
        cortex_m::peripheral::NVIC::unpend(Irq(self.rx_irq));
        b
    }

    /// Lets a received byte wake the core from WFI: RX interrupt enabled in
    /// the UART and the NVIC, PRIMASK set so no handler runs. A guest that
    /// busy-polls the UART holds QEMU's I/O lock and starves the host link
    /// (≈ 3.5 ms per PIL round trip); sleeping lets the bytes in at once.
    pub fn enable_rx_wakeup(&mut self) {
        cortex_m::interrupt::disable();
        self.write_reg(CTRL, 0b11 | CTRL_RX_INT);
        // SAFETY: no handler runs (PRIMASK set); the IRQ only ends WFI.
        unsafe { cortex_m::peripheral::NVIC::unmask(Irq(self.rx_irq)) };
    }
}

/// Ends the QEMU run with a status (semihosting SYS_EXIT).
pub fn exit(ok: bool) -> ! {
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::wfi();
    }
}

/// Start of a QEMU image: paints the stack (for [`stack::high_water`]) and
/// takes the controller with the default configuration; exits QEMU with a
/// failure if it was taken already.
pub fn boot() -> &'static mut Ctrl {
    stack::paint();
    match take_controller(Config::default()) {
        Some(c) => c,
        None => exit(false),
    }
}

/// Prints `key=value` lines on QEMU's stdout via semihosting (the host's
/// scripts parse them).
pub fn report(items: &[(&str, usize)]) {
    for (key, value) in items {
        hprintln!("{}={}", key, value);
    }
}

impl crate::app::ByteSink for CmsdkUart {
    fn write_all(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_byte(b);
        }
    }
}

impl crate::app::Link for CmsdkUart {
    fn read_byte(&mut self) -> u8 {
        CmsdkUart::read_byte(self)
    }
}
