//! The vehicle and its world, as the planner models them: the bottom under
//! the track, the line of waypoints, the identified pitch dynamics, the
//! autopilot's PID cascade, and the mission's envelope. Everything here is
//! configuration (validated, `Copy` where small) or a pure function of it;
//! nothing here flies.
//!
//! | file | concern |
//! |---|---|
//! | `profile.rs` | [`Profile`] / [`ProfileView`]: `b(x)`, linear, never extrapolated |
//! | `line.rs` | [`Waypoints`] / [`WaypointsView`]: `X_0 < … < X_M` |
//! | `plant.rs`, `expm.rs` | [`TransferFunction`] → [`Plant`]: realization and exact ZOH in f32 |
//! | `autopilot.rs` | [`Autopilot`]: the depth → pitch → elevator cascade, the one statement of the control law |
//! | `engage.rs` | [`Autopilot::step`]: the firmware loop around the cascade: hold, non-finite hold, bumpless re-engage ([`LoopState`]) |
//! | `vehicle.rs` | [`Vehicle`]: speed, sample time, plant and autopilot validated together, with the stability check |
//! | `mission.rs` | [`Mission`]: `h_r`, `h_a`, depth limits, declared uncertainty |
//! | `uncertainty.rs` | [`Uncertainty`] and the certification bottom [`lower_envelope`] |
//! | `check.rs` | [`ConfigError`] and the validators every constructor uses |

mod autopilot;
mod check;
mod engage;
mod expm;
mod line;
mod mission;
mod plant;
mod profile;
mod uncertainty;
mod vehicle;

pub use autopilot::{Autopilot, AutopilotConfig, AutopilotState, Command, PidGains, PidTerms};
pub use check::ConfigError;
pub use engage::{LoopInput, LoopOutput, LoopState};
pub use line::{WaypointError, Waypoints, WaypointsView};
pub use mission::Mission;
pub use plant::{Plant, PlantError, TfKind, TransferFunction};
pub use profile::{Profile, ProfileError, ProfileView};
pub use uncertainty::{Uncertainty, lower_envelope};
pub use vehicle::{MIN_STEP_LENGTH, Vehicle, VehicleConfig};

pub(crate) use profile::{Cursor, Point};
