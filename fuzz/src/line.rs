//! A vehicle, a mission, a line (bottom profile and waypoints) and a start
//! state from fuzzer input: mostly plausible values (so that the planner's
//! interesting paths run: penalties, fallbacks, infeasible tracks, depth
//! limits that bind), with raw `f32` anywhere (NaN, ±∞, unsorted,
//! duplicates, wrong lengths) so that every validation path runs too.
//!
//! Lines are short in simulation steps (`U0 Ts`), at most
//! [`MAX_LINE_STEPS`], so that an execution takes about a millisecond at
//! most and a long run reaches 10⁷ executions in an hour or two.

use std::sync::OnceLock;

use arbitrary::Arbitrary;
use auvnav::{
    AutopilotConfig, Mission, PidGains, Profile, Scenario, TfKind, TransferFunction, Vehicle,
    VehicleConfig, VehicleState, Waypoints,
};

/// Profile capacity.
pub const SAMPLES: usize = 64;
/// Waypoint capacity (5 tracks).
pub const WAYPOINTS: usize = 6;
/// Plant order capacity of a tuned vehicle (the default one runs at 3,
/// exactly as the firmware does).
pub const ORDER: usize = 4;
/// Longest line, in simulation steps.
pub const MAX_LINE_STEPS: f32 = 400.0;

/// Largest length or depth of a physical input, m.
pub const PHYSICAL_LENGTH: f32 = 1e6;
/// Largest gain, limit, speed, sample time or plant state of a physical
/// input.
pub const PHYSICAL_SETTING: f32 = 1e4;
/// Shortest step `U0 Ts` of a physical input, m.
pub const PHYSICAL_STEP: f32 = 1e-4;

/// Every value is within `bound` in magnitude.
pub fn within(values: &[f32], bound: f32) -> bool {
    values.iter().all(|v| v.abs() <= bound)
}

/// One number: the default, a plausible value (a fraction of a range the
/// caller gives), or any `f32` bit pattern.
#[derive(Arbitrary, Debug, Clone, Copy, PartialEq)]
pub enum Val {
    /// The documented default.
    Default,
    /// `lo + (hi − lo) · s / 65535`.
    Scaled(u16),
    /// Any bits: NaN, ±∞, subnormals, huge values.
    Raw(f32),
}

impl Val {
    /// The value, with `default` and the plausible range `[lo, hi]`.
    pub fn get(self, default: f32, lo: f32, hi: f32) -> f32 {
        match self {
            Self::Default => default,
            Self::Scaled(s) => lo + (hi - lo) * f32::from(s) / f32::from(u16::MAX),
            Self::Raw(v) => v,
        }
    }
}

/// The vehicle.
#[derive(Arbitrary, Debug)]
pub enum VehicleIn {
    /// `Vehicle::c_auv4()` (order 3, as on the target).
    CAuv4,
    /// Any configuration and plant, at order capacity [`ORDER`].
    Tuned(Box<Tuned>),
}

/// A configured vehicle.
#[derive(Arbitrary, Debug)]
pub struct Tuned {
    pub speed: Val,
    pub sample_time: Val,
    pub depth_pid: [Val; 3],
    pub pitch_pid: [Val; 3],
    pub pitch_limit: Val,
    pub elevator_limit: Val,
    pub plant: PlantIn,
}

/// The pitch dynamics.
#[derive(Arbitrary, Debug)]
pub enum PlantIn {
    /// The paper's `θ/δ`.
    CAuv4,
    /// The paper's `q/δ` (kind `rate`).
    PaperRate,
    /// `θ/δ` from coefficients (each defaulting to the paper's).
    Pitch(Vec<Val>, Vec<Val>),
    /// `q/δ` from coefficients.
    Rate(Vec<Val>, Vec<Val>),
}

const NUM: [f32; 1] = [-0.173];
const NUM_RATE: [f32; 2] = [-0.173, 0.0];
const DEN: [f32; 4] = [1.0, 2.681, 0.546, 0.048];

fn coefficients(v: &[Val], default: &[f32]) -> Vec<f32> {
    v.iter()
        .take(ORDER + 2)
        .enumerate()
        .map(|(i, c)| c.get(default.get(i).copied().unwrap_or(0.0), -3.0, 3.0))
        .collect()
}

