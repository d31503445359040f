//! Optimal maneuver-based navigation for cruising AUVs.
//!
//! An AUV flying a survey line close to steep seafloor plans the reference
//! depth of its next waypoint by simulating its own closed loop — identified
//! pitch dynamics and the autopilot's PID cascade, exactly as they run —
//! over the mapped bottom, and optimizing the depths so that the flight
//! tracks the bottom at a reference altitude `h_r` without going below a
//! minimum altitude `h_a`.
//!
//! `#![no_std]`, no allocation, no `unsafe`, no panics; f32 throughout, the
//! same code on the host and on a Cortex-M4F.
//!
//! # The data flow, module by module
//!
//! 1. [`profile`] — the bottom under the track: a bounded array of
//!    along-track samples, linearly interpolated, never extrapolated.
//! 2. [`plant`] and [`expm`] — the pitch transfer function `θ/δ` (or the
//!    paper's `q/δ`), realized in controllable canonical form and discretized
//!    by an exact zero-order hold computed in f32.
//! 3. [`autopilot`] — the depth → pitch → elevator PID cascade, configuration
//!    apart from state, usable as the real autopilot's loop.
//! 4. [`vehicle`] — speed, sample time, plant and autopilot validated
//!    together ([`Vehicle`]); the mission's altitudes and depth limits
//!    ([`Mission`]).
//! 5. [`sim`] — a [`Scenario`] (vehicle, profile, [`Waypoints`], mission)
//!    flies tracks from a [`VehicleState`], switching the reference at the
//!    first sample past each waypoint, and scores each track as it goes:
//!    `J = ½ ∫ (d_t − d)² dx` by the clipped trapezoid rule, RMS deviation,
//!    minimum altitude, violation of `h ≥ h_a` ([`TrackScore`]).
//! 6. [`gradient`] — the same pass with tangent states gives the exact
//!    gradient of `J` and of the violation with respect to the next `K`
//!    reference depths ([`Evaluation`]).
//! 7. [`optim`] — allocation-free gradient descent and dense BFGS with an
//!    Armijo line search, on a box.
//! 8. [`planner`] — the main entry point: a [`Planner`] takes the vehicle
//!    state at the start of the next track and returns that track's
//!    reference depth ([`Plan`]), verified safe by simulation or flagged
//!    [`PlanStatus::SafeFallback`] / [`PlanStatus::Infeasible`].
//!
//! Shapes are const generics: `N` the plant order capacity, `S` the profile
//! capacity, `W` the waypoint capacity, `K` the number of depths optimized
//! jointly. Values are validated at run time: every constructor returns a
//! typed error ([`ProfileError`], [`PlantError`], [`ConfigError`],
//! [`WaypointError`], [`SimError`], or the umbrella [`Error`]), and nothing
//! non-finite leaves the library.
//!
//! # Example
//!
//! ```
//! use auvnav::{Mission, Profile, Scenario, TrackScore, Vehicle, Waypoints};
//!
//! let vehicle = Vehicle::c_auv4()?;
//! let bottom = Profile::<64>::new(&[0.0, 400.0, 800.0], &[500.0, 450.0, 440.0])?;
//! let wps = Waypoints::<4>::new(&[0.0, 400.0, 800.0])?;
//! let line = Scenario::new(&vehicle, &bottom, &wps, Mission::default())?;
//! let start = line.start_state(line.default_initial_depth()); // 420 m
//! let e = line.evaluate::<2>(&start, 0, &[375.0, 360.0])?;
//! assert!(e.min_altitude > 60.0);
//! // Going deeper on track 1 brings the flight closer to the target.
//! assert!(e.grad_j[0] < 0.0);
//! # Ok::<(), auvnav::Error>(())
//! ```
#![no_std]
#![cfg_attr(test, allow(clippy::float_cmp, clippy::arithmetic_side_effects))]

pub mod autopilot;
pub mod error;
pub mod expm;
pub mod gradient;
mod log;
mod num;
pub mod optim;
pub mod planner;
pub mod plant;
pub mod profile;
pub mod sim;
pub mod vehicle;

pub use autopilot::{Autopilot, AutopilotConfig, AutopilotState, Command, PidGains, PidTerms};
pub use error::{ConfigError, Error};
pub use gradient::Evaluation;
pub use planner::{Method, Mode, Plan, PlanError, PlanStatus, Planner, PlannerConfig};
pub use plant::{Plant, PlantError, TfKind, TransferFunction};
pub use profile::{Profile, ProfileError};
pub use sim::{Sample, Scenario, SimError, TrackScore, VehicleState, WaypointError, Waypoints};
pub use vehicle::{MIN_STEP_LENGTH, Mission, Vehicle, VehicleConfig};

/// The README's examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
