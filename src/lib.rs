//! Optimal maneuver-based navigation for cruising AUVs.
//!
//! (Crate documentation is being written; see README.md.)
#![no_std]
#![cfg_attr(test, allow(clippy::float_cmp))]

pub mod autopilot;
pub mod error;
pub mod expm;
pub mod gradient;
mod num;
pub mod plant;
pub mod profile;
pub mod sim;
pub mod vehicle;

pub use autopilot::{Autopilot, AutopilotConfig, AutopilotState, Command, PidGains, PidTerms};
pub use error::{ConfigError, Error};
pub use gradient::Evaluation;
pub use plant::{Plant, PlantError, TfKind, TransferFunction};
pub use profile::{Profile, ProfileError};
pub use sim::{Sample, Scenario, SimError, TrackScore, VehicleState, WaypointError, Waypoints};
pub use vehicle::{Mission, Vehicle, VehicleConfig};
