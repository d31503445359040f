//! Shared by the on-target tests `tests/qemu_*.rs` (Cortex-M under QEMU,
//! defmt-test harness) and by their host-side `main`s.
//!
//! - `monterey`: the paper's line as consts, generated (with
//!   `fixtures.rs`, the golden fixtures, included by
//!   `tests/qemu_fixtures.rs` only) by `python3 tools/qemu/make_fixtures.py`;
//! - `paper`: the paper's scenario, planned the same way everywhere;
//! - `expected`: the host's plans of the paper's line, bit for bit
//!   (`tests/qemu_plan.rs` explains how they are refreshed);
//! - `say!` / `check!`: log and assert through defmt on the target, through
//!   `println!` / `assert!` on the host, so the same checking code runs on
//!   both (format strings use plain `{}` only, which both accept);
//! - on the target: the defmt logger (semihosting), and panic handlers that
//!   exit QEMU with status 1.
#![allow(dead_code, unused_macros, unused_imports)]

macro_rules! say {
    ($($arg:tt)+) => {{
        #[cfg(target_os = "none")]
        { defmt::println!($($arg)+); }
        #[cfg(not(target_os = "none"))]
        { println!($($arg)+); }
    }};
}

macro_rules! check {
    ($cond:expr, $($arg:tt)+) => {{
        #[cfg(target_os = "none")]
        { defmt::assert!($cond, $($arg)+); }
        #[cfg(not(target_os = "none"))]
        { assert!($cond, $($arg)+); }
    }};
}

/// Fails the test with `what` when `r` is an error.
macro_rules! ok {
    ($r:expr, $($arg:tt)+) => {
        match $r {
            Ok(v) => v,
            Err(_) => {
                #[cfg(target_os = "none")]
                { defmt::panic!($($arg)+) }
                #[cfg(not(target_os = "none"))]
                { panic!($($arg)+) }
            }
        }
    };
}

pub mod compare;
#[rustfmt::skip] // generated
pub mod expected;
#[rustfmt::skip] // generated
pub mod monterey;
pub mod paper;

/// `|got - want| / |want|`, as the host's `common::rel_err`.
pub fn rel_err(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs().max(f64::MIN_POSITIVE)
}

#[cfg(target_os = "none")]
mod target {
    use cortex_m as _; // critical section for the defmt logger
    use cortex_m_rt as _; // reset handler, vector table
    use defmt_semihosting as _; // defmt frames to semihosting stdout

    use auvnav_qemu as _; // HardFault handler that exits non-zero

    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo) -> ! {
        defmt::error!("{}", defmt::Display2Format(info));
        auvnav_qemu::exit(false)
    }

    #[defmt::panic_handler]
    fn defmt_panic() -> ! {
        auvnav_qemu::exit(false)
    }
}