impl Tuned {
    /// The configuration and transfer function, unvalidated.
    pub fn config(
        &self,
    ) -> (
        VehicleConfig,
        Result<TransferFunction<ORDER>, auvnav::PlantError>,
    ) {
        let d = VehicleConfig::default();
        let (dp, pp) = (d.autopilot.depth_pid, d.autopilot.pitch_pid);
        let gains = |v: &[Val; 3], g: PidGains, hi: [f32; 3]| PidGains {
            kp: v[0].get(g.kp, 0.0, hi[0]),
            ki: v[1].get(g.ki, 0.0, hi[1]),
            kd: v[2].get(g.kd, 0.0, hi[2]),
        };
        let cfg = VehicleConfig {
            speed: self.speed.get(d.speed, 0.2, 5.0),
            sample_time: self.sample_time.get(d.sample_time, 0.01, 1.0),
            autopilot: AutopilotConfig {
                depth_pid: gains(&self.depth_pid, dp, [5.0, 1.0, 10.0]),
                pitch_pid: gains(&self.pitch_pid, pp, [5.0, 1.0, 10.0]),
                pitch_limit: self.pitch_limit.get(d.autopilot.pitch_limit, 0.0, 89.9),
                elevator_limit: self
                    .elevator_limit
                    .get(d.autopilot.elevator_limit, 0.0, 60.0),
            },
        };
        let tf = match &self.plant {
            PlantIn::CAuv4 => TransferFunction::pitch(&NUM, &DEN),
            PlantIn::PaperRate => TransferFunction::rate(&NUM_RATE, &DEN),
            PlantIn::Pitch(n, d) => TransferFunction::new(
                TfKind::Pitch,
                &coefficients(n, &NUM),
                &coefficients(d, &DEN),
            ),
            PlantIn::Rate(n, d) => TransferFunction::new(
                TfKind::Rate,
                &coefficients(n, &NUM_RATE),
                &coefficients(d, &DEN),
            ),
        };
        (cfg, tf)
    }

    /// The validated vehicle, or `None` when the library rejects it.
    pub fn vehicle(&self) -> Option<Vehicle<ORDER>> {
        let (cfg, tf) = self.config();
        let v = Vehicle::new(&cfg, tf.ok()?).ok()?;
        let step = v.speed() * v.sample_time();
        assert!(
            step.is_finite() && step >= 0.0,
            "validated vehicle with step {step}: {cfg:?}"
        );
        if step == 0.0 && crate::known::ZERO_STEP_VEHICLE {
            return None;
        }
        Some(v)
    }
}

/// The paper's vehicle, built once.
pub fn c_auv4() -> &'static Vehicle<3> {
    static V: OnceLock<Vehicle<3>> = OnceLock::new();
    V.get_or_init(|| match Vehicle::c_auv4() {
        Ok(v) => v,
        Err(e) => panic!("the paper's vehicle is rejected: {e}"),
    })
}

/// The mission.
#[derive(Arbitrary, Debug)]
pub struct MissionIn {
    /// `h_r`, a fraction of the line's length when scaled.
    pub reference_altitude: Val,
    /// `h_a`, a fraction of `h_r` when scaled, absolute when raw.
    pub min_altitude: Val,
    pub limits: LimitsIn,
}

/// The allowed reference depths.
#[derive(Arbitrary, Debug)]
pub enum LimitsIn {
    /// `[0, 6000]` m.
    Default,
    /// Around the default start depth `b(X_0) − h_r`: `[d0 − a, d0 + b]`
    /// with `a`, `b` fractions of the line's length, so they bind.
    AroundStart(u8, u8),
    /// Any.
    Raw(f32, f32),
}

impl MissionIn {
    /// The validated mission for a line of length `len` whose first
    /// waypoint's bottom is `b0`, or `None` when the library rejects it.
    pub fn mission(&self, len: f32, b0: f32) -> Option<Mission> {
        let m = Mission::default();
        let h_r = self
            .reference_altitude
            .get(m.reference_altitude(), 0.005 * len, 0.3 * len);
        let h_a = match self.min_altitude {
            Val::Default if self.reference_altitude == Val::Default => m.min_altitude(),
            Val::Raw(v) => v,
            v => h_r * v.get(0.75, 0.0, 1.0),
        };
        let limits = match self.limits {
            LimitsIn::Default => m.depth_limits(),
            LimitsIn::AroundStart(a, b) => {
                let d0 = b0 - h_r;
                let f = |v: u8| len * f32::from(v) / 255.0;
                [d0 - f(a), d0 + f(b)]
            }
            LimitsIn::Raw(lo, hi) => [lo, hi],
        };
        Mission::new(h_r, h_a, limits).ok()
    }
}

