//! The planner's answer for one track: small and `Copy`, so a firmware
//! task can hand it on by value. The whole horizon and the optimizer's
//! history stay in the caller-owned [`crate::Planner`]
//! ([`crate::Planner::horizon`], [`crate::Planner::history`]).

use crate::sim::VehicleState;

use super::{OptimizerStop, PlanStatus};

/// The planner's answer for one track.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Plan<const N: usize> {
    /// Reference depth to command on the track, m.
    pub depth: f32,
    /// What the plan is: optimal, constrained, or infeasible.
    pub status: PlanStatus,
    /// Why the optimizer stopped (a diagnostic, apart from the status).
    pub optimizer: OptimizerStop,
    /// Certified safe: in every declared world (model contract §12; the
    /// nominal model when nothing is declared) the minimum altitude is at
    /// least `h_a` plus the safety margin on this track and, in horizon
    /// mode, with [`crate::Planner::continuation`] to the end of the line
    /// (§11). Constrained, with one vehicle world, where an earlier
    /// committed track ended on its waypoint's knife edge, from the state
    /// the other switch reaches too (`knife.rs`).
    pub safe: bool,
    /// Predicted `J` of the track flown at [`Plan::depth`], m³.
    pub j: f32,
    /// Predicted RMS deviation from the target depth, m.
    pub rms: f32,
    /// Predicted minimum altitude on the track (nominal model and map), m.
    pub min_altitude: f32,
    /// Least altitude on the track over the declared worlds, m (equal to
    /// [`Plan::min_altitude`] when nothing is declared).
    pub certified_min_altitude: f32,
    /// The optimizer's final objective (`Σ J + μ Σ V` over the horizon), m³.
    pub objective: f32,
    /// Optimizer iterations.
    pub iterations: u32,
    /// Simulations run for this answer, of every kind: scan, objective and
    /// gradient, verification, fallback.
    pub evaluations: u32,
    /// Norm of the objective's gradient at the optimizer's last point, m².
    pub grad_norm: f32,
    /// Number of tracks optimized jointly.
    pub horizon_len: usize,
    /// The state when the vehicle, flying [`Plan::depth`], first reaches
    /// the end of the track: the next call's start state.
    pub next_state: VehicleState<N>,
}
