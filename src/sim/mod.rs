//! Closed-loop simulation of the vehicle flying its next tracks (model
//! contract §3, §6, §7), scored as it goes (§8), with the exact gradient
//! of the scores in the same pass.
//!
//! | file | concern |
//! |---|---|
//! | `mod.rs` | [`Scenario`]: a vehicle, a bottom, waypoints and a mission, bound |
//! | `state.rs` | [`VehicleState`], [`Sample`] |
//! | `run.rs` | the loop: one step in the contract's order, the fast in-segment path |
//! | `score.rs` | [`TrackScore`] and the one scoring kernel |
//! | `lin.rs` | what a step and a scored piece linearize to |
//! | `tangent.rs` | tangent states: [`Evaluation`], `∂J/∂z` by forward sensitivity |
//! | `column.rs` | one tangent column: its step, its sleep where the step is the identity, the pieces it scores |
//! | `watch.rs` | what a tangent pass records for the SQP: segments' least altitudes, Gauss–Newton |
//! | `estimate.rs` | [`Measurement`]; the start state from what the vehicle measures |
//! | `switch.rs` | a track flown with its waypoint switch one sample the other way |
//! | `world.rs` | [`World`]: true speed, flight-path offset, vertical current |
//! | `error.rs` | [`SimError`] |
//! | `rng.rs` | (tests only) the randomized tests' generator |

mod column;
mod error;
mod estimate;
mod fast;
mod lin;
#[cfg(test)]
mod rng;
mod run;
mod score;
mod state;
mod switch;
mod tangent;
mod watch;
mod world;

pub use error::SimError;
pub use estimate::Measurement;
pub use score::TrackScore;
pub use state::{Sample, VehicleState};
pub(crate) use switch::{EDGE, offset};
pub use tangent::Evaluation;
pub(crate) use watch::Watch;
pub use world::{MAX_WORLDS, World};

use world::Kinematics;

use crate::model::{
    Mission, Profile, ProfileView, Vehicle, WaypointError, Waypoints, WaypointsView,
};

/// A vehicle flying a line of waypoints over a bottom profile, with the
/// mission's envelope: everything a simulation needs, borrowed. Small and
/// `Copy`: the profile and the waypoints are held as capacity-erased views,
/// so only the plant order `N` appears in the type.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Scenario<'a, const N: usize> {
    vehicle: &'a Vehicle<N>,
    profile: ProfileView<'a>,
    waypoints: WaypointsView<'a>,
    mission: Mission,
    /// Altitude the violation measure is taken against, m (default `h_a`).
    penalty_altitude: f32,
    /// The world's kinematics (nominal unless [`Scenario::in_world`]).
    kin: Kinematics,
    /// The bottom a planner certifies over (see
    /// [`Scenario::with_certification_bottom`]).
    certification: Option<ProfileView<'a>>,
}

impl<'a, const N: usize> Scenario<'a, N> {
    /// Binds a vehicle, a profile, waypoints and a mission. The capacities
    /// `S` and `W` of the profile and the waypoints are inferred and
    /// erased.
    ///
    /// # Errors
    /// [`WaypointError::OutsideProfile`] when a waypoint lies outside the
    /// profile.
    pub fn new<const S: usize, const W: usize>(
        vehicle: &'a Vehicle<N>,
        profile: &'a Profile<S>,
        waypoints: &'a Waypoints<W>,
        mission: Mission,
    ) -> Result<Self, SimError> {
        Self::from_views(vehicle, profile.view(), waypoints.view(), mission)
    }

    /// [`Scenario::new`] from views (e.g. of `static` arrays validated by
    /// [`ProfileView::new`]).
    ///
    /// # Errors
    /// [`WaypointError::OutsideProfile`] when a waypoint lies outside the
    /// profile.
    pub fn from_views(
        vehicle: &'a Vehicle<N>,
        profile: ProfileView<'a>,
        waypoints: WaypointsView<'a>,
        mission: Mission,
    ) -> Result<Self, SimError> {
        for (index, &x) in waypoints.positions().iter().enumerate() {
            profile
                .depth_at(x)
                .map_err(|_| WaypointError::OutsideProfile { index })?;
        }
        let kin = World::nominal(vehicle).kinematics(vehicle.sample_time());
        Ok(Self {
            vehicle,
            profile,
            waypoints,
            penalty_altitude: mission.min_altitude(),
            mission,
            kin,
            certification: None,
        })
    }

    /// The same scenario with the bottom a planner certifies its plans
    /// over under the mission's declared map uncertainty: the map's lower
    /// envelope ([`crate::model::lower_envelope`]).
    ///
    /// # Errors
    /// [`WaypointError::OutsideProfile`] when a waypoint lies outside
    /// `bottom`.
    pub fn with_certification_bottom(mut self, bottom: ProfileView<'a>) -> Result<Self, SimError> {
        for (index, &x) in self.waypoints.positions().iter().enumerate() {
            bottom
                .depth_at(x)
                .map_err(|_| WaypointError::OutsideProfile { index })?;
        }
        self.certification = Some(bottom);
        Ok(self)
    }

    /// The certification bottom, if given.
    pub fn certification_bottom(&self) -> Option<ProfileView<'a>> {
        self.certification
    }

    /// The same line flown in `world` over `bottom` (e.g. the
    /// certification bottom of [`crate::model::lower_envelope`]): the
    /// scores are then the world's, against the true bottom.
    ///
    /// # Errors
    /// [`WaypointError::OutsideProfile`] when a waypoint lies outside
    /// `bottom`.
    pub fn in_world(&self, world: &World, bottom: ProfileView<'a>) -> Result<Self, SimError> {
        let mut sc = Self::from_views(self.vehicle, bottom, self.waypoints, self.mission)?;
        sc.penalty_altitude = self.penalty_altitude;
        sc.kin = world.kinematics(self.vehicle.sample_time());
        Ok(sc)
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
    pub fn profile(&self) -> ProfileView<'a> {
        self.profile
    }

    /// The waypoints.
    pub fn waypoints(&self) -> WaypointsView<'a> {
        self.waypoints
    }

    /// The mission envelope.
    pub fn mission(&self) -> &Mission {
        &self.mission
    }

    /// The default start depth `b(X_0) − h_r`, m (contract §9).
    pub fn default_initial_depth(&self) -> f32 {
        let x0 = self.waypoints.positions().first().copied().unwrap_or(0.0);
        self.profile.depth_at(x0).unwrap_or(0.0) - self.mission.reference_altitude()
    }

    /// Trimmed level flight at `X_0` and `depth` (m).
    pub fn start_state(&self, depth: f32) -> VehicleState<N> {
        let x0 = self.waypoints.positions().first().copied().unwrap_or(0.0);
        VehicleState::trimmed(depth, x0)
    }
}
