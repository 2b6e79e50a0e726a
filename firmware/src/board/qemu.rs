//! QEMU `mps2-an386` board layer: CMSDK APB UART0 and semihosting.

use cortex_m_semihosting::{debug, hprintln};

/// CMSDK APB UART (ARM DDI 0479, §4.3): DATA, STATE, CTRL, INTSTATUS, BAUDDIV.
pub struct CmsdkUart {
    base: usize,
}

const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const BAUDDIV: usize = 0x10;
const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;

impl CmsdkUart {
    /// UART0 of the AN385/AN386 memory map.
    pub const UART0: usize = 0x4000_4000;
    /// UART1 of the AN385/AN386 memory map.
    pub const UART1: usize = 0x4000_5000;

    /// Enables TX and RX. QEMU refuses to move bytes while BAUDDIV < 16.
    pub fn new(base: usize) -> Self {
        let uart = Self { base };
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

    /// Blocks until a byte arrives.
    pub fn read_byte(&mut self) -> u8 {
        while self.read_reg(STATE) & STATE_RX_FULL == 0 {}
        self.read_reg(DATA) as u8
    }
}

/// Ends the QEMU run with a status (semihosting SYS_EXIT).
pub fn exit(ok: bool) -> ! {
    debug::exit(if ok { debug::EXIT_SUCCESS } else { debug::EXIT_FAILURE });
    loop {
        cortex_m::asm::wfi();
    }
}

/// Prints `key=value` lines on QEMU's stdout via semihosting (the host's
/// scripts parse them).
pub fn report(items: &[(&str, usize)]) {
    for (key, value) in items {
        hprintln!("{}={}", key, value);
    }
}

impl crate::app::Link for CmsdkUart {
    fn read_byte(&mut self) -> u8 {
        CmsdkUart::read_byte(self)
    }
    fn write_all(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_byte(b);
        }
    }
}
