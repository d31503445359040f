//! The guidances of `plan fly` and the closed loop that flies them: the
//! library's `Autopilot::update` at `Ts` on noisy measurements driving the
//! true plant (the model's transfer function with the world's gain and
//! time scales, discretised by the library's own ZOH `Plant::new`), behind
//! a first-order actuator lag and an elevator rate limit, with the world's
//! speed, flight-path offset and current in the kinematics.

use auvnav::{
    AutopilotState, Measurement, Plan, PlanError, Planner, PlannerConfig, Plant, Scenario,
    TransferFunction, VehicleState,
};

use super::sonar;
use super::world::{Flight, Map, Rng};
use crate::input::{MAX_HORIZON, ORDER};

/// One guidance, as `--guidance` names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Horizon,
    Certified,
    Track,
    BottomFollow,
    MinAltitude,
    Constant,
}

impl Kind {
    pub const ALL: [Kind; 6] = [
        Kind::Horizon,
        Kind::Certified,
        Kind::Track,
        Kind::BottomFollow,
        Kind::MinAltitude,
        Kind::Constant,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Kind::Horizon => "horizon",
            Kind::Certified => "certified",
            Kind::Track => "track",
            Kind::BottomFollow => "bottom-follow",
            Kind::MinAltitude => "min-altitude",
            Kind::Constant => "constant",
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }
    pub fn sonar(self) -> bool {
        matches!(self, Kind::BottomFollow | Kind::MinAltitude)
    }
}

/// What every flight of a line shares.
pub struct Line<'a> {
    /// The nominal scenario (horizon, and the precomputed plans).
    pub nominal: Scenario<'a, ORDER>,
    /// The scenario with the config's declared uncertainty (certified).
    pub declared: Scenario<'a, ORDER>,
    pub planner: PlannerConfig,
    pub map: Map,
    /// Waypoints, m (navigation frame).
    pub wp: Vec<f64>,
    pub initial_depth: f32,
    /// The paper's track-wise plan over the map, from predicted states.
    pub track_plan: Vec<f32>,
    /// The deepest constant depth safe over the whole line on the map.
    pub constant: f32,
}

/// One flight's record for one guidance.
#[derive(Clone, Debug, Default)]
pub struct Record {
    pub min_altitude: f64,
    /// Where (true x, m) the least altitude was met.
    pub min_at: f64,
    pub sum_sq: f64,
    pub sum_alt: f64,
    pub samples: u64,
    pub below_steps: u64,
    pub lock_steps: u64,
    /// DVL pings (sonar guidances).
    pub pings: u64,
    pub collided: bool,
    /// Per track: the flown least altitude and the planner's prediction
    /// of it (planned guidances), m.
    pub track_min: Vec<f64>,
    pub predicted: Vec<Option<f64>>,
    /// Estimator error at each replanning waypoint: depth (m), pitch (deg),
    /// predicted minimum altitude from the estimate minus from the true
    /// state (m).
    pub est: Vec<[f64; 3]>,
    /// The flown path (x, depth, true bottom, lock), kept for plots.
    pub path: Vec<(f64, f64, f64, bool)>,
}

impl Record {
    fn new(tracks: usize) -> Self {
        Self {
            min_altitude: f64::INFINITY,
            track_min: vec![f64::INFINITY; tracks],
            predicted: vec![None; tracks],
            ..Self::default()
        }
    }
}

