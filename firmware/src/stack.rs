//! Stack painting: fill the free RAM between the end of the statics and the
//! stack pointer with a pattern at start-up, later find the deepest word the
//! stack overwrote. Gives the measured worst-case stack of everything that ran.

const PAINT: u32 = 0x5AA5_C33C;

extern "C" {
    // cortex-m-rt's link.x: end of .bss/.uninit and the initial stack pointer.
    static mut __sheap: u32;
    static _stack_start: u32;
}

fn bounds() -> (usize, usize) {
    // Only the addresses of the linker symbols are taken.
    (
        core::ptr::addr_of!(__sheap) as usize,
        core::ptr::addr_of!(_stack_start) as usize,
    )
}

/// Paints from the end of the statics up to 256 bytes below the current stack
/// pointer (the margin covers this function's own frame).
#[inline(never)]
pub fn paint() {
    let (lo, _) = bounds();
    let sp = cortex_m::register::msp::read() as usize;
    let mut p = lo;
    while p + 4 <= sp.saturating_sub(256) {
        // SAFETY: [lo, sp - 256) is RAM above the statics that no live data uses.
        unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
}

/// Deepest stack use so far in bytes (top of stack minus the lowest
/// overwritten painted word).
pub fn high_water() -> usize {
    let (lo, top) = bounds();
    let mut p = lo;
    // SAFETY: reads of RAM between the statics and the stack top.
    while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
        p += 4;
    }
    top - p
}

/// Bytes of RAM used by statics (.data + .bss + .uninit).
pub fn static_bytes() -> usize {
    let (lo, _) = bounds();
    lo - 0x2000_0000
}
