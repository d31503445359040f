//! Benchmarks on the target: instruction counts of the simulation, the
//! objective+gradient evaluation and the planner on the paper's line
//! (`us_monterey_canyon_1`, C-AUV #4, `h_r = 80 m`, `h_a = 60 m`), and the
//! stack one solve uses. BENCHMARKS.md shows and explains the table.
//!
//! ```sh
//! cargo qemu-bench       # Cortex-M4F, QEMU mps2-an386
//! cargo qemu-bench-m3    # Cortex-M3 (soft float), QEMU lm3s6965evb
//! ```
//!
//! The firmware prints what it measures through semihosting, calls the
//! marker `auvnav_bench_start`, runs the code, calls `auvnav_bench_stop`;
//! the QEMU plugin `tools/qemu/insn_count.c` prints the instructions
//! executed in between, and `tools/qemu/bench_table.sh` (run by the cargo
//! runner) turns the two into the table, subtracting the markers' own
//! overhead (an empty measurement) and adding flash and RAM figures.
//! Instruction counts, not cycles; exactly repeatable.
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
#[allow(dead_code)]
#[rustfmt::skip] // generated
#[path = "../tests/qemu_support/expected.rs"]
mod expected;

#[cfg(target_os = "none")]
mod firmware {
    // Benchmark code: the arithmetic is on small counts and sizes.
    #![allow(clippy::arithmetic_side_effects, clippy::indexing_slicing)]

    use auvnav::{
        Mission, Planner, Profile, Scenario, TrackScore, Uncertainty, Vehicle, VehicleState,
        Waypoints, lower_envelope,
    };
    use auvnav_qemu::{bench, exit, image, stack};
    use cortex_m_rt::entry;
    use cortex_m_semihosting::hprintln;

    use crate::paper::{self, S, TRACKS, TrackPlan, W};
    use crate::{expected, monterey};

