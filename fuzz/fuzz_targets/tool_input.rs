//! Fuzz target `tool_input`: see `auvnav_fuzz::tool` (fuzz/src/tool.rs) for the
//! input and what is checked.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = auvnav_fuzz::tool::run(data);
});
