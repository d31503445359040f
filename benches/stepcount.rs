//! Flies track 2 of `us_monterey_canyon_1` once, plainly and with the
//! K = 1 gradient, for an exact instruction count of the hot loop on the
//! host (x86-64; the target's own counts come from `cargo qemu-bench`):
//!
//! ```sh
//! cargo bench --bench stepcount --no-run
//! valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!     --toggle-collect='*plain_track*' target/release/deps/stepcount-*[^.d]
//! ```

#![allow(clippy::unwrap_used, clippy::indexing_slicing, missing_docs)]
#![allow(clippy::arithmetic_side_effects)]

mod common;

use std::hint::black_box;

use auvnav::{Scenario, TrackScore, VehicleState};

#[inline(never)]
fn plain_track(sc: &Scenario<'_, 3>, st: &VehicleState<3>) -> VehicleState<3> {
    let mut s = [TrackScore::default()];
    sc.simulate(st, 1, &[black_box(680.0)], &mut s, |_| {})
        .unwrap()
}

#[inline(never)]
fn gradient_track(sc: &Scenario<'_, 3>, st: &VehicleState<3>) -> f32 {
    sc.evaluate::<1>(st, 1, &[black_box(680.0)]).unwrap().grad_j[0]
}

fn main() {
    let l = common::line();
    let sc = l.scenario();
    let st = sc.start_state(sc.default_initial_depth());
    let mut s = [TrackScore::default()];
    let st = sc.simulate(&st, 0, &[866.86], &mut s, |_| {}).unwrap();
    let mut steps = 0_u32;
    sc.simulate(&st, 1, &[680.0], &mut s, |_| steps += 1)
        .unwrap();
    black_box(plain_track(&sc, &st));
    black_box(gradient_track(&sc, &st));
    println!("{steps} samples");
}
