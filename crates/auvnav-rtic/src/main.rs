//! Real-time integration under RTIC 2 on QEMU mps2-an386 (Cortex-M4F): the
//! logic of `examples/qemu_realtime.rs`, with RTIC's scheduling.
//!
//! - `control`: hardware task bound to TIMER0 (IRQ 8), priority 2, 10 Hz:
//!   `Autopilot::update` and the simulated vehicle; at a waypoint it
//!   switches the reference and spawns `plan`.
//! - `plan`: software task, priority 1: the next track's depth with
//!   `auvnav::Resumable`, from `VehicleState::measured`.
//! - `idle`: waits for the line's end, reports, exits via semihosting.
#![no_std]
#![no_main]
#![allow(clippy::arithmetic_side_effects, clippy::indexing_slicing)]

// The line, the simulated vehicle and the timing record, shared with the
// super-loop example.
#[path = "../../../examples/realtime/flight.rs"]
mod flight;
mod pac;

use auvnav_qemu::timer;
use cortex_m_semihosting::hprintln;

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("panic: {}", info);
    auvnav_qemu::exit(false)
}

/// Starts CMSDK timer 0 (interrupt every `reload + 1` ticks).
fn timer_start(reload: u32) {
    const BASE: usize = 0x4000_0000;
    for (off, v) in [(0, 0), (8, reload), (4, reload), (12, 1), (0, 1 | 8)] {
        // SAFETY: CTRL/VALUE/RELOAD/INTCLEAR of timer 0, always mapped.
        unsafe { core::ptr::write_volatile((BASE + off) as *mut u32, v) };
    }
}

/// Stops CMSDK timer 0.
fn timer_stop() {
    // SAFETY: timer 0's CTRL register.
    unsafe { core::ptr::write_volatile(0x4000_0000 as *mut u32, 0) };
}

#[rtic::app(device = crate::pac, peripherals = false, dispatchers = [TIMER1])]
mod app {
    use super::*;
    use crate::flight::{Arrival, Flight, IPS, MAP_B, MAP_X, STEP_FLIGHTS, Times, WAYPOINTS};
    use auvnav::{
        Mission, Planner, PlannerConfig, ProfileView, Resumable, Scenario, Step, TrackScore,
        Vehicle, VehicleState, Waypoints,
    };
    use rtic::Mutex;

    /// Timer ticks per control period (10 Hz).
    const PERIOD: u32 = timer::CLOCK_HZ / 10;

    /// What the control task keeps.
    pub struct Control {
        /// The vehicle flying the line.
        flight: Flight,
        /// A waypoint reached, for the planner.
        arrived: Option<Arrival>,
        /// Control periods run, worst release latency (ticks), misses,
        /// planner calls that could not start (the last still running).
        ticks: u32,
        worst_latency: u32,
        misses: u32,
        overruns: u32,
    }

    #[shared]
    struct Shared {
        control: Control,
        times: Times,
    }

    #[local]
    struct Local {
        sc: Scenario<'static, 3>,
        r: Resumable<3>,
        prior: VehicleState<3>,
    }

    #[init(local = [vehicle: Option<Vehicle<3>> = None, line: Option<Waypoints<4>> = None])]
    fn init(cx: init::Context) -> (Shared, Local) {
        let Ok(vehicle) = Vehicle::c_auv4() else {
            auvnav_qemu::exit(false)
        };
        let Ok(line) = Waypoints::<4>::new(&WAYPOINTS) else {
            auvnav_qemu::exit(false)
        };
        let v: &'static Vehicle<3> = cx.local.vehicle.insert(vehicle);
        let l: &'static Waypoints<4> = cx.local.line.insert(line);
        let Ok(map) = ProfileView::new(&MAP_X, &MAP_B) else {
            auvnav_qemu::exit(false)
        };
        let Ok(sc) = Scenario::from_views(v, map, l.view(), Mission::default()) else {
            auvnav_qemu::exit(false)
        };
        let Ok(p) = Planner::<3>::new(PlannerConfig::default()) else {
            auvnav_qemu::exit(false)
        };
        let mut r = Resumable::new(p);
        let d0 = sc.default_initial_depth();
        let start = sc.start_state(d0);
        // Before launch: the first track in one blocking call.
        r.begin(&start, 0, u32::MAX);
        let (z0, safe) = match r.step(&sc, u32::MAX) {
            Ok(Step::Done(p)) => (p.depth, p.safe),
            _ => (d0, false),
        };
        hprintln!("track 1: depth {} m (planned before launch)", z0);
        let (flight, arrival) = Flight::new(*v, d0, z0);
        let control = Control {
            flight,
            arrived: Some(arrival),
            ticks: 0,
            worst_latency: 0,
            misses: 0,
            overruns: 0,
        };
        timer_start(PERIOD - 1);
        let times = Times {
            all_safe: safe,
            ..Times::default()
        };
        (
            Shared { control, times },
            Local {
                sc,
                r,
                prior: start,
            },
        )
    }

