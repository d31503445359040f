//! Support for auvnav's on-target tests, examples and benchmarks under QEMU
//! (see `BENCHMARKS.md` and `tools/qemu/README.md`).
//!
//! The library itself forbids `unsafe`, and so do its tests and examples
//! (the package's `[lints]`). The few things bare-metal test firmware needs
//! that cannot be written without it live here, in a separate crate that is
//! only a target dev-dependency, never a dependency of the library:
//!
//! - [`exit`]: the QEMU process's exit status, through semihosting;
//! - a `HardFault` handler that prints the faulting PC and exits non-zero
//!   (the default one loops forever, hanging QEMU until a timeout);
//! - [`bench::start`] / [`bench::stop`]: the marker functions between which
//!   the QEMU plugin `tools/qemu/insn_count.c` counts executed instructions;
//! - [`stack`]: stack painting and high-water marks;
//! - [`image`]: the linked image's section sizes, from the linker symbols.
//!
//! Everything here is panic-free, so the `panic-never` example can use it.
#![no_std]

use cortex_m_rt::{ExceptionFrame, exception};
use cortex_m_semihosting::{debug, hio};

/// Ends the QEMU run with exit status 0 (`ok`) or 1.
pub fn exit(ok: bool) -> ! {
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    // Only reached when no debugger/QEMU honours the exit request.
    loop {
        cortex_m::asm::bkpt();
    }
}

/// Writes `s` to the host's stdout (semihosting), ignoring errors.
pub fn print(s: &str) {
    if let Ok(mut out) = hio::hstdout() {
        let _ = out.write_all(s.as_bytes());
    }
}

/// Writes `s` to the host's stderr (semihosting), ignoring errors.
pub fn eprint(s: &str) {
    if let Ok(mut out) = hio::hstderr() {
        let _ = out.write_all(s.as_bytes());
    }
}

/// Writes `v` in decimal to the host's stdout, without `core::fmt`.
pub fn print_u32(v: u32) {
    let mut buf = [0_u8; 10];
    let mut i = buf.len();
    let mut v = v;
    loop {
        i -= 1;
        buf[i] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 || i == 0 {
            break;
        }
    }
    if let Ok(mut out) = hio::hstdout() {
        let _ = out.write_all(buf.get(i..).unwrap_or(&[]));
    }
}

#[exception]
unsafe fn HardFault(ef: &ExceptionFrame) -> ! {
    // To stderr: stdout may be a defmt stream.
    eprint("HardFault at pc 0x");
    let pc = ef.pc();
    let mut hex = [0_u8; 8];
    for (k, h) in hex.iter_mut().enumerate() {
        let nibble = (pc >> (28 - 4 * k as u32)) & 0xf;
        *h = b"0123456789abcdef"[nibble as usize];
    }
    if let Ok(s) = core::str::from_utf8(&hex) {
        eprint(s);
    }
    eprint("\n");
    exit(false)
}

/// Instruction-count markers for `tools/qemu/insn_count.c`.
///
/// The plugin finds the two functions by their symbol names in the ELF
/// QEMU loaded; every instruction executed from the entry of
/// `auvnav_bench_start` to the entry of `auvnav_bench_stop` is counted, and
/// printed as a line `QEMU-BENCH <count>` on QEMU's stdout when the stop
/// marker runs. The marker bodies differ, so LLVM can neither merge nor
/// drop them. Subtract the count of an empty measurement (the markers' own
/// call overhead, a few instructions).
pub mod bench {
    /// Start counting.
    #[unsafe(no_mangle)]
    #[inline(never)]
    pub extern "C" fn auvnav_bench_start() {
        // SAFETY: a register-neutral instruction sequence.
        unsafe {
            core::arch::asm!(
                "nop",
                "mov r12, r12",
                options(nomem, nostack, preserves_flags)
            )
        }
    }

    /// Stop counting and print the count.
    #[unsafe(no_mangle)]
    #[inline(never)]
    pub extern "C" fn auvnav_bench_stop() {
        // SAFETY: a register-neutral instruction sequence.
        unsafe {
            core::arch::asm!(
                "mov r12, r12",
                "nop",
                options(nomem, nostack, preserves_flags)
            )
        }
    }

    /// Starts a measurement.
    #[inline(always)]
    pub fn start() {
        auvnav_bench_start();
    }

    /// Ends a measurement.
    #[inline(always)]
    pub fn stop() {
        auvnav_bench_stop();
    }
}

unsafe extern "C" {
    static _stack_start: u32;
    static _stack_end: u32;
    static __stext: u32;
    static __etext: u32;
    static __srodata: u32;
    static __erodata: u32;
    static __sdata: u32;
    static __edata: u32;
    static __sbss: u32;
    static __ebss: u32;
    static __suninit: u32;
    static __euninit: u32;
}

fn addr(p: *const u32) -> usize {
    p as usize
}

/// Stack painting and high-water marks (the stack grows down from
/// `_stack_start`, the top of RAM, towards `_stack_end`, the end of the
/// statics).
pub mod stack {
    use super::addr;

    /// The pattern: cortex-m-rt's `paint-stack` value.
    pub const PAINT: u32 = 0xcccc_cccc;

    fn bottom() -> usize {
        addr(&raw const super::_stack_end)
    }

    fn top() -> usize {
        addr(&raw const super::_stack_start)
    }

    /// The current stack pointer.
    #[inline(always)]
    pub fn sp() -> usize {
        cortex_m::register::msp::read() as usize
    }

    /// Paints the free stack below the current stack pointer (less a
    /// 64-byte guard) and returns that stack pointer: measure with
    /// [`used_below`].
    #[inline(never)]
    pub fn repaint() -> usize {
        let here = sp();
        let end = here.saturating_sub(64) & !3;
        let mut a = bottom();
        while a < end {
            // SAFETY: the words between the end of the statics and the
            // stack pointer are free stack, owned by nobody.
            unsafe { core::ptr::write_volatile(a as *mut u32, PAINT) };
            a += 4;
        }
        here
    }