/// Where the waypoints and the bottom are.
#[derive(Arbitrary, Debug)]
pub enum LineIn {
    /// A synthetic bottom.
    Shaped(Box<Shaped>),
    /// A window of one of the real profiles of `data/bathymetry`, squeezed
    /// onto the line (its slopes kept, times a factor).
    Real(Box<RealWindow>),
    /// Raw positions and depths, unvalidated.
    Raw(Box<RawLine>),
}

/// A synthetic line.
#[derive(Arbitrary, Debug)]
pub struct Shaped {
    /// Line length, steps (8 + `length % 392`).
    pub length: u16,
    /// `X_0`, m.
    pub origin: Val,
    /// Tracks' relative lengths (one track per entry, at most 5).
    pub tracks: Vec<u8>,
    /// Profile margins before `X_0` and after the last waypoint, steps;
    /// 255 puts the waypoint one step outside.
    pub before: u8,
    pub after: u8,
    /// Bottom depth at the origin, m.
    pub base: Val,
    /// Relief, a fraction of the line's length.
    pub relief: u8,
    /// Bottom heights in `[-1, 1]` of the relief, one per sample.
    pub heights: Vec<i8>,
    /// Gaps between samples (relative).
    pub gaps: Vec<u8>,
}

/// A window of a real profile.
#[derive(Arbitrary, Debug)]
pub struct RealWindow {
    pub which: u8,
    pub offset: u16,
    pub samples: u8,
    pub length: u16,
    pub origin: Val,
    pub tracks: Vec<u8>,
    pub before: u8,
    pub after: u8,
    /// Vertical exaggeration of the real slopes.
    pub exaggeration: Val,
}

/// A raw line.
#[derive(Arbitrary, Debug)]
pub struct RawLine {
    pub x: Vec<f32>,
    pub depth: Vec<f32>,
    pub waypoints: Vec<f32>,
}

/// The real profiles, parsed once.
fn real_profiles() -> &'static [(Vec<f32>, Vec<f32>)] {
    static P: OnceLock<Vec<(Vec<f32>, Vec<f32>)>> = OnceLock::new();
    P.get_or_init(|| {
        [
            include_str!("../../data/bathymetry/us_monterey_canyon_1.csv"),
            include_str!("../../data/bathymetry/us_monterey_canyon_2.csv"),
            include_str!("../../data/bathymetry/us_monterey_canyon_3.csv"),
            include_str!("../../data/bathymetry/es_medes_islands_1.csv"),
            include_str!("../../data/bathymetry/es_medes_islands_2.csv"),
            include_str!("../../data/bathymetry/jp_aburatsubo_sagami_1.csv"),
        ]
        .iter()
        .map(|text| {
            text.lines()
                .skip(1)
                .filter_map(|l| {
                    let (x, b) = l.split_once(',')?;
                    Some((x.trim().parse::<f32>().ok()?, b.trim().parse::<f32>().ok()?))
                })
                .unzip()
        })
        .collect()
    })
}

/// Waypoints `X_0 .. X_0 + len` split in the given relative track lengths.
fn waypoints(origin: f32, len: f32, tracks: &[u8]) -> Vec<f32> {
    let rel: Vec<f32> = if tracks.is_empty() {
        vec![1.0]
    } else {
        tracks
            .iter()
            .take(WAYPOINTS - 1)
            .map(|&t| 1.0 + f32::from(t))
            .collect()
    };
    let total: f32 = rel.iter().sum();
    let mut out = vec![origin];
    let mut acc = 0.0;
    for r in &rel {
        acc += r;
        out.push(origin + len * (acc / total));
    }
    out
}

/// A line from `first` to `last` is at most [`MAX_LINE_STEPS`] long (and
/// not NaN). A vehicle that does not advance (`step` 0) is flown anyway once
/// [`crate::known::ZERO_STEP_VEHICLE`] is fixed: its flight must fail fast.
fn flyable(first: f32, last: f32, step: f32) -> bool {
    (last - first) / step <= MAX_LINE_STEPS || (step == 0.0 && !crate::known::ZERO_STEP_VEHICLE)
}

fn margin(m: u8, step: f32) -> f32 {
    if m == 255 {
        -step
    } else {
        step * f32::from(m % 64)
    }
}

/// Positions and depths of the profile, and the waypoints.
pub type RawParts = (Vec<f32>, Vec<f32>, Vec<f32>);

