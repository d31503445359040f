//! What the two real-time examples share (`examples/qemu_realtime.rs`, the
//! bare super-loop, and `crates/auvnav-rtic`, the same under RTIC 2; both
//! compile this file in by path): the short line they fly, the simulated
//! vehicle their control task steps in place of the real AUV, and the
//! planner's timing record. Only the scheduling differs between them.

use auvnav::{AutopilotState, Measurement, ProfileView, Vehicle};

/// The mapped bottom under the line, m (as `examples/firmware_loop.rs`).
pub static MAP_X: [f32; 7] = [0.0, 400.0, 800.0, 1200.0, 1600.0, 2000.0, 2400.0];
/// Bottom depths at `MAP_X`, m.
pub static MAP_B: [f32; 7] = [500.0, 480.0, 430.0, 330.0, 300.0, 310.0, 320.0];
/// The line's waypoints, m along track.
pub static WAYPOINTS: [f32; 4] = [0.0, 800.0, 1600.0, 2380.0];
/// Flights per planner step.
pub const STEP_FLIGHTS: u32 = 8;
/// Virtual instructions per simulated second (`-icount shift=3`).
pub const IPS: f32 = 125.0e6;

/// A waypoint reached: the new track, what was measured there, the
/// autopilot's integrators `[I_d, I_θ]` and the track's reference depth, m.
pub struct Arrival(pub usize, pub Measurement, pub [f32; 2], pub f32);

/// The simulated vehicle flying the line under the autopilot.
pub struct Flight {
    vehicle: Vehicle<3>,
    /// Plant state, depth and position (and their previous samples).
    eta: [f32; 3],
    d: [f32; 2],
    x: [f32; 2],
    ap: AutopilotState,
    /// The track flown and its reference depth, m.
    track: usize,
    reference: f32,
    /// The depth prepared for the next track, m.
    pub next: Option<f32>,
    /// Least altitude over the map so far, m.
    pub min_altitude: f32,
    /// The line's last waypoint is reached.
    pub done: bool,
}

impl Flight {
    /// Trimmed at depth `d0` (m) on waypoint 0, flying `z0` (m); with the
    /// arrival at waypoint 0 the planner starts from.
    pub fn new(vehicle: Vehicle<3>, d0: f32, z0: f32) -> (Self, Arrival) {
        let m0 = Measurement {
            x: 0.0,
            depth: d0,
            pitch: 0.0,
            pitch_rate: 0.0,
        };
        let flight = Self {
            vehicle,
            eta: [0.0; 3],
            d: [d0, d0],
            x: [0.0, 0.0],
            ap: AutopilotState::trimmed(d0),
            track: 0,
            reference: z0,
            next: None,
            min_altitude: f32::INFINITY,
            done: false,
        };
        (flight, Arrival(0, m0, [0.0, 0.0], z0))
    }

    /// One sample: the autopilot on the measurements, then the vehicle;
    /// at a waypoint the reference switches to `next` and the arrival is
    /// returned.
    pub fn sample(&mut self) -> Option<Arrival> {
        let vehicle = self.vehicle;
        let plant = vehicle.plant();
        let (u, ts) = (vehicle.speed(), vehicle.sample_time());
        let theta = plant.pitch(&self.eta);
        let cmd = vehicle.autopilot().update(
            &mut self.ap,
            self.reference,
            self.d[0],
            theta,
            plant.pitch_rate(&self.eta),
        );
        self.eta = plant.step(&self.eta, cmd.elevator);
        let mean = 0.5 * (theta + plant.pitch(&self.eta)).to_radians();
        self.d = [self.d[0] - u * ts * libm::sinf(mean), self.d[0]];
        self.x = [self.x[0] + u * ts * libm::cosf(mean), self.x[0]];
        if let Ok(map) = ProfileView::new(&MAP_X, &MAP_B)
            && let Ok(b) = map.depth_at(self.x[0].min(WAYPOINTS[3]))
        {
            self.min_altitude = self.min_altitude.min(b - self.d[0]);
        }
        if self.x[0] >= WAYPOINTS[3] {
            self.done = true;
        } else if self.x[0] >= WAYPOINTS[self.track + 1] {
            self.track += 1;
            if let Some(z) = self.next.take() {
                self.reference = z;
            }
            let m = Measurement {
                x: self.x[0],
                depth: self.d[0],
                pitch: plant.pitch(&self.eta),
                pitch_rate: plant.pitch_rate(&self.eta),
            };
            let ints = [self.ap.depth_integral, self.ap.pitch_integral];
            return Some(Arrival(self.track, m, ints, self.reference));
        }
        None
    }
}

/// The planner's calls and steps, simulated s.
#[derive(Default)]
pub struct Times {
    pub calls: u32,
    pub steps: u32,
    pub worst_call: f32,
    pub worst_step: f32,
    pub total: f32,
    pub all_safe: bool,
}
