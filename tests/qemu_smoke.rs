//! The smoke test, small enough for every QEMU machine including the
//! soft-float Cortex-M3 (lm3s6965evb: 256 KiB flash, 64 KiB SRAM): the
//! C-AUV #4 plant's f32 ZOH, one objective+gradient evaluation of the
//! paper's whole line (`Scenario::evaluate::<5>`), and a track-wise plan
//! (`Planner::<1>`) of its last track, each compared bit for bit with the
//! host's values (`tests/qemu_support/expected.rs`, refreshed by
//! `AUVNAV_BLESS=1 cargo test --test qemu_plan`). See `paper::smoke`.
//!
//! `scripts/qemu-test.sh` runs it on mps2-an386 (Cortex-M4F), mps2-an500
//! (Cortex-M7) and lm3s6965evb (Cortex-M3). On the host, `cargo test` runs
//! this file's `main`, which checks the host against the same values.
#![cfg_attr(target_os = "none", no_std, no_main)]
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
#![allow(
    clippy::indexing_slicing,
    clippy::arithmetic_side_effects,
    clippy::float_cmp
)]

#[macro_use]
mod qemu_support;

#[cfg(target_os = "none")]
#[defmt_test::tests]
mod tests {
    use super::qemu_support::{compare, expected, paper};

    #[test]
    fn smoke_equals_host_bit_for_bit() {
        let got = ok!(paper::smoke(), "smoke computation failed");
        compare::smoke(&got, &expected::SMOKE);
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    let got = ok!(qemu_support::paper::smoke(), "smoke computation failed");
    qemu_support::compare::smoke(&got, &qemu_support::expected::SMOKE);
}