/// The true vehicle's plant: the model's transfer function with the
/// world's gain and time scales (`G_true(s) = g G(τ s)`).
pub fn true_plant(line: &Line<'_>, gain: f64, time: f64) -> Result<Plant<ORDER>, String> {
    let v = line.nominal.vehicle();
    let tf = v.plant().transfer_function();
    // Exactly the model: the vehicle's own plant, bit for bit.
    #[allow(clippy::float_cmp)]
    if gain == 1.0 && time == 1.0 {
        return Ok(*v.plant());
    }
    let n = tf.order();
    let (den, num) = (tf.denominator(), tf.numerator());
    // den: s^n + a_1 s^{n-1} + ... ; num: b_0 s^{n-1} + ... (padded).
    let tau = time as f32;
    let mut d = vec![1.0_f32];
    let mut m = Vec::new();
    for k in 1..=n {
        d.push(den[k - 1] / tau.powi(k as i32));
    }
    for (i, &b) in num.iter().enumerate().take(n) {
        // power s^{n-1-i} -> tau^{n-1-i} / tau^n
        m.push(gain as f32 * b / tau.powi(i as i32 + 1));
    }
    let tf = TransferFunction::<ORDER>::pitch(&m, &d).map_err(|e| format!("true plant: {e}"))?;
    Plant::new(tf, v.sample_time()).map_err(|e| format!("true plant: {e}"))
}

/// The guidance's memory during a flight.
struct State {
    reference: f32,
    planner: Option<Box<Planner<MAX_HORIZON, ORDER>>>,
    prior: VehicleState<ORDER>,
    /// Bottom follower: seconds since lock was lost, and the UNSAFE
    /// state (DUNE's `SM_UNSAFE`) with its hysteresis.
    unlocked: f64,
    unsafe_climb: bool,
}

/// The true vehicle.
struct Body {
    eta: [f32; ORDER],
    elevator: f32,
    x: f64,
    x_prev: f64,
    d: f64,
    d_prev: f64,
    t: f64,
}

/// The true vehicle's dynamics in one world.
struct Truth {
    plant: Plant<ORDER>,
    ts: f64,
    /// True speed, m/s; flight-path offset, rad.
    u: f64,
    alpha: f64,
    /// Actuator lag, s, its per-step gain, and the rate limit per step, deg.
    lag: f64,
    lag_a: f64,
    rate: f64,
}

impl Truth {
    fn new(line: &Line<'_>, world: &Flight) -> Result<Self, String> {
        let vehicle = line.nominal.vehicle();
        let ts = f64::from(vehicle.sample_time());
        let lag = world.v["actuator_lag"];
        Ok(Self {
            plant: true_plant(
                line,
                world.v["plant_gain_scale"],
                world.v["plant_time_scale"],
            )?,
            ts,
            u: f64::from(vehicle.speed()) * (1.0 + world.v["speed_error"]),
            alpha: world.v["flight_path_offset"].to_radians(),
            lag,
            lag_a: if lag > 0.0 {
                1.0 - (-ts / lag).exp()
            } else {
                1.0
            },
            rate: world.v["elevator_rate_limit"] * ts,
        })
    }

    /// The true pitch (deg) and the measured depth (m), pitch (deg) and
    /// pitch rate (deg/s).
    fn measure(&self, b: &Body, world: &Flight, rng: &mut Rng) -> (f64, f64, f64, f64) {
        let theta = f64::from(self.plant.pitch(&b.eta));
        let q = f64::from(self.plant.pitch_rate(&b.eta));
        let m_depth = b.d + world.v["depth_noise"] * rng.normal();
        let m_pitch = theta + world.v["pitch_noise"] * rng.normal();
        let m_q = q + world.v["pitch_rate_noise"] * rng.normal();
        (theta, m_depth, m_pitch, m_q)
    }

    /// One step: the commanded elevator through the actuator, the plant,
    /// and the kinematics along the mean pitch less the flight-path offset.
    fn step(&self, b: &mut Body, commanded: f32, world: &Flight) -> (f64, f64) {
        b.elevator = if self.lag <= 0.0 && self.rate <= 0.0 {
            commanded
        } else {
            let mut change = self.lag_a as f32 * (commanded - b.elevator);
            if self.rate > 0.0 {
                change = change.clamp(-self.rate as f32, self.rate as f32);
            }
            b.elevator + change
        };
        let next = self.plant.step(&b.eta, b.elevator);
        let theta = f64::from(self.plant.pitch(&b.eta));
        let mean = (0.5 * (theta + f64::from(self.plant.pitch(&next)))).to_radians() - self.alpha;
        let (ts, u) = (self.ts, self.u);
        let (d_new, x_new) = (
            b.d - u * ts * mean.sin() + world.current(b.t) * ts,
            b.x + u * ts * mean.cos(),
        );
        let from = (b.x, b.d);
        (b.d_prev, b.x_prev, b.d, b.x, b.eta) = (b.d, b.x, d_new, x_new, next);
        b.t += ts;
        from
    }
}

