//! Closed-loop simulation of the vehicle flying its next tracks (model
//! contract §3, §6, §7), scored as it goes (§8).
//!
//! One step, in the contract's order:
//! 1. the active reference `r_k = z_n` for `X_{n-1} <= x_k < X_n`;
//! 2. the autopilot cascade gives `δ_k`, then updates its integrators;
//! 3. `η_{k+1} = Ad η_k + Bd δ_k`;
//! 4. kinematics along the mean pitch `θ̄ = (θ_k + θ_{k+1}) / 2`:
//!    `d += -U0 Ts sin θ̄`, `x += U0 Ts cos θ̄`;
//! 5. `d_{k-1} <- d_k`.
//!
//! A run over tracks `first..first+m` starts from a state on track `first`
//! and ends at the first sample with `x >= X_{first+m}`; that final state is
//! exactly the start state of the next track. Each segment between two
//! samples is scored into the tracks it overlaps as it is flown, so a run
//! costs one pass and no trajectory storage.
//!
//! The loop is written once. A `Sensitivity` hook receives what each step
//! and each scored segment linearize to; the plain simulation passes a
//! no-op that compiles away, the gradient ([`crate::gradient`]) propagates
//! tangents in the same pass.

use core::fmt;

use heapless::Vec;
use nalgebra::SVector;

use crate::autopilot::Command;
use crate::num::{Comp, DEG, Sum, max, min};
use crate::profile::{Cursor, Point, Profile};
use crate::vehicle::{Mission, Vehicle};

/// Why waypoints were rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WaypointError {
    /// Fewer than two waypoints: no track.
    TooFew {
        /// Number given.
        len: usize,
    },
    /// More waypoints than the capacity `W`.
    OverCapacity {
        /// Number given.
        len: usize,
        /// The capacity `W`.
        capacity: usize,
    },
    /// A waypoint position is NaN or infinite.
    NonFinite {
        /// Index of the waypoint.
        index: usize,
    },
    /// `X[index] <= X[index - 1]`.
    NotIncreasing {
        /// Index of the waypoint.
        index: usize,
    },
    /// A waypoint lies outside the bottom profile.
    OutsideProfile {
        /// Index of the waypoint.
        index: usize,
    },
}

impl fmt::Display for WaypointError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::TooFew { len } => write!(f, "need at least 2 waypoints, got {len}"),
            Self::OverCapacity { len, capacity } => {
                write!(f, "{len} waypoints exceed the capacity {capacity}")
            }
            Self::NonFinite { index } => write!(f, "waypoint {index} is not finite"),
            Self::NotIncreasing { index } => {
                write!(f, "waypoint {index} does not lie beyond the previous one")
            }
            Self::OutsideProfile { index } => {
                write!(f, "waypoint {index} lies outside the bottom profile")
            }
        }
    }
}

impl core::error::Error for WaypointError {}

/// Why a simulation could not run or did not finish.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SimError {
    /// The waypoints were rejected.
    Waypoints(WaypointError),
    /// The mission's altitudes or depth limits were rejected.
    Mission(crate::error::ConfigError),
    /// No depths, or tracks beyond the last waypoint.
    TrackRange,
    /// The score buffer is shorter than the number of tracks simulated.
    ScoreBuffer,
    /// A reference depth is NaN or infinite.
    NonFiniteDepth {
        /// Index into the depths given.
        index: usize,
    },
    /// The start state is not finite.
    NonFiniteState,
    /// The start state's `x` does not lie on the first simulated track.
    StateOffTrack,
    /// The flight diverged: a value became non-finite, or the vehicle
    /// stopped advancing (|pitch| reached 90°).
    Diverged,
    /// The step budget ran out before the last waypoint was reached.
    StepLimit,
    /// A scored position fell outside the bottom profile.
    OutOfProfile,
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Waypoints(e) => e.fmt(f),
            Self::Mission(e) => e.fmt(f),
            Self::TrackRange => f.write_str("tracks outside the waypoint list"),
            Self::ScoreBuffer => f.write_str("score buffer shorter than the tracks simulated"),
            Self::NonFiniteDepth { index } => write!(f, "reference depth {index} is not finite"),
            Self::NonFiniteState => f.write_str("start state is not finite"),
            Self::StateOffTrack => f.write_str("start state is not on the first track"),
            Self::Diverged => f.write_str("simulation diverged"),
            Self::StepLimit => f.write_str("simulation step limit reached"),
            Self::OutOfProfile => f.write_str("simulated position outside the bottom profile"),
        }
    }
}

impl core::error::Error for SimError {}

impl From<WaypointError> for SimError {
    fn from(e: WaypointError) -> Self {
        Self::Waypoints(e)
    }
}

