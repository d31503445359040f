//! The paper's scenario planned on the target, bit for bit against the
//! host: `us_monterey_canyon_1`, default C-AUV #4 vehicle,
//! `Mission::default()` (`h_r = 80 m`, `h_a = 60 m`), receding horizon
//! with `Planner::<5>` and `PlannerConfig::default()`, and track-wise with
//! `Planner::<1>` (`tests/qemu_support/paper.rs`).
//!
//! Every track's committed depth, predicted J, minimum altitude and final
//! objective, the next start state, the status, the iteration and
//! evaluation counts, and a hash of the whole objective history must
//! equal the host's plan (`tests/qemu_support/expected.rs`) exactly: the
//! library is f32 throughout with no fused multiply-add and its own
//! (libm) transcendental functions, so x86-64, Cortex-M4F (hardware
//! single precision), Cortex-M7 and soft-float Cortex-M3 compute the same
//! bits.
//!
//! This is also the smoke test run on all three QEMU machines
//! (`scripts/qemu-test.sh`): mps2-an386 (M4F), mps2-an500 (M7),
//! lm3s6965evb (M3, `thumbv7m-none-eabi`).
//!
//! On the host, `cargo test` runs this file's `main`: it plans the line on
//! the host and checks it against the committed values, so host and
//! target both equal `expected.rs`. After an intended change of the
//! planner, refresh it with
//! `AUVNAV_BLESS=1 cargo test --test qemu_plan` (and review the diff).
#![cfg_attr(target_os = "none", no_std, no_main)]
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
#![allow(
    clippy::indexing_slicing,
    clippy::arithmetic_side_effects,
    clippy::float_cmp
)]

#[macro_use]
mod qemu_support;

mod checks {
    use crate::qemu_support::paper::{self, TrackPlan};

    /// Receding horizon, `Planner::<5>`, default configuration.
    pub fn horizon() -> [TrackPlan; paper::TRACKS] {
        ok!(
            paper::plan_line::<5>(paper::horizon_config(), |_, _, _| {}),
            "horizon planning failed"
        )
    }

    /// Track-wise, `Planner::<1>`.
    pub fn trackwise() -> [TrackPlan; paper::TRACKS] {
        ok!(
            paper::plan_line::<1>(paper::trackwise_config(), |_, _, _| {}),
            "track-wise planning failed"
        )
    }
}

#[cfg(target_os = "none")]
#[defmt_test::tests]
mod tests {
    use super::checks;
    use super::qemu_support::{compare, expected};

    #[test]
    fn horizon_k5_plan_equals_host_bit_for_bit() {
        compare::plans("horizon K=5", &checks::horizon(), &expected::HORIZON_K5);
    }

    #[test]
    fn trackwise_k1_plan_equals_host_bit_for_bit() {
        compare::plans(
            "track-wise K=1",
            &checks::trackwise(),
            &expected::TRACKWISE_K1,
        );
    }
}

#[cfg(not(target_os = "none"))]
mod bless {
    use crate::qemu_support::paper::{Smoke, TrackPlan};
    use std::fmt::Write;

    /// An f32 as an exact const expression, with its value.
    fn f(v: f32) -> String {
        format!("f32::from_bits(0x{:08x}) /* {v:?} */", v.to_bits())
    }

    fn fs(v: &[f32]) -> String {
        let items: Vec<String> = v.iter().map(|&v| format!("        {},\n", f(v))).collect();
        format!("[\n{}    ]", items.concat())
    }

    fn track(out: &mut String, indent: &str, p: &TrackPlan) {
        let i = indent;
        writeln!(out, "TrackPlan {{").unwrap();
        writeln!(out, "{i}    depth: {},", f(p.depth)).unwrap();
        writeln!(out, "{i}    status: {:?},", p.status).unwrap();
        writeln!(out, "{i}    safe: {},", p.safe).unwrap();
        writeln!(out, "{i}    j: {},", f(p.j)).unwrap();
        writeln!(out, "{i}    min_altitude: {},", f(p.min_altitude)).unwrap();
        writeln!(out, "{i}    objective: {},", f(p.objective)).unwrap();
        writeln!(out, "{i}    iterations: {},", p.iterations).unwrap();
        writeln!(out, "{i}    evaluations: {},", p.evaluations).unwrap();
        writeln!(out, "{i}    history_len: {},", p.history_len).unwrap();
        writeln!(out, "{i}    history_hash: 0x{:08x},", p.history_hash).unwrap();
        writeln!(out, "{i}    next_x: {},", f(p.next_x)).unwrap();
        writeln!(out, "{i}    next_depth: {},", f(p.next_depth)).unwrap();
        write!(out, "{i}}}").unwrap();
    }

