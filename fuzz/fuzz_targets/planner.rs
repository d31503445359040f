//! Fuzz target `planner`: see `auvnav_fuzz::planner` (fuzz/src/planner.rs) for the
//! input and what is checked.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = auvnav_fuzz::planner::run(data);
});
