//! The C interface of `auvnav` (spec/capi.md): `libauvnav_c.a` plus
//! `include/auvnav.h`, generated from this crate by cbindgen.
//!
//! Everything the C caller can get wrong is an error code, never undefined
//! behaviour inside the library and never a trap: null pointers, lengths
//! over a capacity, non-finite values, invalid settings, an object used
//! before its `*_init`. The `unsafe` of this crate is the pointer handling
//! of [`ffi`] (each block with its `// SAFETY:` reason); the planning is
//! the library's safe code ([`planner`], [`autopilot`]), whose crate
//! forbids `unsafe`.
//!
//! **Panics.** On a bare-metal target (`target_os = "none"`) the library
//! is `no_std` and has no reachable panic (the core's lints, and the
//! link-time proof of scripts/c-test.sh). Rust still requires a panic
//! handler in a static library: this one calls `void auvnav_panic(void)`,
//! which the firmware defines (the panic hook, README "From C"). A
//! firmware image that does not define it links only if no panic path
//! survived optimization: that is the proof. On the host the library
//! links `std` (its panic handler; a panic cannot unwind out of an
//! `extern "C"` function, it aborts).
#![cfg_attr(target_os = "none", no_std)]

mod autopilot;
mod convert;
pub mod error;
pub mod ffi;
mod planner;
pub mod types;

#[cfg(target_os = "none")]
mod hook {
    unsafe extern "C" {
        /// Defined by the firmware: what to do on a panic (never returns).
        fn auvnav_panic() -> !;
    }

    #[panic_handler]
    fn panic(_: &core::panic::PanicInfo) -> ! {
        // SAFETY: `auvnav_panic` takes no arguments and does not return;
        // the firmware defines it (README "From C").
        unsafe { auvnav_panic() }
    }
}
