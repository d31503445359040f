//! Links the firmware: copies `memory.x` and `device.x` to `OUT_DIR`, puts
//! it on the linker's search path and passes cortex-m-rt's `link.x` (which
//! includes both). Only for a `thumbv*` target.

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if !env::var("TARGET").unwrap_or_default().starts_with("thumbv") {
        return;
    }
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap_or_default());
    for f in ["memory.x", "device.x"] {
        println!("cargo:rerun-if-changed={f}");
        if let Err(e) = fs::copy(f, out.join(f)) {
            println!("cargo:warning=cannot copy {f} to OUT_DIR: {e}");
            return;
        }
    }
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg=-Tlink.x");
}