    /// The 10 Hz control task.
    #[task(binds = TIMER0, priority = 2, shared = [control])]
    fn control(mut cx: control::Context) {
        let latency = timer::reload().saturating_sub(timer::value());
        timer::clear();
        let arrived = cx.shared.control.lock(|c| {
            c.worst_latency = c.worst_latency.max(latency);
            c.ticks += 1;
            if !c.flight.done
                && let Some(a) = c.flight.sample()
            {
                c.arrived = Some(a);
            }
            c.arrived.take()
        });
        let overrun = arrived.is_some_and(|a| plan::spawn(a).is_err());
        let missed = timer::pending();
        if overrun || missed {
            cx.shared.control.lock(|c| {
                c.misses += u32::from(missed);
                c.overruns += u32::from(overrun);
            });
        }
    }

    /// Simulated time now, s (control periods and the timer's count).
    fn now(c: &mut impl Mutex<T = Control>) -> f32 {
        let (ticks, value) = c.lock(|c| (c.ticks, timer::value()));
        (ticks as f32 + (PERIOD - 1 - value.min(PERIOD - 1)) as f32 / PERIOD as f32) * 0.1
    }

    /// The planner: the next track's depth while the vehicle flies this one.
    #[task(priority = 1, shared = [control, times], local = [sc, r, prior])]
    async fn plan(mut cx: plan::Context, a: Arrival) {
        let Arrival(n, m, ints, z) = a;
        let (sc, r, prior) = (cx.local.sc, cx.local.r, cx.local.prior);
        let st = VehicleState::measured(prior, &m).and_then(|s| s.with_integrals(ints[0], ints[1]));
        let Ok(st) = st else {
            cx.shared.times.lock(|t| t.all_safe = false);
            return;
        };
        if n + 2 >= WAYPOINTS.len() {
            return;
        }
        let mut s = [TrackScore::default()];
        *prior = sc.simulate(&st, n, &[z], &mut s, |_| {}).unwrap_or(st);
        r.begin(prior, n + 1, u32::MAX);
        let t0 = now(&mut cx.shared.control);
        let (mut steps, mut worst_step) = (0, 0.0_f32);
        let result = loop {
            let s0 = now(&mut cx.shared.control);
            let step = r.step(sc, STEP_FLIGHTS);
            worst_step = worst_step.max(now(&mut cx.shared.control) - s0);
            steps += 1;
            match step {
                Ok(Step::Pending) => {}
                Ok(Step::Done(p)) => break Some(p),
                Err(_) => break None,
            }
        };
        let dt = now(&mut cx.shared.control) - t0;
        cx.shared.times.lock(|t| {
            t.steps += steps;
            t.worst_step = t.worst_step.max(worst_step);
            t.worst_call = t.worst_call.max(dt);
            t.total += dt;
            t.calls += 1;
            t.all_safe &= result.as_ref().is_some_and(|p| p.safe);
        });
        if let Some(p) = result {
            hprintln!(
                "track {}: depth {} m, {}, certified min altitude {} m, planned in {} s",
                n + 2,
                p.depth,
                p.status,
                p.certified_min_altitude,
                dt
            );
            cx.shared.control.lock(|c| c.flight.next = Some(p.depth));
        }
    }

    #[idle(shared = [control, times])]
    fn idle(mut cx: idle::Context) -> ! {
        while !cx.shared.control.lock(|c| c.flight.done) {
            cortex_m::asm::wfi();
        }
        timer_stop();
        let (ticks, latency, misses, overruns, min_alt) = cx.shared.control.lock(|c| {
            (
                c.ticks,
                c.worst_latency,
                c.misses,
                c.overruns,
                c.flight.min_altitude,
            )
        });
        let (calls, worst, total, steps, worst_step, safe) = cx.shared.times.lock(|t| {
            (
                t.calls,
                t.worst_call,
                t.total,
                t.steps,
                t.worst_step,
                t.all_safe,
            )
        });
        hprintln!(
            "clock: -icount shift=3, {} M instructions per simulated second",
            IPS / 1e6
        );
        hprintln!(
            "control task (RTIC, TIMER0 prio 2): {} periods at 10 Hz, worst release latency {} us, deadline misses {}, planner overruns {}",
            ticks,
            latency as f32 * 1e6 / timer::CLOCK_HZ as f32,
            misses,
            overruns
        );
        hprintln!(
            "planner (RTIC task prio 1): {} calls in flight, worst {} s, mean {} s; {} steps of <= {} flights, worst step {} s (~{} M instructions)",
            calls,
            worst,
            total / calls.max(1) as f32,
            steps,
            STEP_FLIGHTS,
            worst_step,
            worst_step * IPS / 1e6
        );
        let h_a = Mission::default().min_altitude();
        hprintln!("flown: minimum altitude {} m (h_a {} m)", min_alt, h_a);
        auvnav_qemu::exit(misses == 0 && overruns == 0 && safe && min_alt >= h_a)
    }
}