    fn plans(out: &mut String, name: &str, what: &str, plans: &[TrackPlan]) {
        writeln!(out, "\n/// {what}").unwrap();
        writeln!(out, "pub const {name}: [TrackPlan; {}] = [", plans.len()).unwrap();
        for p in plans {
            write!(out, "    ").unwrap();
            track(out, "    ", p);
            writeln!(out, ",").unwrap();
        }
        writeln!(out, "];").unwrap();
    }

    fn smoke(out: &mut String, s: &Smoke) {
        writeln!(out, "\n/// The smoke test's values (`paper::smoke`).").unwrap();
        writeln!(out, "pub const SMOKE: Smoke = Smoke {{").unwrap();
        writeln!(out, "    ad: {},", fs(&s.ad)).unwrap();
        writeln!(out, "    bd: {},", fs(&s.bd)).unwrap();
        writeln!(out, "    j: {},", f(s.j)).unwrap();
        writeln!(out, "    violation: {},", f(s.violation)).unwrap();
        writeln!(out, "    min_altitude: {},", f(s.min_altitude)).unwrap();
        writeln!(out, "    grad_j: {},", fs(&s.grad_j)).unwrap();
        writeln!(out, "    grad_violation: {},", fs(&s.grad_violation)).unwrap();
        writeln!(out, "    end_x: {},", f(s.end_x)).unwrap();
        writeln!(out, "    end_depth: {},", f(s.end_depth)).unwrap();
        write!(out, "    last_track: ").unwrap();
        track(out, "    ", &s.last_track);
        writeln!(out, ",\n}};").unwrap();
    }

    /// The source of `tests/qemu_support/expected.rs`.
    pub fn source(horizon: &[TrackPlan], trackwise: &[TrackPlan], s: &Smoke) -> String {
        let mut out = String::from(
            "// @generated by `AUVNAV_BLESS=1 cargo test --test qemu_plan`: the host's\n\
             // (x86-64) results, compared bit for bit on the target by\n\
             // tests/qemu_plan.rs and tests/qemu_smoke.rs. Review the diff before\n\
             // committing a change.\n\
             #![allow(clippy::all)]\n\n\
             use super::paper::{Smoke, TrackPlan};\n",
        );
        plans(
            &mut out,
            "HORIZON_K5",
            "Receding horizon, `Planner::<5>`, `PlannerConfig::default()`.",
            horizon,
        );
        plans(
            &mut out,
            "TRACKWISE_K1",
            "Track-wise, `Planner::<1>`, `Mode::TrackWise`.",
            trackwise,
        );
        smoke(&mut out, s);
        out
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    let horizon = checks::horizon();
    let trackwise = checks::trackwise();
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/qemu_support/expected.rs"
    );
    let smoke = ok!(qemu_support::paper::smoke(), "smoke");
    let source = bless::source(&horizon, &trackwise, &smoke);
    if std::env::var_os("AUVNAV_BLESS").is_some() {
        std::fs::write(path, &source).unwrap();
        println!("wrote {path}");
        return;
    }
    let committed = std::fs::read_to_string(path).unwrap_or_default();
    if committed != source {
        println!("{source}");
        println!(
            "the host's plans differ from {path} (printed above); after an intended planner \
             change run `AUVNAV_BLESS=1 cargo test --test qemu_plan` and review the diff"
        );
    }
    qemu_support::compare::plans("horizon K=5", &horizon, &qemu_support::expected::HORIZON_K5);
    qemu_support::compare::plans(
        "track-wise K=1",
        &trackwise,
        &qemu_support::expected::TRACKWISE_K1,
    );
    qemu_support::compare::smoke(&smoke, &qemu_support::expected::SMOKE);
}