/// The guidance's state at the start of the line.
fn start(line: &Line<'_>, kind: Kind) -> Result<State, String> {
    Ok(State {
        reference: line.initial_depth,
        planner: match kind {
            Kind::Horizon | Kind::Certified => Some(Box::new(
                Planner::new(line.planner).map_err(|e| format!("planner: {e}"))?,
            )),
            _ => None,
        },
        prior: line.nominal.start_state(line.initial_depth),
        unlocked: 0.0,
        unsafe_climb: false,
    })
}

/// Flies one guidance through one world. `noise_seed` seeds the sensors
/// (the same for every guidance of a flight: paired comparisons).
pub fn fly(
    line: &Line<'_>,
    world: &Flight,
    kind: Kind,
    noise_seed: (u64, u64),
    keep_path: bool,
) -> Result<Record, String> {
    let truth = Truth::new(line, world)?;
    let ap_law = line.nominal.vehicle().autopilot();
    let mission = line.nominal.mission();
    let (h_r, h_a) = (
        f64::from(mission.reference_altitude()),
        f64::from(mission.min_altitude()),
    );
    let mut rng = Rng::new(noise_seed.0, noise_seed.1);
    let (d0, x0) = (f64::from(line.initial_depth), line.wp[0]);
    let x_end = *line.wp.last().unwrap_or(&x0);
    let tracks = line.wp.len() - 1;
    let mut b = Body {
        eta: [0.0; ORDER],
        elevator: 0.0,
        x: x0,
        x_prev: x0,
        d: d0,
        d_prev: d0,
        t: 0.0,
    };
    let mut ap = AutopilotState::trimmed(line.initial_depth);
    let mut g = start(line, kind)?;
    let mut rec = Record::new(tracks);
    let mut track = usize::MAX;
    let budget = (20.0 * (x_end - x0) / (truth.u * truth.ts)) as u64 + 10_000;
    for _ in 0..budget {
        let xi = world.navigated(b.x);
        let (theta, m_depth, m_pitch, m_q) = truth.measure(&b, world, &mut rng);
        let alt = world.bottom(&line.map, b.x) - b.d;
        if alt < rec.min_altitude {
            rec.min_at = b.x;
        }
        score(&mut rec, alt, h_r, h_a);
        if xi >= x_end || rec.collided {
            return Ok(rec);
        }
        let n = line.wp.partition_point(|&w| w <= xi).clamp(1, tracks) - 1;
        if n != track {
            track = n;
            let meas = Measurement {
                x: xi as f32,
                depth: m_depth as f32,
                pitch: m_pitch as f32,
                pitch_rate: m_q as f32,
            };
            on_waypoint(line, kind, &mut g, &mut rec, n, &meas, &ap, &b, world)?;
        }
        let ping = kind
            .sonar()
            .then(|| sonar::ping(world, &line.map, &mut rng, b.x, b.d, theta));
        if let Some(p) = &ping {
            rec.lock_steps += u64::from(p.lock);
            rec.pings += 1;
        }
        let r = step_reference(
            line,
            kind,
            &mut g,
            n,
            m_depth,
            m_pitch,
            ping.as_ref(),
            truth.ts,
            world,
        );
        let cmd = ap_law.update(&mut ap, r, m_depth as f32, m_pitch as f32, m_q as f32);
        let from = truth.step(&mut b, cmd.elevator, world);
        segment(&mut rec, line, world, from, (b.x, b.d));
        if keep_path {
            let bt = world.bottom(&line.map, b.x);
            rec.path.push((b.x, b.d, bt, ping.is_some_and(|p| p.lock)));
        }
    }
    Err("flight did not reach the end of the line".into())
}

