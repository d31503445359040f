//! Benchmarks on the target, the other Monterey lines: the receding-horizon
//! planner (`Planner::<5>`, default settings, C-AUV #4, `h_r = 80 m`,
//! `h_a = 60 m`) on `us_monterey_canyon_2` and `us_monterey_canyon_3`, call
//! by call, nominal and certified under the declared uncertainty of
//! `qemu_bench` (5 m, 0.1 %, 1 m, 5 %, 1°, 0.05 m/s). The same tables as
//! `qemu_bench`'s `hz_*` and `hc_*` rows for the paper's line
//! (BENCHMARKS.md).
//!
//! ```sh
//! cargo qemu-bench-lines   # Cortex-M4F, QEMU mps2-an386
//! ```
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(not(target_os = "none"))]
fn main() {}

#[cfg(target_os = "none")]
#[rustfmt::skip] // generated
#[path = "../tests/qemu_support/monterey_2.rs"]
mod monterey_2;

#[cfg(target_os = "none")]
#[rustfmt::skip] // generated
#[path = "../tests/qemu_support/monterey_3.rs"]
mod monterey_3;

#[cfg(target_os = "none")]
mod firmware {
    // Benchmark code: the arithmetic is on small counts and sizes.
    #![allow(clippy::arithmetic_side_effects, clippy::indexing_slicing)]

    use auvnav::{
        Mission, Planner, PlannerConfig, Profile, Scenario, Uncertainty, Vehicle, VehicleState,
        Waypoints, lower_envelope,
    };
    use auvnav_qemu::{bench, exit, stack};
    use cortex_m_rt::entry;
    use cortex_m_semihosting::hprintln;

    use crate::{monterey_2, monterey_3};

    /// Profile capacity (the lines have 173 and 186 samples).
    const S: usize = 256;
    /// Waypoint capacity (six waypoints each).
    const W: usize = 8;
    /// Tracks of each line.
    const TRACKS: usize = 5;

    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo) -> ! {
        hprintln!("panic: {}", info);
        exit(false)
    }

    /// Runs `f` between the markers, after announcing it as
    /// `bench|id|label|units|unit`; returns its result.
    fn measure<T>(id: &str, label: &str, f: impl FnOnce() -> T) -> T {
        hprintln!("bench|{}|{}|1|solve", id, label);
        bench::start();
        let r = f();
        bench::stop();
        r
    }

    /// One line: its name, the row ids' prefix, the samples and waypoints.
    struct Line {
        name: &'static str,
        id: &'static str,
        x: &'static [f32],
        b: &'static [f32],
        waypoints: &'static [f32],
    }

    /// The line's horizon plan, call by call, nominal (`certified`
    /// false) or under the declared uncertainty over the map's lower
    /// envelope; each call's row is `{id}_{n}` (`h`: nominal, `c`:
    /// certified).
    fn fly_line(line: &Line, certified: bool) {
        let Ok(vehicle) = Vehicle::c_auv4() else {
            exit(false)
        };
        let Ok(bottom) = Profile::<S>::new(line.x, line.b) else {
            exit(false)
        };
        let Ok(waypoints) = Waypoints::<W>::new(line.waypoints) else {
            exit(false)
        };
        let Ok(u) = Uncertainty::new(5.0, 0.001, 1.0, 0.05, 1.0, 0.05) else {
            exit(false)
        };
        let x0 = line.waypoints[0];
        let Ok(envelope) = lower_envelope::<{ 3 * S + 1 }>(bottom.view(), &u, x0) else {
            exit(false)
        };
        let mission = if certified {
            Mission::default().with_uncertainty(u)
        } else {
            Mission::default()
        };
        let Ok(mut sc) = Scenario::new(&vehicle, &bottom, &waypoints, mission) else {
            exit(false)
        };
        if certified {
            let Ok(with) = sc.with_certification_bottom(envelope.view()) else {
                exit(false)
            };
            sc = with;
        }
        let Ok(mut planner) = Planner::<TRACKS>::new(PlannerConfig::default()) else {
            exit(false)
        };
        let mut state: VehicleState<3> = sc.start_state(sc.default_initial_depth());
        let kind = if certified { "c" } else { "h" };
        for n in 0..TRACKS {
            let ids = ["1", "2", "3", "4", "5"];
            let label = if certified {
                "certified horizon solve (Planner::<5>, declared uncertainty)"
            } else {
                "horizon solve (Planner::<5>)"
            };
            let base = stack::repaint();
            let r = measure(&id(line.id, kind, ids[n]), label, || {
                planner.plan(&sc, &state, n)
            });
            let used = stack::used_below(base);
            let plan = match r {
                Ok(plan) => plan,
                // The line's end for a vehicle that met the bottom (an
                // infeasible line: Monterey 3's wall).
                Err(e) => {
                    hprintln!("note|{}|{}: {}", id(line.id, kind, ids[n]), line.name, e);
                    return;
                }
            };
            hprintln!(
                "note|{}|{} track {}: depth {} m, {} evaluations, {}, safe {}, certified min altitude {} m",
                id(line.id, kind, ids[n]),
                line.name,
                n + 1,
                plan.depth,
                plan.evaluations,
                plan.status.as_str(),
                plan.safe,
                plan.certified_min_altitude
            );
            hprintln!("stack|{}|{}", id(line.id, kind, ids[n]), used);
            state = plan.next_state;
        }
    }

    /// The row id `{line}{kind}_{n}` (at most 15 bytes).
    fn id(line: &str, kind: &str, n: &str) -> heapless::String<16> {
        let mut s = heapless::String::new();
        for part in [line, kind, "_", n] {
            let _ = s.push_str(part);
        }
        s
    }

    #[entry]
    fn main() -> ! {
        measure("overhead", "empty measurement (marker overhead)", || {});
        let lines = [
            Line {
                name: "us_monterey_canyon_2",
                id: "m2",
                x: &monterey_2::X,
                b: &monterey_2::B,
                waypoints: &monterey_2::WAYPOINTS,
            },
            Line {
                name: "us_monterey_canyon_3",
                id: "m3",
                x: &monterey_3::X,
                b: &monterey_3::B,
                waypoints: &monterey_3::WAYPOINTS,
            },
        ];
        for line in &lines {
            fly_line(line, false);
            fly_line(line, true);
        }
        hprintln!("done");
        exit(true)
    }
}
