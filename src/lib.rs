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
//! # The data flow, folder by folder
//!
//! ```text
//!  model/   profile, waypoints ─┐
//!           plant (ZOH), autopilot, vehicle, mission
//!              │
//!  sim/     Scenario ─► run (one step in the contract's order) ─► score (J, V, h_min)
//!              │                        └─► tangent (∂J/∂z, same pass)
//!  optim/   GD, BFGS + Armijo, root search  (arrays in, arrays out)
//!              │
//!  plan/    Planner: box, scan, solve, verify, fallback ─► Plan (depth, status, …)
//! ```
//!
//! 1. [`model`] — the vehicle and its world: the bottom under the track
//!    ([`Profile`], never extrapolated), the line ([`Waypoints`]), the pitch
//!    transfer function `θ/δ` (or the paper's `q/δ`) realized in
//!    observability canonical form and discretized by an exact
//!    zero-order hold computed in f32 ([`Plant`]), the depth → pitch →
//!    elevator PID cascade ([`Autopilot`], usable as the real autopilot's
//!    loop), validated together ([`Vehicle`]), and the mission's envelope
//!    ([`Mission`]).
//! 2. [`sim`] — a [`Scenario`] (vehicle, profile, waypoints, mission) flies
//!    tracks from a [`VehicleState`], switching the reference at the first
//!    sample past each waypoint, and scores each track as it goes:
//!    `J = ½ ∫ (d_t − d)² dx` by the clipped trapezoid rule, RMS deviation,
//!    minimum altitude, violation of `h ≥ h_a` ([`TrackScore`]); the same
//!    pass with tangent states gives their exact gradients with respect to
//!    the next `K` reference depths ([`Evaluation`]).
//! 3. [`optim`] — allocation-free gradient descent and dense BFGS with an
//!    Armijo line search, on a box.
//! 4. [`plan`] — the main entry point: a [`Planner`] takes the vehicle
//!    state at the start of the next track and returns that track's
//!    reference depth ([`Plan`]): in horizon mode committed only with a
//!    continuation to the end of the line certified in every world of the
//!    mission's declared [`Uncertainty`] ([`PlanStatus::Optimal`],
//!    [`PlanStatus::Constrained`]), or flagged [`PlanStatus::Infeasible`]
//!    by the first call that finds none.
//!
//! The model's equations, units and step order are in the repository's
//! `docs/model.md`, in this crate's words.
//!
//! Shapes are const generics: `N` the plant order capacity, `S` the profile
//! capacity and `W` the waypoint capacity (erased once a [`Scenario`] is
//! bound: it holds [`ProfileView`] and [`WaypointsView`]), `K` the number of
//! depths optimized jointly. Values are validated at run time: every
//! constructor returns a typed, `#[non_exhaustive]` error
//! ([`ProfileError`], [`PlantError`], [`ConfigError`], [`WaypointError`],
//! [`SimError`], [`PlanError`], or the umbrella [`Error`]), and nothing
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

pub mod error;
mod log;
pub mod model;
mod num;
pub mod optim;
pub mod plan;
pub mod sim;

pub use error::Error;
pub use model::{
    Autopilot, AutopilotConfig, AutopilotState, Command, ConfigError, LoopInput, LoopOutput,
    LoopState, MIN_STEP_LENGTH, Mission, PidGains, PidTerms, Plant, PlantError, Profile,
    ProfileError, ProfileView, TfKind, TransferFunction, Uncertainty, Vehicle, VehicleConfig,
    WaypointError, Waypoints, WaypointsView, lower_envelope,
};
pub use plan::{
    Method, Mode, OptimizerStop, Plan, PlanConfigError, PlanError, PlanStatus, Planner,
    PlannerConfig, Resumable, Step,
};
pub use sim::{
    Evaluation, Measurement, Sample, Scenario, SimError, TrackScore, VehicleState, World,
};

/// The README's examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