/// Along-track waypoint positions `X_0 < X_1 < … < X_M` (m), at most `W`.
/// Track `i` (0-based) runs from `X_i` to `X_{i+1}`.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Waypoints<const W: usize> {
    x: Vec<f32, W>,
}

impl<const W: usize> Waypoints<W> {
    /// Validates positions `x` (m): at least two, finite, strictly
    /// increasing, at most `W`.
    ///
    /// # Errors
    /// [`WaypointError`] naming the first offending waypoint.
    pub fn new(x: &[f32]) -> Result<Self, WaypointError> {
        const { assert!(W >= 2, "waypoint capacity must be at least 2") };
        if x.len() < 2 {
            return Err(WaypointError::TooFew { len: x.len() });
        }
        let over = WaypointError::OverCapacity {
            len: x.len(),
            capacity: W,
        };
        let mut v = Vec::new();
        let mut last = f32::NEG_INFINITY;
        for (index, &xi) in x.iter().enumerate() {
            if !xi.is_finite() {
                return Err(WaypointError::NonFinite { index });
            }
            if xi <= last {
                return Err(WaypointError::NotIncreasing { index });
            }
            last = xi;
            v.push(xi).map_err(|_| over)?;
        }
        Ok(Self { x: v })
    }

    /// Positions, m.
    pub fn positions(&self) -> &[f32] {
        &self.x
    }

    /// Number of tracks `M` (waypoints − 1).
    pub fn tracks(&self) -> usize {
        self.x.len().saturating_sub(1)
    }
}

/// The vehicle's state at one sample: `(η, d, d_prev, x, I_d, I_θ)` of the
/// contract, plus the previous sample's position `x_prev`, which scoring
/// needs for the piece of a track flown before its first sample.
///
/// Depth and position are kept compensated (see `num::Comp`), so chaining
/// states track after track loses nothing to f32 rounding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VehicleState<const N: usize> {
    pub(crate) eta: SVector<f32, N>,
    pub(crate) depth: Comp,
    pub(crate) depth_prev: Comp,
    pub(crate) x: Comp,
    pub(crate) x_prev: Comp,
    pub(crate) depth_integral: f32,
    pub(crate) pitch_integral: f32,
}

#[cfg(feature = "defmt")]
impl<const N: usize> defmt::Format for VehicleState<N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "VehicleState {{ x: {} m, depth: {} m, eta: {}, I_d: {}, I_theta: {} }}",
            self.x.value(),
            self.depth.value(),
            self.eta.as_slice(),
            self.depth_integral,
            self.pitch_integral
        );
    }
}

impl<const N: usize> VehicleState<N> {
    /// Trimmed level flight at `depth` (m) and position `x` (m): `η = 0`,
    /// integrators zero, `d_prev = d` (contract §7).
    pub fn trimmed(depth: f32, x: f32) -> Self {
        Self {
            eta: SVector::zeros(),
            depth: Comp::new(depth),
            depth_prev: Comp::new(depth),
            x: Comp::new(x),
            x_prev: Comp::new(x),
            depth_integral: 0.0,
            pitch_integral: 0.0,
        }
    }

    /// A state from measurements: plant state `η`, depth and previous
    /// depth (m), position and previous position (m), integrators `I_d`
    /// (m s) and `I_θ` (deg s).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        eta: SVector<f32, N>,
        depth: f32,
        depth_prev: f32,
        x: f32,
        x_prev: f32,
        depth_integral: f32,
        pitch_integral: f32,
    ) -> Self {
        Self {
            eta,
            depth: Comp::new(depth),
            depth_prev: Comp::new(depth_prev),
            x: Comp::new(x),
            x_prev: Comp::new(x_prev),
            depth_integral,
            pitch_integral,
        }
    }

    /// Plant state `η`.
    pub fn eta(&self) -> &SVector<f32, N> {
        &self.eta
    }
    /// Depth `d`, m, positive down.
    pub fn depth(&self) -> f32 {
        self.depth.value()
    }
    /// Depth at the previous sample, m.
    pub fn depth_prev(&self) -> f32 {
        self.depth_prev.value()
    }
    /// Along-track position `x`, m.
    pub fn x(&self) -> f32 {
        self.x.value()
    }
    /// Along-track position at the previous sample, m.
    pub fn x_prev(&self) -> f32 {
        self.x_prev.value()
    }
    /// Depth-loop integral `I_d`, m s.
    pub fn depth_integral(&self) -> f32 {
        self.depth_integral
    }
    /// Pitch-loop integral `I_θ`, deg s.
    pub fn pitch_integral(&self) -> f32 {
        self.pitch_integral
    }

    fn is_finite(&self) -> bool {
        self.eta.iter().all(|v| v.is_finite())
            && [
                self.depth(),
                self.depth_prev(),
                self.x(),
                self.x_prev(),
                self.depth_integral,
                self.pitch_integral,
            ]
            .iter()
            .all(|v| v.is_finite())
    }
}

