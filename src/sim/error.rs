//! Why a simulation could not run or did not finish.

use core::fmt;

use crate::model::WaypointError;

/// Why a simulation could not run or did not finish.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum SimError {
    /// The waypoints were rejected.
    Waypoints(WaypointError),
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
    /// Not a simulation failure: the planner refused the flight because
    /// its call's flight budget was spent (internal to the planner, which
    /// then commits its fallback; never returned by a simulation).
    FlightBudget,
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Waypoints(e) => e.fmt(f),
            Self::TrackRange => f.write_str("tracks outside the waypoint list"),
            Self::ScoreBuffer => f.write_str("score buffer shorter than the tracks simulated"),
            Self::NonFiniteDepth { index } => write!(f, "reference depth {index} is not finite"),
            Self::NonFiniteState => f.write_str("start state is not finite"),
            Self::StateOffTrack => f.write_str("start state is not on the first track"),
            Self::Diverged => f.write_str("simulation diverged"),
            Self::StepLimit => f.write_str("simulation step limit reached"),
            Self::OutOfProfile => f.write_str("simulated position outside the bottom profile"),
            Self::FlightBudget => f.write_str("the planner's flight budget is spent"),
        }
    }
}

impl core::error::Error for SimError {}

impl From<WaypointError> for SimError {
    fn from(e: WaypointError) -> Self {
        Self::Waypoints(e)
    }
}
