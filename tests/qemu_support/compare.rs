//! Bit-for-bit comparison of target results with the host's
//! (`expected.rs`): every difference is printed with its size in ulps
//! before the check fails.

use super::paper::{Smoke, TrackPlan};

/// Distance in units in the last place between two finite f32.
fn ulps(a: f32, b: f32) -> i64 {
    let key = |v: f32| {
        let i = i64::from(v.to_bits() as i32);
        if i < 0 { i64::from(i32::MIN) - i } else { i }
    };
    key(a) - key(b)
}

/// `got` and `want` have the same bits; else the difference is printed.
fn same(what: &str, index: usize, got: f32, want: f32) -> bool {
    if got.to_bits() == want.to_bits() {
        return true;
    }
    say!(
        "{} [{}]: {} here vs {} on the host: differs by {} ({} ulp)",
        what,
        index,
        got,
        want,
        got - want,
        ulps(got, want)
    );
    false
}

fn all_same(what: &str, got: &[f32], want: &[f32]) -> bool {
    let mut all = got.len() == want.len();
    for (i, (&g, &w)) in got.iter().zip(want).enumerate() {
        all &= same(what, i, g, w);
    }
    all
}

fn track(mode: &str, t: usize, g: &TrackPlan, w: &TrackPlan) -> bool {
    let mut all = true;
    all &= same(mode, t + 1, g.depth, w.depth);
    all &= same("J", t + 1, g.j, w.j);
    all &= same("min altitude", t + 1, g.min_altitude, w.min_altitude);
    all &= same("objective", t + 1, g.objective, w.objective);
    all &= same("next x", t + 1, g.next_x, w.next_x);
    all &= same("next depth", t + 1, g.next_depth, w.next_depth);
    let counts = g.status == w.status
        && g.safe == w.safe
        && g.iterations == w.iterations
        && g.evaluations == w.evaluations
        && g.history_len == w.history_len
        && g.history_hash == w.history_hash;
    if !counts {
        say!(
            "{} track {}: status {} safe {} iterations {} evaluations {} history {} #{} here, status {} safe {} iterations {} evaluations {} history {} #{} on the host",
            mode,
            t + 1,
            g.status,
            g.safe,
            g.iterations,
            g.evaluations,
            g.history_len,
            g.history_hash,
            w.status,
            w.safe,
            w.iterations,
            w.evaluations,
            w.history_len,
            w.history_hash
        );
    }
    all && counts
}

/// Every field of every track equal, bit for bit.
pub fn plans(mode: &str, got: &[TrackPlan], want: &[TrackPlan]) {
    check!(got.len() == want.len(), "{}: track count", mode);
    let mut all = true;
    for (t, (g, w)) in got.iter().zip(want).enumerate() {
        all &= track(mode, t, g, w);
        say!(
            "{} track {}: depth {} m, J {} m3, min altitude {} m, {} iterations, {} evaluations, {}",
            mode,
            t + 1,
            g.depth,
            g.j,
            g.min_altitude,
            g.iterations,
            g.evaluations,
            g.status
        );
    }
    check!(all, "{}: the plan differs from the host's", mode);
}

/// The smoke values equal, bit for bit.
pub fn smoke(got: &Smoke, want: &Smoke) {
    let mut all = true;
    all &= all_same("C-AUV #4 Ad", &got.ad, &want.ad);
    all &= all_same("C-AUV #4 Bd", &got.bd, &want.bd);
    all &= all_same(
        "evaluate::<5> J, violation, min altitude, end x, end depth",
        &[
            got.j,
            got.violation,
            got.min_altitude,
            got.end_x,
            got.end_depth,
        ],
        &[
            want.j,
            want.violation,
            want.min_altitude,
            want.end_x,
            want.end_depth,
        ],
    );
    all &= all_same("evaluate::<5> dJ/dz", &got.grad_j, &want.grad_j);
    all &= all_same(
        "evaluate::<5> dV/dz",
        &got.grad_violation,
        &want.grad_violation,
    );
    say!(
        "evaluate::<5> of the line: J {} m3, violation {} m3, min altitude {} m",
        got.j,
        got.violation,
        got.min_altitude
    );
    all &= track(
        "last track, track-wise",
        4,
        &got.last_track,
        &want.last_track,
    );
    say!(
        "last track, track-wise: depth {} m, {} iterations, {} evaluations, {}",
        got.last_track.depth,
        got.last_track.iterations,
        got.last_track.evaluations,
        got.last_track.status
    );
    check!(all, "smoke: the results differ from the host's");
}