/// Most steps of one run of the simulation's fast path (see `run`).
const FAST_RUN: f32 = 256.0;

/// One simulated sample, as handed to an observer.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Along-track position, m.
    pub x: f32,
    /// Depth, m, positive down.
    pub depth: f32,
    /// Pitch `θ = C η`, deg, positive nose-up.
    pub pitch: f32,
    /// Pitch rate `q = C A η`, deg/s.
    pub pitch_rate: f32,
    /// Active track (0-based) and reference depth `r_k` (m); `None` at the
    /// final sample, past the last waypoint, where no command is computed.
    pub reference: Option<(usize, f32)>,
    /// The autopilot's command at this sample; `None` at the final sample.
    pub command: Option<Command>,
}

/// Score of one track over `[X_i, X_{i+1}]` (contract §8).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrackScore {
    x_start: f32,
    x_end: f32,
    j: Sum,
    violation: Sum,
    min_altitude: f32,
}

#[cfg(feature = "defmt")]
impl defmt::Format for TrackScore {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "TrackScore {{ x: {}..{} m, J: {} m^3, min_altitude: {} m }}",
            self.x_start,
            self.x_end,
            self.j(),
            self.min_altitude
        );
    }
}

impl TrackScore {
    fn new(x_start: f32, x_end: f32) -> Self {
        Self {
            x_start,
            x_end,
            j: Sum::default(),
            violation: Sum::default(),
            min_altitude: f32::INFINITY,
        }
    }

    /// Start of the track `X_i`, m.
    pub fn x_start(&self) -> f32 {
        self.x_start
    }
    /// End of the track `X_{i+1}`, m.
    pub fn x_end(&self) -> f32 {
        self.x_end
    }
    /// `J = ½ ∫ (d_t − d)² dx` by the clipped trapezoid rule, m³.
    pub fn j(&self) -> f32 {
        self.j.value()
    }
    /// RMS deviation from the target depth `sqrt(2 J / (X_{i+1} − X_i))`, m.
    pub fn rms(&self) -> f32 {
        // √J · √(2 / L): no overflow of `2 J` where `J` is near f32's range.
        libm::sqrtf(self.j()) * libm::sqrtf(2.0 / (self.x_end - self.x_start))
    }
    /// Constraint violation `½ ∫ max(0, h_p − h)² dx` by the same
    /// trapezoid, m³, with `h_p` the scenario's penalty altitude (`h_a`
    /// unless set otherwise); zero when the altitude never drops below
    /// `h_p` at a scored point.
    pub fn violation(&self) -> f32 {
        self.violation.value()
    }
    /// Least altitude above the bottom at the samples on the track and its
    /// clipped end points, m.
    pub fn min_altitude(&self) -> f32 {
        self.min_altitude
    }
    /// `h >= h_a` at every scored point: the track is safe for the model.
    /// (A certifying caller adds its own margin to `h_a`.)
    pub fn is_safe(&self, min_altitude: f32) -> bool {
        self.min_altitude >= min_altitude
    }
}

/// How the per-step cascade and kinematics linearize, for a tangent pass.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepLin {
    /// Index of the active track among the simulated ones.
    pub slot: usize,
    pub command: Command,
    /// `sin θ̄`, `cos θ̄`.
    pub sin: f32,
    pub cos: f32,
}

/// Where one end of a scored piece lies.
#[derive(Clone, Copy, Debug)]
pub(crate) enum EndAt {
    /// At the segment's first sample (`b'` there).
    Start { slope: f32 },
    /// At the segment's second sample.
    End { slope: f32 },
    /// At a fixed waypoint, fraction `t` of the way along the segment.
    Clip { t: f32 },
}

/// One end of a scored piece: where, and its `e = d_t − d` and
/// `p = max(0, h_a − h)` (m).
#[derive(Clone, Copy, Debug)]
pub(crate) struct End {
    pub at: EndAt,
    pub e: f32,
    pub p: f32,
}

/// A scored piece of a segment: its length (m), the segment's `Δx`, `Δd`
/// (m) and its two ends.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PieceLin {
    pub len: f32,
    pub dx: f32,
    pub dd: f32,
    pub lo: End,
    pub hi: End,
}

/// Receives the linearization of a run as it happens.
pub(crate) trait Sensitivity<const N: usize> {
    /// After step `k` has moved the state to sample `k + 1`.
    fn step(&mut self, vehicle: &Vehicle<N>, lin: &StepLin);
    /// After a piece of the newest segment was scored into track `slot`.
    fn piece(&mut self, slot: usize, lin: &PieceLin);
}

