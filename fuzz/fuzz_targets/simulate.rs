//! Fuzz target `simulate`: see `auvnav_fuzz::simulate` (fuzz/src/simulate.rs) for the
//! input and what is checked.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = auvnav_fuzz::simulate::run(data);
});