    /// Lowest address whose paint was scrubbed, scanning up from the
    /// bottom of the stack.
    fn lowest_used() -> usize {
        let mut a = bottom();
        let t = top();
        while a < t {
            // SAFETY: an aligned word of RAM between the statics and the
            // top of the stack.
            if unsafe { core::ptr::read_volatile(a as *const u32) } != PAINT {
                break;
            }
            a += 4;
        }
        a
    }

    /// Bytes of stack used below `base` (from [`repaint`]) since it was
    /// painted.
    pub fn used_below(base: usize) -> usize {
        base.saturating_sub(lowest_used())
    }

    /// Bytes of stack used since reset, when cortex-m-rt's `paint-stack`
    /// feature painted the whole stack (and [`repaint`] was not called).
    pub fn high_water() -> usize {
        top().saturating_sub(lowest_used())
    }
}

/// Section sizes of the linked image, in bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sizes {
    /// `.vector_table` and anything before `.text` in flash.
    pub vectors: usize,
    /// `.text`, code.
    pub text: usize,
    /// `.rodata`, constants.
    pub rodata: usize,
    /// `.data`, initialized statics (in RAM, with a copy in flash).
    pub data: usize,
    /// `.bss`, zeroed statics.
    pub bss: usize,
    /// `.uninit`.
    pub uninit: usize,
}

/// The image's section sizes, from cortex-m-rt's linker symbols.
pub mod image {
    use super::{Sizes, addr};

    /// The sizes of the running image.
    pub fn sizes() -> Sizes {
        let d = |a: *const u32, b: *const u32| addr(b).saturating_sub(addr(a));
        Sizes {
            vectors: addr(&raw const super::__stext),
            text: d(&raw const super::__stext, &raw const super::__etext),
            rodata: d(&raw const super::__srodata, &raw const super::__erodata),
            data: d(&raw const super::__sdata, &raw const super::__edata),
            bss: d(&raw const super::__sbss, &raw const super::__ebss),
            uninit: d(&raw const super::__suninit, &raw const super::__euninit),
        }
    }
}

/// The CMSDK APB timer 0 of QEMU's `mps2-an386` (base `0x4000_0000`,
/// interrupt 8, clocked at the board's 25 MHz system clock) and a handler
/// for its interrupt: what the real-time example (`examples/qemu_realtime.rs`)
/// needs without `unsafe` of its own.
pub mod timer {
    use core::cell::Cell;
    use core::ptr::{read_volatile, write_volatile};

    use cortex_m::interrupt::Mutex;
    use cortex_m_rt::exception;

    const BASE: usize = 0x4000_0000;
    const CTRL: usize = BASE;
    const VALUE: usize = BASE + 4;
    const RELOAD: usize = BASE + 8;
    const INTSTATUS: usize = BASE + 12;
    /// The timer's interrupt number.
    pub const IRQ: u16 = 8;
    /// The timer's input clock, Hz (the mps2 boards' `SYSCLK_FRQ`).
    pub const CLOCK_HZ: u32 = 25_000_000;

    /// The handler the timer's interrupt calls, once one is installed.
    type Slot = Mutex<Cell<Option<fn()>>>;
    static HANDLER: Slot = Mutex::new(Cell::new(None));

    #[derive(Clone, Copy)]
    struct Irq;
    // SAFETY: the timer's interrupt number on this board.
    unsafe impl cortex_m::interrupt::InterruptNumber for Irq {
        fn number(self) -> u16 {
            IRQ
        }
    }

    fn read(addr: usize) -> u32 {
        // SAFETY: a register of the timer, always mapped on the board.
        unsafe { read_volatile(addr as *const u32) }
    }

    fn write(addr: usize, v: u32) {
        // SAFETY: as `read`.
        unsafe { write_volatile(addr as *mut u32, v) }
    }

    /// Starts the timer with an interrupt every `reload + 1` clock ticks,
    /// calling `handler` (at the priority `prio`, 0 the highest).
    pub fn start(reload: u32, prio: u8, handler: fn()) {
        cortex_m::interrupt::free(|cs| HANDLER.borrow(cs).set(Some(handler)));
        write(CTRL, 0);
        write(RELOAD, reload);
        write(VALUE, reload);
        write(INTSTATUS, 1);
        if let Some(mut p) = cortex_m::Peripherals::take() {
            // SAFETY: the priority of an interrupt nothing else uses.
            unsafe {
                p.NVIC.set_priority(Irq, prio);
                cortex_m::peripheral::NVIC::unmask(Irq);
            }
        }
        // Enable, interrupt enable.
        write(CTRL, 1 | 8);
    }

    /// Stops the timer.
    pub fn stop() {
        write(CTRL, 0);
        cortex_m::peripheral::NVIC::mask(Irq);
    }

    /// The counter (counts down from the reload value).
    pub fn value() -> u32 {
        read(VALUE)
    }

    /// The reload value.
    pub fn reload() -> u32 {
        read(RELOAD)
    }

    /// Whether the interrupt is pending at the timer (a period ended).
    pub fn pending() -> bool {
        read(INTSTATUS) & 1 != 0
    }

    /// Clears the timer's interrupt.
    pub fn clear() {
        write(INTSTATUS, 1);
    }

    #[exception]
    unsafe fn DefaultHandler(irqn: i16) {
        let h = cortex_m::interrupt::free(|cs| HANDLER.borrow(cs).get());
        match h {
            Some(f) if irqn == IRQ as i16 => f(),
            _ => crate::exit(false),
        }
    }
}