impl LineIn {
    /// Profile positions, depths and waypoints for a vehicle flying `step`
    /// metres per sample; `None` when the line would be too long to fly
    /// quickly.
    pub fn parts(&self, step: f32) -> Option<RawParts> {
        match self {
            Self::Shaped(s) => {
                let len = step * (8.0 + f32::from(s.length % 392));
                let origin = s.origin.get(0.0, -1e4, 1e4);
                let wp = waypoints(origin, len, &s.tracks);
                let p0 = origin - margin(s.before, step);
                let p1 = origin + len + margin(s.after, step);
                let n = s.heights.len().clamp(2, SAMPLES);
                let gaps: Vec<f32> = (0..n - 1)
                    .map(|i| {
                        1.0 + f32::from(s.gaps.get(i % s.gaps.len().max(1)).copied().unwrap_or(0))
                    })
                    .collect();
                let total: f32 = gaps.iter().sum();
                let mut x = vec![p0];
                let mut acc = 0.0;
                for g in &gaps {
                    acc += g;
                    x.push(p0 + (p1 - p0) * (acc / total));
                }
                let base = s.base.get(500.0, 0.0, 6000.0);
                let relief = len * f32::from(s.relief) / 255.0;
                let b = (0..n)
                    .map(|i| {
                        let h = s.heights.get(i).copied().unwrap_or(0);
                        base + relief * f32::from(h) / 127.0
                    })
                    .collect();
                Some((x, b, wp))
            }
            Self::Real(r) => {
                let profiles = real_profiles();
                let (px, pb) = profiles.get(usize::from(r.which) % profiles.len())?;
                let n = (2 + usize::from(r.samples) % (SAMPLES - 1)).min(px.len());
                let first = usize::from(r.offset) % (px.len() - n + 1);
                let (wx, wb) = (&px[first..first + n], &pb[first..first + n]);
                let len = step * (8.0 + f32::from(r.length % 392));
                let origin = r.origin.get(0.0, -1e4, 1e4);
                let wp = waypoints(origin, len, &r.tracks);
                let p0 = origin - margin(r.before, step);
                let p1 = origin + len + margin(r.after, step);
                let scale = (p1 - p0) / (wx[n - 1] - wx[0]);
                let v = r.exaggeration.get(1.0, 0.0, 3.0);
                let x = wx.iter().map(|&x| p0 + (x - wx[0]) * scale).collect();
                let b = wb
                    .iter()
                    .map(|&b| wb[0] + (b - wb[0]) * scale * v)
                    .collect();
                Some((x, b, wp))
            }
            Self::Raw(r) => {
                let wp: Vec<f32> = r.waypoints.iter().copied().take(WAYPOINTS + 1).collect();
                let (first, last) = (wp.first()?, wp.last()?);
                if !flyable(*first, *last, step) {
                    return None;
                }
                Some((
                    r.x.iter().copied().take(SAMPLES + 1).collect(),
                    r.depth.iter().copied().take(SAMPLES + 1).collect(),
                    wp,
                ))
            }
        }
    }
}

/// The start state.
#[derive(Arbitrary, Debug)]
pub enum StartIn {
    /// `start_state(default_initial_depth())`.
    Default,
    /// Trimmed at `X_0`, this far below the default depth (a fraction of
    /// the line's length when scaled).
    Depth(Val),
    /// Anything: plant state, depths, position on (or off) the first
    /// track, integrators.
    Full(Box<[Val; 10]>),
}

impl StartIn {
    /// The start state on a line starting at `x0` with first track length
    /// `track`, total length `len`, default start depth `d0`.
    pub fn state<const N: usize>(&self, x0: f32, track: f32, len: f32, d0: f32) -> VehicleState<N> {
        match self {
            Self::Default => VehicleState::trimmed(d0, x0),
            Self::Depth(v) => VehicleState::trimmed(
                match v {
                    Val::Raw(d) => *d,
                    v => d0 + v.get(0.0, -len, len),
                },
                x0,
            ),
            Self::Full(v) => {
                let eta: [f32; N] =
                    core::array::from_fn(|i| v.get(i).map_or(0.0, |e| e.get(0.0, -5.0, 5.0)));
                let depth = d0 + v[4].get(0.0, -len, len);
                let x = x0 + v[6].get(0.0, -0.05 * track, 1.05 * track);
                VehicleState::new(
                    eta,
                    depth,
                    depth + v[5].get(0.0, -1.0, 1.0),
                    x,
                    x - v[7].get(0.0, -0.5, 2.0),
                    v[8].get(0.0, -50.0, 50.0),
                    v[9].get(0.0, -50.0, 50.0),
                )
            }
        }
    }
}

/// Everything a scenario borrows, validated.
pub struct Line<const N: usize> {
    pub vehicle: Vehicle<N>,
    pub profile: Profile<SAMPLES>,
    pub waypoints: Waypoints<WAYPOINTS>,
    pub mission: Mission,
    /// Every value is of physical magnitude (see
    /// [`crate::known::ABSURD_OVERFLOW`]).
    pub physical: bool,
}

