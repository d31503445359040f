//! The survey line: along-track waypoint positions, validated.

use core::fmt;

use heapless::Vec;

/// Why waypoints were rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
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

    /// The capacity-erased view a [`crate::sim::Scenario`] holds.
    pub fn view(&self) -> WaypointsView<'_> {
        WaypointsView { x: &self.x }
    }
}

/// A borrowed, capacity-erased view of validated waypoints: what a
/// [`crate::sim::Scenario`] holds, whatever the capacity `W` of the
/// [`Waypoints`] it came from.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WaypointsView<'a> {
    x: &'a [f32],
}

impl<'a> WaypointsView<'a> {
    /// Positions, m.
    pub fn positions(&self) -> &'a [f32] {
        self.x
    }

    /// Number of tracks `M` (waypoints − 1).
    pub fn tracks(&self) -> usize {
        self.x.len().saturating_sub(1)
    }
}