/// The plain simulation's hook: does nothing, and compiles to nothing.
pub(crate) struct NoSensitivity;

impl<const N: usize> Sensitivity<N> for NoSensitivity {
    #[inline(always)]
    fn step(&mut self, _: &Vehicle<N>, _: &StepLin) {}
    #[inline(always)]
    fn piece(&mut self, _: usize, _: &PieceLin) {}
}

/// A sample's position and depth, with the bottom under it when scored.
#[derive(Clone, Copy, Debug)]
struct Geo {
    x: Comp,
    d: Comp,
    /// Where the sample is scored (`x <= x_end`): what scoring needs of it.
    at: Option<At>,
    /// `x − x_end`, m: the run ends at the first sample with `past >= 0`.
    past: f32,
}

/// A scored sample: altitude `h`, bottom slope `b'`, `e = h − h_r` and
/// `p = max(0, h_p − h)` (m, m/m, m, m), computed once per sample.
#[derive(Clone, Copy, Debug)]
struct At {
    h: f32,
    slope: f32,
    e: f32,
    p: f32,
}

/// A vehicle flying a line of waypoints over a bottom profile, with the
/// mission's envelope: everything a simulation needs, borrowed.
///
/// `N` is the plant order capacity, `S` the profile capacity, `W` the
/// waypoint capacity.
#[derive(Clone, Debug)]
pub struct Scenario<'a, const N: usize, const S: usize, const W: usize> {
    vehicle: &'a Vehicle<N>,
    profile: &'a Profile<S>,
    waypoints: &'a Waypoints<W>,
    mission: Mission,
    /// Altitude the violation measure is taken against, m (default `h_a`).
    penalty_altitude: f32,
    /// `b(X_i)`, m.
    wp_bottom: Vec<f32, W>,
}

impl<'a, const N: usize, const S: usize, const W: usize> Scenario<'a, N, S, W> {
    /// Binds a vehicle, a profile, waypoints and a mission.
    ///
    /// # Errors
    /// [`WaypointError::OutsideProfile`] when a waypoint lies outside the
    /// profile.
    pub fn new(
        vehicle: &'a Vehicle<N>,
        profile: &'a Profile<S>,
        waypoints: &'a Waypoints<W>,
        mission: Mission,
    ) -> Result<Self, SimError> {
        let mut wp_bottom = Vec::new();
        for (index, &x) in waypoints.positions().iter().enumerate() {
            let b = profile
                .depth_at(x)
                .map_err(|_| WaypointError::OutsideProfile { index })?;
            wp_bottom
                .push(b)
                .map_err(|_| WaypointError::OutsideProfile { index })?;
        }
        Ok(Self {
            vehicle,
            profile,
            waypoints,
            penalty_altitude: mission.min_altitude(),
            mission,
            wp_bottom,
        })
    }

    /// The same scenario with the violation measure
    /// ([`TrackScore::violation`]) taken against `altitude` (m) instead of
    /// `h_a`: a planner penalizes a little above `h_a` to keep a margin.
    pub fn with_penalty_altitude(mut self, altitude: f32) -> Self {
        if altitude.is_finite() {
            self.penalty_altitude = altitude;
        }
        self
    }

    /// The altitude the violation measure is taken against, m.
    pub fn penalty_altitude(&self) -> f32 {
        self.penalty_altitude
    }

    /// The vehicle.
    pub fn vehicle(&self) -> &Vehicle<N> {
        self.vehicle
    }
    /// The bottom profile.
    pub fn profile(&self) -> &Profile<S> {
        self.profile
    }
    /// The waypoints.
    pub fn waypoints(&self) -> &Waypoints<W> {
        self.waypoints
    }
    /// The mission envelope.
    pub fn mission(&self) -> &Mission {
        &self.mission
    }

    /// The default start depth `b(X_0) − h_r`, m (contract §9).
    pub fn default_initial_depth(&self) -> f32 {
        self.wp_bottom.first().copied().unwrap_or(0.0) - self.mission.reference_altitude()
    }

    /// Trimmed level flight at `X_0` and `depth` (m).
    pub fn start_state(&self, depth: f32) -> VehicleState<N> {
        let x0 = self.waypoints.positions().first().copied().unwrap_or(0.0);
        VehicleState::trimmed(depth, x0)
    }