impl<const N: usize> Line<N> {
    /// Validates the parts; `None` (after checking that the library's
    /// validation agrees with the obvious rules) when they are rejected.
    pub fn new(vehicle: Vehicle<N>, line: &LineIn, mission: &MissionIn) -> Option<Self> {
        let step = vehicle.speed() * vehicle.sample_time();
        let (x, b, wp) = line.parts(step)?;
        let profile = Profile::<SAMPLES>::new(&x, &b);
        let valid_profile = (2..=SAMPLES).contains(&x.len())
            && x.len() == b.len()
            && x.iter().chain(&b).all(|v| v.is_finite())
            && x.windows(2).all(|w| w[0] < w[1]);
        assert_eq!(
            profile.is_ok(),
            valid_profile,
            "Profile::new({x:?}, {b:?}) = {profile:?}"
        );
        let waypoints = Waypoints::<WAYPOINTS>::new(&wp);
        let valid_wp = (2..=WAYPOINTS).contains(&wp.len())
            && wp.iter().all(|v| v.is_finite())
            && wp.windows(2).all(|w| w[0] < w[1]);
        assert_eq!(
            waypoints.is_ok(),
            valid_wp,
            "Waypoints::new({wp:?}) = {waypoints:?}"
        );
        let (profile, waypoints) = (profile.ok()?, waypoints.ok()?);
        let wp = waypoints.positions();
        let (first, last) = (wp[0], wp[wp.len() - 1]);
        if !flyable(first, last, step) {
            return None;
        }
        let b0 = profile.depth_at(first).unwrap_or(0.0);
        let mission = mission.mission(last - first, b0)?;
        let ap = vehicle.autopilot().config();
        let (dp, pp) = (ap.depth_pid, ap.pitch_pid);
        let settings = [
            vehicle.speed(),
            vehicle.sample_time(),
            dp.kp,
            dp.ki,
            dp.kd,
            pp.kp,
            pp.ki,
            pp.kd,
            ap.pitch_limit,
            ap.elevator_limit,
        ];
        let tf = vehicle.plant().transfer_function();
        let [lo, hi] = mission.depth_limits();
        let lengths = [mission.reference_altitude(), mission.min_altitude(), lo, hi];
        let physical = step >= PHYSICAL_STEP
            && within(&settings, PHYSICAL_SETTING)
            && within(tf.numerator(), PHYSICAL_SETTING)
            && within(tf.denominator(), PHYSICAL_SETTING)
            && within(&lengths, PHYSICAL_LENGTH)
            && within(profile.positions(), PHYSICAL_LENGTH)
            && within(profile.depths(), PHYSICAL_LENGTH)
            && within(waypoints.positions(), PHYSICAL_LENGTH);
        Some(Self {
            vehicle,
            profile,
            waypoints,
            mission,
            physical,
        })
    }

    /// The scenario, or `None` when a waypoint lies outside the profile
    /// (checked to be the only reason).
    pub fn scenario(&self) -> Option<Scenario<'_, N>> {
        let sc = Scenario::new(&self.vehicle, &self.profile, &self.waypoints, self.mission);
        let inside = self
            .waypoints
            .positions()
            .iter()
            .all(|&x| x >= self.profile.start() && x <= self.profile.end());
        assert_eq!(sc.is_ok(), inside, "Scenario::new: {:?}", sc.as_ref().err());
        sc.ok()
    }

    /// The first track's length and the line's.
    pub fn lengths(&self) -> (f32, f32) {
        let wp = self.waypoints.positions();
        (wp[1] - wp[0], wp[wp.len() - 1] - wp[0])
    }
}

/// A state of physical magnitude.
pub fn state_is_physical<const N: usize>(s: &VehicleState<N>) -> bool {
    within(s.eta().as_slice(), PHYSICAL_SETTING)
        && within(&[s.depth_integral(), s.pitch_integral()], PHYSICAL_SETTING)
        && within(
            &[s.depth(), s.depth_prev(), s.x(), s.x_prev()],
            PHYSICAL_LENGTH,
        )
}

/// Every component of a state is finite.
pub fn state_is_finite<const N: usize>(s: &VehicleState<N>) -> bool {
    s.eta().iter().all(|v| v.is_finite())
        && [
            s.depth(),
            s.depth_prev(),
            s.x(),
            s.x_prev(),
            s.depth_integral(),
            s.pitch_integral(),
        ]
        .iter()
        .all(|v| v.is_finite())
}