/// The altitude at a sample, scored.
fn score(rec: &mut Record, alt: f64, h_r: f64, h_a: f64) {
    rec.min_altitude = rec.min_altitude.min(alt);
    rec.sum_sq += (alt - h_r).powi(2);
    rec.sum_alt += alt;
    rec.samples += 1;
    rec.below_steps += u64::from(alt < h_a);
    rec.collided |= alt < 0.0;
}

/// Each track's least true altitude over the flown segment from `a` to `b`
/// (true x, depth), clipped to the track windows (navigated x) and taken
/// at the segment's ends and the windows' ends, as the model's §8 takes it
/// (`sim/score.rs`: the samples and the waypoint clips).
fn segment(rec: &mut Record, line: &Line<'_>, world: &Flight, a: (f64, f64), b: (f64, f64)) {
    let (xa, xb) = (world.navigated(a.0), world.navigated(b.0));
    if xb <= xa {
        return;
    }
    let at = |xi: f64| {
        let f = (xi - xa) / (xb - xa);
        let x = a.0 + f * (b.0 - a.0);
        world.bottom(&line.map, x) - (a.1 + f * (b.1 - a.1))
    };
    for n in 0..line.wp.len() - 1 {
        let (lo, hi) = (xa.max(line.wp[n]), xb.min(line.wp[n + 1]));
        if lo > hi {
            continue;
        }
        let m = at(lo).min(at(hi));
        rec.track_min[n] = rec.track_min[n].min(m);
    }
}

/// At waypoint `n`: the planned guidances replan from the estimate.
#[allow(clippy::too_many_arguments)]
fn on_waypoint(
    line: &Line<'_>,
    kind: Kind,
    g: &mut State,
    rec: &mut Record,
    n: usize,
    meas: &Measurement,
    ap: &AutopilotState,
    b: &Body,
    world: &Flight,
) -> Result<(), String> {
    match kind {
        Kind::Track | Kind::MinAltitude => g.reference = line.track_plan[n],
        Kind::Constant => g.reference = line.constant,
        Kind::BottomFollow => {}
        Kind::Horizon | Kind::Certified => {
            let sc = if kind == Kind::Horizon {
                &line.nominal
            } else {
                &line.declared
            };
            let est = VehicleState::measured(&g.prior, meas)
                .and_then(|s| s.with_integrals(ap.depth_integral, ap.pitch_integral))
                .map_err(|e| format!("estimate: {e}"))?;
            let planner = g.planner.as_mut().ok_or("no planner")?;
            match planner.plan(sc, &est, n) {
                Ok(p) => {
                    g.reference = p.depth;
                    g.prior = p.next_state;
                    rec.predicted[n] = Some(f64::from(p.min_altitude));
                    rec.est
                        .push(estimator_error(sc, &p, &est, meas, b, world, ap)?);
                }
                // Below the bottom by the map: climb to the shallowest depth.
                Err(PlanError::StartBelowBottom) => {
                    g.reference = sc.mission().depth_limits()[0];
                }
                Err(e) => return Err(format!("planning track {}: {e}", n + 1)),
            }
        }
    }
    Ok(())
}

/// The estimator's error at a waypoint: depth and pitch of the estimate
/// against the truth, and the predicted minimum altitude of the committed
/// depth from the estimate against the same prediction from the true state.
fn estimator_error(
    sc: &Scenario<'_, ORDER>,
    p: &Plan<ORDER>,
    est: &VehicleState<ORDER>,
    meas: &Measurement,
    b: &Body,
    world: &Flight,
    ap: &AutopilotState,
) -> Result<[f64; 3], String> {
    let truth = VehicleState::new(
        b.eta,
        b.d as f32,
        b.d_prev as f32,
        meas.x,
        world.navigated(b.x_prev) as f32,
        ap.depth_integral,
        ap.pitch_integral,
    );
    let n = sc
        .waypoints()
        .positions()
        .partition_point(|&w| w <= meas.x)
        .saturating_sub(1);
    let predict = |s: &VehicleState<ORDER>| {
        let mut score = [auvnav::TrackScore::default()];
        sc.simulate(s, n, &[p.depth], &mut score, |_| {})
            .map(|_| f64::from(score[0].min_altitude()))
            .map_err(|e| format!("estimate check: {e}"))
    };
    let pitch_true = f64::from(sc.vehicle().plant().pitch(&b.eta));
    Ok([
        f64::from(est.depth()) - b.d,
        f64::from(meas.pitch) - pitch_true,
        predict(est)? - predict(&truth)?,
    ])
}

