//! The planner's progress on the target, as a defmt log decoded on the
//! host: the paper's line `us_monterey_canyon_1` (C-AUV #4, `h_r = 80 m`,
//! `h_a = 60 m`) planned track-wise (`Planner::<1>`, the paper's method,
//! a few seconds in QEMU), printing for every track the optimizer's objective
//! at each iteration (`Plan::history`), then the track's outcome: depth,
//! status, safety, minimum altitude, J, iterations and evaluations. (The
//! receding horizon's cold first call is by far the costliest solve, see
//! BENCHMARKS.md; `tests/qemu_plan.rs` runs it.)
//!
//! ```sh
//! cargo qemu-log                   # Cortex-M4F under QEMU, decoded by defmt-print
//! DEFMT_LOG=debug cargo qemu-log   # plus the library's own debug logs, if any
//! ```
//!
//! (`cargo qemu-log` builds with the library's `defmt` feature; the
//! firmware's own lines use `defmt::println!`, shown at any `DEFMT_LOG`.)
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(not(target_os = "none"))]
fn main() {}

#[cfg(target_os = "none")]
#[rustfmt::skip] // generated
#[path = "../tests/qemu_support/monterey.rs"]
mod monterey;

#[cfg(target_os = "none")]
#[allow(dead_code)]
#[path = "../tests/qemu_support/paper.rs"]
mod paper;

#[cfg(target_os = "none")]
mod firmware {
    use auvnav::{Plan, Planner};
    use cortex_m as _; // critical section for the defmt logger
    use cortex_m_rt::entry;
    use defmt_semihosting as _; // defmt frames to semihosting stdout

    use crate::{monterey, paper};

    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo) -> ! {
        defmt::error!("{}", defmt::Display2Format(info));
        auvnav_qemu::exit(false)
    }

    fn log_track<const K: usize>(mode: &str, track: usize, p: &Plan<3>, planner: &Planner<K>) {
        defmt::println!(
            "{=str} track {=usize}: {=usize} track(s) optimized jointly, {=usize} objective values",
            mode,
            track + 1,
            p.horizon_len,
            planner.history().len()
        );
        for (i, j) in planner.history().iter().enumerate() {
            defmt::println!("  iteration {=usize}: objective {=f32} m3", i, j);
        }
        defmt::println!(
            "{=str} track {=usize}: depth {=f32} m, {=str}, safe {=bool}, min altitude {=f32} m, J {=f32} m3, {=u32} iterations, {=u32} evaluations",
            mode,
            track + 1,
            p.depth,
            p.status.as_str(),
            p.safe,
            p.min_altitude,
            p.j,
            p.iterations,
            p.evaluations
        );
    }

    #[entry]
    fn main() -> ! {
        defmt::println!(
            "us_monterey_canyon_1: {=usize} bottom samples, {=usize} tracks; C-AUV #4; h_r 80 m, h_a 60 m",
            monterey::SAMPLES,
            paper::TRACKS
        );
        let plans = paper::plan_line::<1>(paper::trackwise_config(), |n, p, planner| {
            log_track("track-wise", n, p, planner)
        });
        match plans {
            Ok(_) => {
                defmt::println!("done");
                auvnav_qemu::exit(true)
            }
            _ => {
                defmt::error!("planning failed");
                auvnav_qemu::exit(false)
            }
        }
    }
}