    /// Flies tracks `first_track..first_track + depths.len()` with one
    /// reference depth per track (m) from `start`, scoring each track into
    /// `scores` and handing every sample to `observe`. Returns the state at
    /// the first sample past the last of those tracks.
    ///
    /// # Errors
    /// [`SimError`] for bad arguments or a flight that diverges.
    pub fn simulate<F: FnMut(&Sample)>(
        &self,
        start: &VehicleState<N>,
        first_track: usize,
        depths: &[f32],
        scores: &mut [TrackScore],
        observe: F,
    ) -> Result<VehicleState<N>, SimError> {
        self.run(
            start,
            first_track,
            depths,
            scores,
            &mut NoSensitivity,
            observe,
        )
    }

    /// The one simulation loop; see the module docs.
    #[inline(always)]
    pub(crate) fn run<Sn: Sensitivity<N>, F: FnMut(&Sample)>(
        &self,
        start: &VehicleState<N>,
        first: usize,
        depths: &[f32],
        scores: &mut [TrackScore],
        sens: &mut Sn,
        mut observe: F,
    ) -> Result<VehicleState<N>, SimError> {
        let wp = self.waypoints.positions();
        let last = first
            .checked_add(depths.len())
            .filter(|&l| l > first && l < wp.len())
            .ok_or(SimError::TrackRange)?;
        let x_begin = *wp.get(first).ok_or(SimError::TrackRange)?;
        let x_end = *wp.get(last).ok_or(SimError::TrackRange)?;
        let x_next = *wp
            .get(first.saturating_add(1))
            .ok_or(SimError::TrackRange)?;
        let scores = scores
            .get_mut(..depths.len())
            .ok_or(SimError::ScoreBuffer)?;
        for (i, s) in scores.iter_mut().enumerate() {
            let t = first.saturating_add(i);
            let a = wp.get(t).copied().unwrap_or(0.0);
            let b = wp.get(t.saturating_add(1)).copied().unwrap_or(0.0);
            *s = TrackScore::new(a, b);
        }
        if let Some(index) = depths.iter().position(|z| !z.is_finite()) {
            return Err(SimError::NonFiniteDepth { index });
        }
        self.check_start(start, first)?;

        let plant = self.vehicle.plant();
        let ts = plant.sample_time();
        let step_len = self.vehicle.speed() * ts;
        // Even flying at 75° on average the line would be done by then.
        let max_steps = 4.0 * (x_end - start.x()) / step_len + 100.0;
        // Steps left before the run is declared stuck.
        let mut budget = if max_steps.is_finite() {
            max_steps as u32
        } else {
            u32::MAX
        };

        let mut st = *start;
        let mut cursor = Cursor::default();
        let mut cur = self.geo(&mut cursor, st.x, st.depth, x_end)?;
        // The piece of the first track flown before the start sample.
        if st.x_prev.diff(st.x) < 0.0 {
            let mut c0 = Cursor::default();
            let prev = if st.x_prev.minus(x_begin) >= 0.0 {
                self.geo(&mut c0, st.x_prev, st.depth_prev, x_end)?
            } else {
                Geo {
                    x: st.x_prev,
                    d: st.depth_prev,
                    at: None,
                    past: st.x_prev.minus(x_end),
                }
            };
            self.score(&prev, &cur, first, first, last, scores, sens)?;
        } else if let (Some(a), Some(s)) = (cur.at, scores.first_mut()) {
            s.min_altitude = min(s.min_altitude, a.h);
        }

        let mut track = first;
        // X_{track+1}: where the active track ends.
        let mut track_end = x_next;
        // θ_k: computed once per step, as θ_{k+1} of the step before.
        let mut pitch = plant.pitch(&st.eta);
        let mut rise = st.depth.diff(st.depth_prev);
        let h_r = self.mission.reference_altitude();
        let h_p = self.penalty_altitude;
        loop {
            // A sample whose step needs the general treatment: the end of
            // the run, a waypoint switch, a new bottom segment, a sample
            // not scored.
            if cur.past >= 0.0 {
                observe(&Sample {
                    x: st.x(),
                    depth: st.depth(),
                    pitch,
                    pitch_rate: plant.pitch_rate(&st.eta),
                    reference: None,
                    command: None,
                });
                break;
            }
            while track.saturating_add(1) < last && st.x.minus(track_end) >= 0.0 {
                track = track.saturating_add(1);
                track_end = *wp
                    .get(track.saturating_add(1))
                    .ok_or(SimError::TrackRange)?;
            }
            let slot = track.saturating_sub(first);
            let r = *depths.get(slot).ok_or(SimError::TrackRange)?;

            // The fast path: from a scored sample inside the track, as long
            // as each new sample lands short of `fast_limit` it lies on the
            // active track, before the line's end and on the bottom segment
            // the cursor holds, and the segment it ends is scored wholly
            // into this track, with its running score kept in registers.
            // The limit is a few ulps and a millimetre short of the next
            // event, so that its plain f32 compare never decides a case the
            // exact (compensated) tests would decide otherwise.
            if let Some(mut a0) = cur.at
                && st.x.minus(track_end) < 0.0
            {
                // A run is also cut after about `FAST_RUN` steps, so that
                // its plain partial sum of `J` (added to the track's
                // compensated sum when the run ends) adds up at most that
                // many terms: relative error below `FAST_RUN` ε/2.
                let horizon = st.x.value() + FAST_RUN * self.vehicle.speed() * ts;
                let event = min(min(track_end, cursor.end()), horizon);
                let fast_limit = event - (1e-3 + 4.0 * f32::EPSILON * libm::fabsf(event));
                let score = scores.get_mut(slot).ok_or(SimError::ScoreBuffer)?;
                let mut acc = *score;
                let mut j_run = 0.0_f32;
                let mut e2 = a0.e * a0.e;
                let mut guard = if a0.p > 0.0 {
                    f32::INFINITY
                } else {
                    max(acc.min_altitude, h_p)
                };
                let mut fast = false;
                loop {
                    let Some(left) = budget.checked_sub(1) else {
                        acc.j.add(0.25 * j_run);
                        *score = acc;
                        return Err(SimError::StepLimit);
                    };
                    budget = left;
                    let (dx, dd) = match self.advance(
                        &mut st,
                        &mut pitch,
                        &mut rise,
                        r,
                        track,
                        slot,
                        sens,
                        &mut observe,
                    ) {
                        Ok(v) => v,
                        Err(e) => {
                            acc.j.add(0.25 * j_run);
                            *score = acc;
                            return Err(e);
                        }
                    };
                    // (NaN leaves the fast path too.)
                    if st.x.value().partial_cmp(&fast_limit) != Some(core::cmp::Ordering::Less) {
                        break;
                    }
                    fast = true;
                    // Δx and Δd are the step's exact increments; the new
                    // sample is on the cursor's segment: no lookup.
                    let p1 = cursor.point(st.x);
                    let h = p1.altitude(st.depth);
                    let e = h - h_r;
                    let mut a1 = At {
                        h,
                        slope: p1.slope,
                        e,
                        p: 0.0,
                    };
                    let e2_next = e * e;
                    // (The trapezoid's ¼ is applied to the run's sum: a
                    // power of two, so exactly the same.)
                    j_run += dx * (e2 + e2_next);
                    // One compare in the common case: a sample at or above
                    // `guard` sets no new minimum and does not violate, and
                    // `guard` is +inf after a violating sample, so that the
                    // violation's next trapezoid is taken here too.
                    if h.partial_cmp(&guard)
                        .is_none_or(|o| o == core::cmp::Ordering::Less)
                    {
                        let pen = h_p - h;
                        a1.p = if pen > 0.0 { pen } else { 0.0 };
                        if a0.p > 0.0 || a1.p > 0.0 {
                            acc.violation.add(0.25 * dx * (a0.p * a0.p + a1.p * a1.p));
                        }
                        // The segment's first sample was counted as the
                        // last one's end.
                        acc.min_altitude = min(acc.min_altitude, h);
                        guard = if a1.p > 0.0 {
                            f32::INFINITY
                        } else {
                            max(acc.min_altitude, h_p)
                        };
                    }
                    sens.piece(
                        slot,
                        &PieceLin {
                            len: dx,
                            dx,
                            dd,
                            lo: End {
                                at: EndAt::Start { slope: a0.slope },
                                e: a0.e,
                                p: a0.p,
                            },
                            hi: End {
                                at: EndAt::End { slope: a1.slope },
                                e,
                                p: a1.p,
                            },
                        },
                    );
                    e2 = e2_next;
                    a0 = a1;
                }
                acc.j.add(0.25 * j_run);
                *score = acc;
                if fast {
                    // The sample before the one that left the fast path.
                    cur = Geo {
                        x: st.x_prev,
                        d: st.depth_prev,
                        at: Some(a0),
                        past: -1.0,
                    };
                }
            } else {
                budget = budget.checked_sub(1).ok_or(SimError::StepLimit)?;
                self.advance(
                    &mut st,
                    &mut pitch,
                    &mut rise,
                    r,
                    track,
                    slot,
                    sens,
                    &mut observe,
                )?;
            }
            // The step just taken, the general way.
            let prev = cur;
            cur = self.geo(&mut cursor, st.x, st.depth, x_end)?;
            self.score(&prev, &cur, track, first, last, scores, sens)?;
        }
        // Finite inputs of absurd magnitude (a bottom 10¹⁸ m down) can
        // overflow `J` or the violation: never hand out a non-finite score.
        if scores.iter().any(|s| {
            !(s.min_altitude.is_finite() && s.j().is_finite() && s.violation().is_finite())
        }) {
            return Err(SimError::Diverged);
        }
        // An absurd but finite reference (10³⁸ m) can drive an integrator
        // out of range without upsetting the flight, which the clamps keep
        // finite: the end state, handed out, must be finite. (Position and
        // depth are, or the flight would have failed.)
        if !(st.depth_integral.is_finite()
            && st.pitch_integral.is_finite()
            && st.eta.iter().all(|v| v.is_finite()))
        {
            return Err(SimError::Diverged);
        }
        Ok(st)
    }