    /// Whether the horizon solves run: always with hardware floating point,
    /// on request (`AUVNAV_BENCH_HORIZON` at build time) on the M3.
    /// (`AUVNAV_BENCH_QUICK` at build time skips them everywhere, for a
    /// quick look at the step and the track-wise solves while profiling.)
    const HORIZON: bool = option_env!("AUVNAV_BENCH_QUICK").is_none()
        && (cfg!(target_abi = "eabihf") || option_env!("AUVNAV_BENCH_HORIZON").is_some());

    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo) -> ! {
        hprintln!("panic: {}", info);
        exit(false)
    }

    /// Runs `f` between the markers, after announcing it as
    /// `bench|id|label|units|unit`; returns its result.
    fn measure<T>(id: &str, label: &str, units: f32, unit: &str, f: impl FnOnce() -> T) -> T {
        hprintln!("bench|{}|{}|{}|{}", id, label, units, unit);
        bench::start();
        let r = f();
        bench::stop();
        r
    }

    /// Largest bottom slope on track `n`, degrees.
    fn steepest_slope_deg(n: usize) -> f32 {
        let (a, b) = (monterey::WAYPOINTS[n], monterey::WAYPOINTS[n + 1]);
        let mut worst = 0.0_f32;
        for k in 1..monterey::SAMPLES {
            let (x0, x1) = (monterey::X[k - 1], monterey::X[k]);
            if x1 <= a || x0 >= b {
                continue;
            }
            let slope = (monterey::B[k] - monterey::B[k - 1]) / (x1 - x0);
            worst = worst.max(libm::atanf(slope.abs()).to_degrees());
        }
        worst
    }

    fn status(got: &TrackPlan, want: &TrackPlan) -> &'static str {
        if got.depth.to_bits() == want.depth.to_bits() {
            "= host"
        } else {
            "DIFFERS from host"
        }
    }

    fn note_plan(id: &str, p: &TrackPlan, want: &TrackPlan) {
        hprintln!(
            "note|{}|depth {} m ({}), {} iterations, {} evaluations, {}",
            id,
            p.depth,
            status(p, want),
            p.iterations,
            p.evaluations,
            p.status
        );
    }

    /// The receding horizon under a declared uncertainty (the lower end
    /// of the README's recommended bounds: 5 m at the fix, 0.1 % drift,
    /// 1 m of map error, 5 % speed, 1 deg flight-path offset, 0.05 m/s
    /// current), certified over the map's lower envelope, call by call.
    fn certified_horizon(
        vehicle: &Vehicle<3>,
        bottom: &Profile<S>,
        waypoints: &Waypoints<W>,
        start: &VehicleState<3>,
    ) {
        let Ok(u) = Uncertainty::new(5.0, 0.001, 1.0, 0.05, 1.0, 0.05) else {
            exit(false)
        };
        let Ok(envelope) =
            lower_envelope::<{ 3 * S + 1 }>(bottom.view(), &u, monterey::WAYPOINTS[0])
        else {
            exit(false)
        };
        let mission = Mission::default().with_uncertainty(u);
        let Ok(line) = Scenario::new(vehicle, bottom, waypoints, mission)
            .and_then(|sc| sc.with_certification_bottom(envelope.view()))
        else {
            exit(false)
        };
        let Ok(mut planner) = Planner::<TRACKS>::new(paper::horizon_config()) else {
            exit(false)
        };
        let mut state = *start;
        for n in 0..TRACKS {
            let id = ["hc_1", "hc_2", "hc_3", "hc_4", "hc_5"][n];
            let r = measure(
                id,
                "certified horizon solve (Planner::<5>, declared uncertainty)",
                1.0,
                "solve",
                || planner.plan(&line, &state, n),
            );
            let Ok(plan) = r else { exit(false) };
            hprintln!(
                "note|{}|track {}: depth {} m, {} evaluations, safe {}, certified min altitude {} m",
                id,
                n + 1,
                plan.depth,
                plan.evaluations,
                plan.safe,
                plan.certified_min_altitude
            );
            state = plan.next_state;
        }
    }

    #[entry]
    fn main() -> ! {
        // Once, at configuration: the validation and its stability check
        // (20 480 steps of the linearized loop).
        let validated = measure(
            "vehicle",
            "vehicle validation (Vehicle::c_auv4, its stability check)",
            1.0,
            "call",
            Vehicle::c_auv4,
        );
        let Ok(vehicle) = validated else { exit(false) };
        let Ok(bottom) = Profile::<S>::new(&monterey::X, &monterey::B) else {
            exit(false)
        };
        let Ok(waypoints) = Waypoints::<W>::new(&monterey::WAYPOINTS) else {
            exit(false)
        };
        let Ok(line) = Scenario::new(&vehicle, &bottom, &waypoints, Mission::default()) else {
            exit(false)
        };
        let start = line.start_state(line.default_initial_depth());
        let wp = &monterey::WAYPOINTS;
        let length_km = (wp[TRACKS] - wp[0]) / 1000.0;

        measure(
            "overhead",
            "empty measurement (marker overhead)",
            1.0,
            "",
            || {},
        );

        // One simulated step: the whole line at the horizon plan's depths.
        let depths: [f32; TRACKS] = core::array::from_fn(|n| expected::HORIZON_K5[n].depth);
        let mut scores = [TrackScore::default(); TRACKS];
        let mut steps = 0_u32;
        let _ = line.simulate(&start, 0, &depths, &mut scores, |_| steps += 1);
        let steps = steps.saturating_sub(1); // samples include the start
        let r = measure(
            "step",
            "simulated step (Scenario::simulate, whole line, scored)",
            steps as f32,
            "step",
            || line.simulate(&start, 0, &depths, &mut scores, |_| {}),
        );
        if r.is_err() {
            exit(false)
        }

        // Objective + gradient per km: K = 5 over the line, K = 1 per track.
        let r = measure(
            "eval5",
            "objective+gradient, K = 5, whole line (Scenario::evaluate::<5>)",
            length_km,
            "km",
            || line.evaluate::<TRACKS>(&start, 0, &depths),
        );
        if r.is_err() {
            exit(false)
        }
        let mut state: VehicleState<3> = start;
        for n in 0..TRACKS {
            let len = (wp[n + 1] - wp[n]) / 1000.0;
            let id = ["eval1_1", "eval1_2", "eval1_3", "eval1_4", "eval1_5"][n];
            let r = measure(
                id,
                "objective+gradient, K = 1, one track",
                len,
                "km",
                || line.evaluate::<1>(&state, n, &[depths[n]]),
            );
            match r {
                Ok(e) => state = e.end,
                Err(_) => exit(false),
            }
        }

        // Track-wise solves (the paper's method, Planner::<1>), track by
        // track from the state the previous committed depth leaves; the
        // stack of each solve is measured from the caller's stack pointer.
        let Ok(mut planner) = Planner::<1>::new(paper::trackwise_config()) else {
            exit(false)
        };
        let mut state = start;
        for n in 0..TRACKS {
            let id = ["tw_1", "tw_2", "tw_3", "tw_4", "tw_5"][n];
            hprintln!(
                "note|{}|track {}: {} m, steepest bottom slope {} deg",
                id,
                n + 1,
                wp[n + 1] - wp[n],
                steepest_slope_deg(n)
            );
            let base = stack::repaint();
            let r = measure(id, "track-wise solve (Planner::<1>)", 1.0, "solve", || {
                planner.plan(&line, &state, n)
            });
            let used = stack::used_below(base);
            let Ok(plan) = r else { exit(false) };
            note_plan(
                id,
                &TrackPlan::of(&plan, &planner),
                &expected::TRACKWISE_K1[n],
            );
            hprintln!("stack|{}|{}", id, used);
            state = plan.next_state;
        }

        // Receding horizon, K = 5 (the library's default), call by call;
        // the first call is cold (scan and five tracks jointly), the later
        // ones are warm-started. On the soft-float M3 the cold call alone
        // runs tens of billions of instructions (minutes in QEMU): skipped
        // unless the build sets AUVNAV_BENCH_HORIZON.
        if HORIZON {
            let Ok(mut planner) = Planner::<TRACKS>::new(paper::horizon_config()) else {
                exit(false)
            };
            let mut state = start;
            for n in 0..TRACKS {
                let id = ["hz_1", "hz_2", "hz_3", "hz_4", "hz_5"][n];
                let base = stack::repaint();
                let r = measure(id, "horizon solve (Planner::<5>)", 1.0, "solve", || {
                    planner.plan(&line, &state, n)
                });
                let used = stack::used_below(base);
                let Ok(plan) = r else { exit(false) };
                let p = TrackPlan::of(&plan, &planner);
                hprintln!(
                    "note|{}|track {} of {}, {} tracks jointly",
                    id,
                    n + 1,
                    TRACKS,
                    plan.horizon_len
                );
                note_plan(id, &p, &expected::HORIZON_K5[n]);
                hprintln!("stack|{}|{}", id, used);
                state = plan.next_state;
            }
            certified_horizon(&vehicle, &bottom, &waypoints, &start);
        } else {
            hprintln!(
                "skip|horizon solves (Planner::<5>) not run on this soft-float build (tens of billions of instructions, minutes in QEMU); AUVNAV_BENCH_HORIZON=1 cargo qemu-bench-m3 runs them"
            );
        }

        let s = image::sizes();
        hprintln!(
            "image|{}|{}|{}|{}|{}|{}",
            s.vectors,
            s.text,
            s.rodata,
            s.data,
            s.bss,
            s.uninit
        );
        hprintln!("done");
        exit(true)
    }
}