/// The reference depth of this sample.
#[allow(clippy::too_many_arguments)]
fn step_reference(
    line: &Line<'_>,
    kind: Kind,
    g: &mut State,
    n: usize,
    depth: f64,
    pitch: f64,
    ping: Option<&sonar::Ping>,
    ts: f64,
    world: &Flight,
) -> f32 {
    let mission = line.nominal.mission();
    let (h_r, h_a) = (
        f64::from(mission.reference_altitude()),
        f64::from(mission.min_altitude()),
    );
    let shallow = f64::from(mission.depth_limits()[0]);
    match (kind, ping) {
        // MOOS-IvP BHV_MinAltitudeX (ivp/src/lib_behaviors-marine/
        // BHV_MinAltitudeX.cpp, onRunState): with an altitude, the deepest
        // allowed depth is depth + altitude - min_altitude; without one
        // the behaviour returns no objective and the plan flies uncapped.
        (Kind::MinAltitude, Some(p)) => {
            let plan = f64::from(line.track_plan[n]);
            if p.lock {
                plan.min((depth + p.altitude - h_a).max(shallow)) as f32
            } else {
                plan as f32
            }
        }
        (Kind::BottomFollow, Some(p)) => bottom_follow(g, p, depth, pitch, h_r, ts, world, shallow),
        _ => g.reference,
    }
}

/// DUNE's altitude tracking with its BottomTracker
/// (src/DUNE/Control/BottomTracker.cpp, SlopeData.hpp): altitude
/// reference `h_r` flown as depth `d + altitude − h_r`; the slope ahead
/// from the forward range (`SlopeData::updateFRange`: the angle of the
/// line from the bottom below to the forward beam's hit); above the safe
/// pitch (15°, hysteresis 1.5°: `PathController` defaults) the tracker is
/// UNSAFE and commands the depth at the slope's top minus the altitude
/// reference (`dispatchSafeDepth`); on lock loss it holds the last depth
/// reference (`dispatchSameZ`) for `dvl_timeout` s, then climbs by `h_r`
/// (the supervisor's abort on a lost altitude, kept under way).
#[allow(clippy::too_many_arguments)]
fn bottom_follow(
    g: &mut State,
    p: &sonar::Ping,
    depth: f64,
    _pitch: f64,
    h_r: f64,
    ts: f64,
    world: &Flight,
    shallow: f64,
) -> f32 {
    const SAFE_PITCH: f64 = 15.0;
    const HYST: f64 = 1.5;
    if !p.lock {
        g.unlocked += ts;
        if g.unlocked > world.v["dvl_timeout"] {
            g.reference = (depth - h_r).max(shallow) as f32;
            g.unlocked = 0.0;
        }
        return g.reference;
    }
    g.unlocked = 0.0;
    let below = depth + p.altitude;
    let mut r = below - h_r;
    if let Some((ahead, top)) = p.fore {
        let slope = ((below - top) / ahead.max(1e-3)).atan().to_degrees();
        if slope > SAFE_PITCH {
            g.unsafe_climb = true;
        } else if slope < SAFE_PITCH - HYST {
            g.unsafe_climb = false;
        }
        if g.unsafe_climb {
            r = r.min(top - h_r);
        }
    }
    g.reference = r.max(shallow) as f32;
    g.reference
}
