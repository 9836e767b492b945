//! Stack high-water mark: paint the free stack with a pattern at boot, find the deepest
//! overwritten word later.

use core::ptr::{addr_of, read_volatile, write_volatile};

const PATTERN: u32 = 0xDEAD_BEEF;

extern "C" {
    /// End of static data (start of the free RAM), from cortex-m-rt's link.x.
    static __sheap: u32;
    /// Top of the stack, from cortex-m-rt's link.x.
    static _stack_start: u32;
}

fn bottom() -> usize {
    addr_of!(__sheap) as usize
}

fn top() -> usize {
    addr_of!(_stack_start) as usize
}

/// Paints from the end of static data up to 256 bytes below the current stack pointer.
/// Call first thing in `main`.
pub fn paint() {
    let sp = cortex_m::register::msp::read() as usize;
    let mut a = (bottom() + 3) & !3;
    while a + 256 < sp {
        // SAFETY: free RAM between static data and the live stack.
        unsafe { write_volatile(a as *mut u32, PATTERN) };
        a += 4;
    }
}

/// Bytes of stack used at most since [`paint`].
pub fn high_water() -> usize {
    let mut a = (bottom() + 3) & !3;
    let t = top();
    // SAFETY: reads of RAM between static data and the stack top.
    while a < t && unsafe { read_volatile(a as *const u32) } == PATTERN {
        a += 4;
    }
    t - a
}
