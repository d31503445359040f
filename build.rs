//! Links the on-target (Cortex-M, QEMU) examples and tests, and nothing
//! else: for a `thumbv*` target it copies `memory.x` and the QEMU machine's
//! memory map to `OUT_DIR` and passes them, with cortex-m-rt's and defmt's
//! linker scripts, to the **examples and tests only**
//! (`rustc-link-arg-examples` / `-tests`, which never reach the library or
//! a downstream crate). For any other target it does nothing. No
//! build-dependencies.
//!
//! `memory.x` includes `qemu-memory.x`, written here: QEMU's mps2-an386 /
//! mps2-an500 map (`tools/qemu/mps2.x`, 4 MiB code SRAM, 4 MiB SRAM) for
//! `thumbv7em-*`, the lm3s6965evb's (`tools/qemu/lm3s6965evb.x`, 256 KiB
//! flash, 64 KiB SRAM) for `thumbv7m-*`. (The linker finds the package's
//! own `memory.x` in its working directory before any `-L` path, so the
//! per-target choice has to happen one include further down.)

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    // Set by tools/qemu/panic_sites.sh to swap panic-never for a handler.
    println!("cargo::rustc-check-cfg=cfg(auvnav_panic_probe)");
    let target = env::var("TARGET").unwrap_or_default();
    // A dependent builds the packaged library, which ships neither the
    // memory map nor the examples that link with it: nothing to do.
    if !target.starts_with("thumbv") || !std::path::Path::new("memory.x").exists() {
        return;
    }
    let map = if target.starts_with("thumbv7m-") {
        "tools/qemu/lm3s6965evb.x"
    } else {
        "tools/qemu/mps2.x"
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap_or_default());
    for (from, to) in [("memory.x", "memory.x"), (map, "qemu-memory.x")] {
        println!("cargo:rerun-if-changed={from}");
        if let Err(e) = fs::copy(from, out.join(to)) {
            println!("cargo:warning=cannot copy {from} to OUT_DIR: {e}");
            return;
        }
    }
    for kind in ["examples", "tests"] {
        println!("cargo:rustc-link-arg-{kind}=-L{}", out.display());
        println!("cargo:rustc-link-arg-{kind}=-Tlink.x");
        println!("cargo:rustc-link-arg-{kind}=-Tdefmt.x");
    }
}
