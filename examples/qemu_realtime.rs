//! Real-time integration on the Cortex-M4F under QEMU (`mps2-an386`), as a
//! bare super-loop without an RTOS: the control task and the planner share
//! one core, and the control task never misses its deadline.
//!
//! - **Control task, high priority**: the CMSDK timer 0 interrupts at
//!   10 Hz (the autopilot's sample time); its handler runs
//!   [`auvnav::Autopilot::update`] on the vehicle's measurements and, in
//!   this example, also steps the vehicle itself (the plant and the
//!   kinematics stand in for the real AUV). At each waypoint it switches
//!   the reference to the depth the planner prepared for the new track,
//!   and hands the planner the measured state.
//! - **Planner, low priority (the main loop)**: from each measured state it
//!   predicts the state at the next waypoint (`VehicleState::measured`,
//!   one flight of the track being flown) and plans the track after it with
//!   [`auvnav::Resumable`], in steps of at most `STEP_FLIGHTS` flights
//!   (`Step::Pending` until done), while the vehicle flies this track.
//!
//! QEMU runs with `-icount shift=3,sleep=off` (`QEMU_ICOUNT`): every
//! instruction takes 2³ ns of virtual time (125 M instructions per
//! simulated second, the stated clock) and idle time is skipped, so every
//! figure is deterministic. It prints the control task's worst release
//! latency, its deadline misses (a period that ended before the handler
//! returned), the planner's simulated time per call and per step, and the
//! line's minimum altitude; it fails unless there are no misses, every plan
//! is certified and the flown line keeps `h_a`.
//!
//! ```sh
//! QEMU_ICOUNT=shift=3,sleep=off cargo run --release \
//!     --target thumbv7em-none-eabihf --example qemu_realtime
//! ```
#![cfg_attr(target_os = "none", no_std, no_main)]
// (Example firmware: indices and counters within a short line.)
#![allow(clippy::arithmetic_side_effects, clippy::indexing_slicing)]

#[cfg(not(target_os = "none"))]
fn main() {}

#[cfg(target_os = "none")]
#[path = "realtime/flight.rs"]
mod flight;

#[cfg(target_os = "none")]
mod firmware {
    use core::cell::RefCell;

    use auvnav::{
        Mission, Planner, PlannerConfig, ProfileView, Resumable, Scenario, Step, TrackScore,
        Vehicle, VehicleState, Waypoints,
    };
    use auvnav_qemu::timer;
    use cortex_m::interrupt::{self, Mutex};
    use cortex_m_rt::entry;
    use cortex_m_semihosting::hprintln;

