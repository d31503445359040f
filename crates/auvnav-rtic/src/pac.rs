//! A minimal device module for QEMU's mps2-an386 (no PAC exists): what
//! `#[rtic::app(device = crate::pac)]` and cortex-m-rt's `device` feature
//! need, as svd2rust PACs provide it.

/// The interrupts the firmware uses (CMSDK timers 0 and 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u16)]
pub enum Interrupt {
    /// CMSDK APB timer 0, IRQ 8: the control task.
    TIMER0 = 8,
    /// CMSDK APB timer 1, IRQ 9: RTIC's dispatcher for software tasks.
    TIMER1 = 9,
}

pub use self::Interrupt as interrupt;

// SAFETY: the numbers are the board's IRQ numbers of these timers.
unsafe impl cortex_m::interrupt::InterruptNumber for Interrupt {
    fn number(self) -> u16 {
        self as u16
    }
}

/// Priority bits of the AN386's Cortex-M4 NVIC.
pub const NVIC_PRIO_BITS: u8 = 3;

/// A vector table entry.
pub union Vector {
    handler: unsafe extern "C" fn(),
    reserved: usize,
}

unsafe extern "C" {
    fn TIMER0();
    fn TIMER1();
}

/// The device's interrupt vectors 0..=9 (cortex-m-rt puts them after the
/// exceptions); unused ones reserved, the rest in `device.x`.
#[unsafe(link_section = ".vector_table.interrupts")]
#[unsafe(no_mangle)]
pub static __INTERRUPTS: [Vector; 10] = [
    Vector { reserved: 0 },
    Vector { reserved: 0 },
    Vector { reserved: 0 },
    Vector { reserved: 0 },
    Vector { reserved: 0 },
    Vector { reserved: 0 },
    Vector { reserved: 0 },
    Vector { reserved: 0 },
    Vector { handler: TIMER0 },
    Vector { handler: TIMER1 },
];