    /// Whether `start` can start a run on track `first`: finite, and at
    /// `X_first <= x < X_first+1`.
    ///
    /// # Errors
    /// [`SimError::TrackRange`], [`SimError::NonFiniteState`] or
    /// [`SimError::StateOffTrack`].
    pub(crate) fn check_start(
        &self,
        start: &VehicleState<N>,
        first: usize,
    ) -> Result<(), SimError> {
        let wp = self.waypoints.positions();
        let x_begin = *wp.get(first).ok_or(SimError::TrackRange)?;
        let x_next = *wp
            .get(first.saturating_add(1))
            .ok_or(SimError::TrackRange)?;
        if !start.is_finite() {
            return Err(SimError::NonFiniteState);
        }
        if !(start.x.minus(x_begin) >= 0.0 && start.x.minus(x_next) < 0.0) {
            return Err(SimError::StateOffTrack);
        }
        Ok(())
    }

    /// One step of the loop (contract §7, steps 2–5) from `st`, whose pitch
    /// `θ_k` is `pitch` and depth change `d_k − d_{k−1}` is `rise`, on
    /// reference `r` of `track`: the cascade, the plant, the kinematics.
    /// Updates `st`, `pitch` and `rise` to sample `k + 1`,
    /// hands sample `k` to `observe` and the linearization to `sens`;
    /// returns the increments `(Δx, Δd)`, m.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn advance<Sn: Sensitivity<N>, F: FnMut(&Sample)>(
        &self,
        st: &mut VehicleState<N>,
        pitch: &mut f32,
        rise: &mut f32,
        r: f32,
        track: usize,
        slot: usize,
        sens: &mut Sn,
        observe: &mut F,
    ) -> Result<(f32, f32), SimError> {
        let plant = self.vehicle.plant();
        let ts = plant.sample_time();
        let pitch_rate = plant.pitch_rate(&st.eta);
        let e_d = -st.depth.minus(r);
        // `d_k − d_{k−1}` is the last step's `Δd`: `depth` was `depth_prev`
        // plus it, exactly to the rounding of the compensation term.
        let depth_rate = *rise / ts;
        let command = self.vehicle.autopilot().cascade(
            &mut st.depth_integral,
            &mut st.pitch_integral,
            e_d,
            depth_rate,
            *pitch,
            pitch_rate,
        );
        observe(&Sample {
            x: st.x(),
            depth: st.depth(),
            pitch: *pitch,
            pitch_rate,
            reference: Some((track, r)),
            command: Some(command),
        });
        let eta = plant.step(&st.eta, command.elevator);
        let pitch_next = plant.pitch(&eta);
        let mean = (*pitch + pitch_next) * (0.5 * DEG);
        // A cruising vehicle's mean pitch is within ±45°: the short
        // polynomials, whose results are finite with `cos > 0`. Beyond (or
        // NaN, from a diverging loop), the checked general case.
        let abs = libm::fabsf(mean);
        let (sin, cos) = if abs <= crate::num::SHORT {
            crate::num::sin_cos_short(mean)
        } else {
            // Inline, not a call: a call in the loop would cost register
            // spills on every step.
            let (sin, cos) = crate::num::sin_cos_long(mean);
            // Beyond ±90° (or NaN) the vehicle flies backwards: the loop
            // has diverged. (NaN fails the compare too.)
            if !(abs <= core::f32::consts::FRAC_PI_2 && cos > 0.0) {
                return Err(SimError::Diverged);
            }
            (sin, cos)
        };
        // With `r`, `d` and `Δd` finite, `e_d` and so `I_d` are.
        let step_len = self.vehicle.speed() * ts;
        let dx = step_len * cos;
        let dd = -step_len * sin;
        st.eta = eta;
        *pitch = pitch_next;
        st.depth_prev = st.depth;
        st.x_prev = st.x;
        st.depth = st.depth.add(dd);
        st.x = st.x.add(dx);
        *rise = dd;
        sens.step(
            self.vehicle,
            &StepLin {
                slot,
                command,
                sin,
                cos,
            },
        );
        Ok((dx, dd))
    }

    /// A sample's geometry; the bottom is looked up only where scoring
    /// needs it (`x <= x_end`), since the last sample may lie past the
    /// profile.
    #[inline]
    fn geo(&self, cursor: &mut Cursor, x: Comp, d: Comp, x_end: f32) -> Result<Geo, SimError> {
        let past = x.minus(x_end);
        let at = if past <= 0.0 {
            let p: Point = self
                .profile
                .locate(cursor, x)
                .ok_or(SimError::OutOfProfile)?;
            let h = p.altitude(d);
            let End { e, p: pen, .. } = self.end(EndAt::Clip { t: 0.0 }, h);
            Some(At {
                h,
                slope: p.slope,
                e,
                p: pen,
            })
        } else {
            None
        };
        Ok(Geo { x, d, at, past })
    }

    /// Scores segment `s0 → s1`, flown from track `track`, into every track
    /// of `first..last` it overlaps, clipping at the waypoints (§8).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn score<Sn: Sensitivity<N>>(
        &self,
        s0: &Geo,
        s1: &Geo,
        track: usize,
        first: usize,
        last: usize,
        scores: &mut [TrackScore],
        sens: &mut Sn,
    ) -> Result<(), SimError> {
        let wp = self.waypoints.positions();
        let dx = s1.x.diff(s0.x);
        let dd = s1.d.diff(s0.d);
        let mut t = track.max(first);
        while t < last {
            let next = t.saturating_add(1);
            let (Some(&a), Some(&b)) = (wp.get(t), wp.get(next)) else {
                return Err(SimError::TrackRange);
            };
            if s1.x.minus(a) <= 0.0 {
                break;
            }
            let lo = if s0.x.minus(a) >= 0.0 {
                self.sample_end(s0, true)?
            } else {
                self.clip_end(s0, dx, dd, t)?
            };
            let ends_here = s1.x.minus(b) <= 0.0;
            let hi = if ends_here {
                self.sample_end(s1, false)?
            } else {
                self.clip_end(s0, dx, dd, next)?
            };
            let len = match (lo.0.at, hi.0.at) {
                (EndAt::Start { .. }, EndAt::End { .. }) => dx,
                (EndAt::Clip { .. }, EndAt::End { .. }) => s1.x.minus(a),
                (EndAt::Start { .. }, _) => -s0.x.minus(b),
                _ => b - a,
            };
            let slot = t.saturating_sub(first);
            let s = scores.get_mut(slot).ok_or(SimError::ScoreBuffer)?;
            let (lo, h_lo) = lo;
            let (hi, h_hi) = hi;
            // The constraint holds at the end points too, even of a piece
            // of zero length (a sample exactly on a waypoint).
            s.min_altitude = min(min(s.min_altitude, h_lo), h_hi);
            if len > 0.0 {
                s.j.add(0.25 * len * (lo.e * lo.e + hi.e * hi.e));
                // Most pieces keep clear of the penalty altitude.
                if lo.p > 0.0 || hi.p > 0.0 {
                    s.violation.add(0.25 * len * (lo.p * lo.p + hi.p * hi.p));
                }
                sens.piece(
                    slot,
                    &PieceLin {
                        len,
                        dx,
                        dd,
                        lo,
                        hi,
                    },
                );
            }
            if ends_here {
                break;
            }
            t = next;
        }
        Ok(())
    }

    /// A piece end at one of the segment's samples, with its altitude.
    #[inline]
    fn sample_end(&self, s: &Geo, first: bool) -> Result<(End, f32), SimError> {
        let a = s.at.ok_or(SimError::OutOfProfile)?;
        let at = if first {
            EndAt::Start { slope: a.slope }
        } else {
            EndAt::End { slope: a.slope }
        };
        Ok((End { at, e: a.e, p: a.p }, a.h))
    }

    /// A piece end clipped at waypoint `i`, depth interpolated in `x`.
    #[inline]
    fn clip_end(&self, s0: &Geo, dx: f32, dd: f32, i: usize) -> Result<(End, f32), SimError> {
        let c = *self
            .waypoints
            .positions()
            .get(i)
            .ok_or(SimError::TrackRange)?;
        let b = *self.wp_bottom.get(i).ok_or(SimError::TrackRange)?;
        let t = -s0.x.minus(c) / dx;
        let h = -s0.d.minus(b) - dd * t;
        Ok((self.end(EndAt::Clip { t }, h), h))
    }

    #[inline(always)]
    fn end(&self, at: EndAt, h: f32) -> End {
        End {
            at,
            e: h - self.mission.reference_altitude(),
            p: {
                let p = self.penalty_altitude - h;
                if p > 0.0 { p } else { 0.0 }
            },
        }
    }
}