    use crate::flight::{Arrival, Flight, IPS, MAP_B, MAP_X, STEP_FLIGHTS, Times, WAYPOINTS};

    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo) -> ! {
        hprintln!("panic: {}", info);
        auvnav_qemu::exit(false)
    }

    /// Timer ticks per control period (10 Hz).
    const PERIOD: u32 = timer::CLOCK_HZ / 10;

    /// What the control task and the planner share.
    struct Control {
        /// The vehicle flying the line.
        flight: Flight,
        /// A waypoint reached, for the planner.
        arrived: Option<Arrival>,
        /// Control periods run, worst release latency (ticks), misses.
        ticks: u32,
        worst_latency: u32,
        misses: u32,
    }

    static CONTROL: Mutex<RefCell<Option<Control>>> = Mutex::new(RefCell::new(None));

    /// The 10 Hz control task.
    fn control() {
        let latency = timer::reload().saturating_sub(timer::value());
        timer::clear();
        interrupt::free(|cs| {
            if let Some(c) = CONTROL.borrow(cs).borrow_mut().as_mut() {
                c.worst_latency = c.worst_latency.max(latency);
                c.ticks += 1;
                if !c.flight.done
                    && let Some(a) = c.flight.sample()
                {
                    c.arrived = Some(a);
                }
            }
        });
        // Another period ended while this one ran: a deadline missed.
        if timer::pending() {
            interrupt::free(|cs| {
                if let Some(c) = CONTROL.borrow(cs).borrow_mut().as_mut() {
                    c.misses += 1;
                }
            });
        }
    }

    /// Simulated time now, s (control periods and the timer's count).
    fn now() -> f32 {
        let (ticks, value) = interrupt::free(|cs| {
            let t = CONTROL.borrow(cs).borrow().as_ref().map_or(0, |c| c.ticks);
            (t, timer::value())
        });
        (ticks as f32 + (PERIOD - 1 - value.min(PERIOD - 1)) as f32 / PERIOD as f32) * 0.1
    }

    /// Plans `track` from `st` in resumable steps; its depth.
    fn plan_track(
        r: &mut Resumable<3>,
        sc: &Scenario<'_, 3>,
        st: &VehicleState<3>,
        track: usize,
        t: &mut Times,
    ) -> Option<f32> {
        r.begin(st, track, u32::MAX);
        // (Before launch the first track is planned in one blocking call.)
        let flights = if track == 0 { u32::MAX } else { STEP_FLIGHTS };
        let t0 = now();
        loop {
            let s0 = now();
            let step = r.step(sc, flights);
            t.worst_step = t.worst_step.max(now() - s0);
            t.steps += 1;
            match step {
                Ok(Step::Pending) => {}
                Ok(Step::Done(p)) => {
                    let dt = now() - t0;
                    t.worst_call = t.worst_call.max(dt);
                    t.total += dt;
                    t.calls += 1;
                    t.all_safe &= p.safe;
                    hprintln!(
                        "track {}: depth {} m, {}, certified min altitude {} m, planned in {} s",
                        track + 1,
                        p.depth,
                        p.status,
                        p.certified_min_altitude,
                        dt
                    );
                    return Some(p.depth);
                }
                Err(e) => {
                    hprintln!("track {}: {}", track + 1, e);
                    t.all_safe = false;
                    return None;
                }
            }
        }
    }

    /// The predicted state at the end of `track` flown at `z` from `st`.
    fn predict(
        sc: &Scenario<'_, 3>,
        st: &VehicleState<3>,
        track: usize,
        z: f32,
    ) -> VehicleState<3> {
        let mut s = [TrackScore::default()];
        sc.simulate(st, track, &[z], &mut s, |_| {}).unwrap_or(*st)
    }

    #[entry]
    fn main() -> ! {
        let ok = run().unwrap_or(false);
        auvnav_qemu::exit(ok)
    }

    fn run() -> Result<bool, auvnav::Error> {
        let vehicle = Vehicle::c_auv4()?;
        let map = ProfileView::new(&MAP_X, &MAP_B)?;
        let line = Waypoints::<4>::new(&WAYPOINTS)?;
        let mission = Mission::default();
        let sc = Scenario::from_views(&vehicle, map, line.view(), mission)?;
        let mut r = Resumable::new(Planner::<3>::new(PlannerConfig::default())?);
        let mut t = Times {
            all_safe: true,
            ..Times::default()
        };
        // Before launch: the first track, then the vehicle goes.
        let d0 = sc.default_initial_depth();
        let start = sc.start_state(d0);
        let z0 = plan_track(&mut r, &sc, &start, 0, &mut t).unwrap_or(d0);
        t = Times {
            all_safe: t.all_safe,
            ..Times::default()
        };
        let (flight, arrival) = Flight::new(vehicle, d0, z0);
        interrupt::free(|cs| {
            *CONTROL.borrow(cs).borrow_mut() = Some(Control {
                flight,
                arrived: Some(arrival),
                ticks: 0,
                worst_latency: 0,
                misses: 0,
            });
        });
        timer::start(PERIOD - 1, 0, control);
        let mut prior = start;
        loop {
            let (arrived, done) = interrupt::free(|cs| {
                let mut c = CONTROL.borrow(cs).borrow_mut();
                c.as_mut()
                    .map_or((None, true), |c| (c.arrived.take(), c.flight.done))
            });
            if done {
                break;
            }
            let Some(Arrival(n, m, ints, z)) = arrived else {
                cortex_m::asm::wfi();
                continue;
            };
            // The measured state, the predicted one at the next waypoint,
            // and the plan of the track after this one.
            let st = VehicleState::measured(&prior, &m)?.with_integrals(ints[0], ints[1])?;
            if n + 1 >= line.tracks() {
                continue;
            }
            prior = predict(&sc, &st, n, z);
            if let Some(next) = plan_track(&mut r, &sc, &prior, n + 1, &mut t) {
                interrupt::free(|cs| {
                    if let Some(c) = CONTROL.borrow(cs).borrow_mut().as_mut() {
                        c.flight.next = Some(next);
                    }
                });
            }
        }
        timer::stop();
        let c = interrupt::free(|cs| {
            let c = CONTROL.borrow(cs).borrow();
            c.as_ref()
                .map(|c| (c.ticks, c.worst_latency, c.misses, c.flight.min_altitude))
        });
        let Some((ticks, latency, misses, min_alt)) = c else {
            return Ok(false);
        };
        hprintln!(
            "clock: -icount shift=3, {} M instructions per simulated second",
            IPS / 1e6
        );
        hprintln!(
            "control task: {} periods at 10 Hz, worst release latency {} us, deadline misses {}",
            ticks,
            latency as f32 * 1e6 / timer::CLOCK_HZ as f32,
            misses
        );
        hprintln!(
            "planner: {} calls in flight, worst {} s, mean {} s; {} steps of <= {} flights, worst step {} s (~{} M instructions)",
            t.calls,
            t.worst_call,
            t.total / t.calls.max(1) as f32,
            t.steps,
            STEP_FLIGHTS,
            t.worst_step,
            t.worst_step * IPS / 1e6
        );
        hprintln!(
            "flown: minimum altitude {} m (h_a {} m)",
            min_alt,
            mission.min_altitude()
        );
        Ok(misses == 0 && t.all_safe && min_alt >= mission.min_altitude())
    }
}
