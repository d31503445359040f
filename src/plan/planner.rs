//! [`Planner`]: the caller-owned planner and its one entry point,
//! [`Planner::plan`]: the call's candidate (`candidate.rs`), then what is
//! committed and how safe it is (`commit.rs`).

use crate::optim::Outcome;
use crate::sim::{Scenario, VehicleState};

use super::budget::Budget;
use super::certify::{Certificate, Tube};
use super::jump::Scanned;
use super::{Plan, PlanError, PlannerConfig};

/// Most candidates of one call aimed again past a knife edge's branch
/// (`knife.rs`).
const BRANCH_ROUNDS: u32 = 3;

pub use super::certify::MAX_TRACKS;

/// A receding-horizon or track-wise planner of up to `K` tracks at a time,
/// for a plant of order at most `N` (default 3).
///
/// Holds its settings, the warm start for the next call, and the last
/// call's workspace: the optimized horizon ([`Planner::horizon`]), the
/// optimizer's history ([`Planner::history`]), the continuation that the
/// committed depth's safety rests on ([`Planner::continuation`]) and each
/// declared world's state. Caller-owned: place it in a `static` or on a
/// task's stack (about 9 KiB + 44 `K` + 300 `N` bytes on a 64-bit host:
/// 10 360 B for `Planner<5>`, 2.5 KiB of it the certificate's rows of a
/// line of worlds, `certify/valley.rs`), so a [`Plan`] stays small.
#[derive(Clone, Debug, PartialEq)]
pub struct Planner<const K: usize, const N: usize = 3> {
    pub(super) cfg: PlannerConfig,
    /// The previous call's plan for the tracks after the committed one.
    pub(super) warm: Option<Warm<K>>,
    /// The last call's optimizer outcome (its point is the horizon).
    pub(super) work: Outcome<K>,
    /// The last call's horizon length.
    pub(super) horizon_len: usize,
    /// The committed continuation: depths for the tracks after the last
    /// committed one.
    pub(super) cont: Continuation,
    /// Each declared world's state at the next track.
    pub(super) tube: Tube<N>,
    /// The current call's flight budget (`budget.rs`).
    pub(super) budget: Budget,
    /// Each track's certification gap, m (`gaps.rs`).
    pub(super) gaps: [f32; MAX_TRACKS],
    /// `J` of the tracks committed since the worlds last started afresh,
    /// m³: the scale a later call's gain is weighed on (`commit.rs`).
    pub(super) line_j: f32,
    /// The later tracks (bits) whose least altitude's row was in
    /// transition where the workspace's last SQP run ended (`probe.rs`).
    pub(super) blended: u32,
    /// The SQP's plateau scans that kept no point, for the held edges'
    /// pass (`jump/`).
    pub(super) scanned: Scanned<K>,
    /// Where the last SQP restart ended before it went back to its best
    /// feasible iterate, and the later depths (bits) it left on plateaus
    /// there (`restart.rs`, for `stride.rs`).
    pub(super) restart_plateaus: Option<([f32; K], u32)>,
}

#[cfg(feature = "defmt")]
impl<const K: usize, const N: usize> defmt::Format for Planner<K, N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "Planner {{ cfg: {}, horizon: {}, continuation: {} }}",
            self.cfg,
            self.horizon(),
            self.continuation()
        );
    }
}

/// The warm start: the previous call's horizon after its committed track.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Warm<const K: usize> {
    pub track: usize,
    pub depths: [f32; K],
    pub len: usize,
    /// The penalty weight the previous call ended with.
    pub mu: f32,
    /// Horizon positions (bit `j`: `track + j`) whose plateau the previous
    /// call's SQP scanned already, none of the other depths moved since by
    /// more than `h_r − h_a` (`solve.rs`'s `ScannedAt`).
    pub plateaus: u64,
    /// The previous call was due the cold call's escapes (`wider.rs`) and
    /// ended infeasible, where they do not run: this call runs them.
    pub escapes: bool,
}

/// Reference depths for the tracks `track..track + len`, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Continuation {
    pub track: usize,
    pub depths: [f32; MAX_TRACKS],
    pub len: usize,
    /// The certificate it was committed with (with the depth before it),
    /// when that was safe in horizon mode.
    pub certified: Option<Certificate>,
    /// That certificate's least altitude on each track of the
    /// continuation (from `track`), m, when it flew every world: the next
    /// call, starting where this one predicted, knows the continuation's
    /// certificate without flying it.
    pub minima: Option<[f32; MAX_TRACKS]>,
}

impl Continuation {
    /// No continuation.
    pub const NONE: Self = Self {
        track: 0,
        depths: [0.0; MAX_TRACKS],
        len: 0,
        certified: None,
        minima: None,
    };

    /// The depth for track `t`, if covered.
    pub fn depth(&self, t: usize) -> Option<f32> {
        let i = t.checked_sub(self.track).filter(|&i| i < self.len)?;
        self.depths.get(i).copied()
    }
}

impl<const K: usize, const N: usize> Planner<K, N> {
    /// A planner with validated settings.
    ///
    /// # Errors
    /// [`PlanError::Config`] naming the first setting out of range.
    pub fn new(cfg: PlannerConfig) -> Result<Self, PlanError> {
        const { assert!(K >= 1, "a planner optimizes at least one track") };
        cfg.validate().map_err(PlanError::Config)?;
        Ok(Self {
            cfg,
            warm: None,
            work: Outcome::at(&[0.0; K]),
            horizon_len: 0,
            cont: Continuation::NONE,
            tube: Tube::default(),
            budget: Budget::NONE,
            gaps: [0.0; MAX_TRACKS],
            line_j: 0.0,
            blended: 0,
            scanned: Scanned::NONE,
            restart_plateaus: None,
        })
    }

    /// The settings.
    pub fn config(&self) -> &PlannerConfig {
        &self.cfg
    }

    /// Forgets the warm start, the continuation and the worlds' states
    /// (e.g. after a re-route).
    pub fn reset(&mut self) {
        self.warm = None;
        self.cont = Continuation::NONE;
        self.tube.reset();
        self.gaps = [0.0; MAX_TRACKS];
    }

    /// The last call's optimized horizon, m: the candidate depth of the
    /// call's track first, then the later tracks' depths the optimizer
    /// found.
    pub fn horizon(&self) -> &[f32] {
        self.work.z.get(..self.horizon_len).unwrap_or(&[])
    }

    /// The continuation the last committed depth's safety rests on (model
    /// contract §11): reference depths for every later track of the line,
    /// m, certified with it; empty in track-wise or unconstrained mode. The
    /// next call starts from it.
    pub fn continuation(&self) -> &[f32] {
        self.cont.depths.get(..self.cont.len).unwrap_or(&[])
    }

    /// The last call's optimizer objective (m³) at its start and after
    /// each iteration (at most [`crate::optim::HISTORY`] values). In
    /// horizon mode it is the penalized horizon objective `Σ J + μ Σ V`,
    /// penalty stages and restarts chained; a single track's boundary
    /// search adds the answer's `J` as one more entry.
    pub fn history(&self) -> &[f32] {
        &self.work.history
    }

    /// Plans the reference depth of `track` (0-based) for a vehicle in
    /// `state`, the state in which it reaches the track's first waypoint.
    ///
    /// # Errors
    /// [`PlanError`] for a track outside the line, a start state that is
    /// not finite, not on the track or below the bottom, a line longer than
    /// [`MAX_TRACKS`] in horizon mode, declared map uncertainty without a
    /// certification bottom, a flight budget
    /// ([`PlannerConfig::max_evaluations`]) below what committing the
    /// fallback needs ([`PlanError::BudgetTooSmall`]), or a simulation that
    /// fails at the very start.
    ///
    /// Never inlined: one entry point, whose stack over every path
    /// `tools/qemu/stack_bound.py` bounds from it.
    #[inline(never)]
    pub fn plan(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
    ) -> Result<Plan<N>, PlanError> {
        if self.cfg.max_evaluations == u32::MAX {
            return self.plan_unbudgeted(sc, state, track);
        }
        self.plan_within(sc, state, track, self.cfg.max_evaluations)
    }

    /// [`Planner::plan`] without a flight budget: the candidate (track by
    /// track after a knife edge, aimed again past the other switch's
    /// branch, `knife.rs`, every candidate's flights counted), then the
    /// commit. Not inlined: its candidate is not on the stack of a
    /// budgeted call.
    #[inline(never)]
    fn plan_unbudgeted(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
    ) -> Result<Plan<N>, PlanError> {
        self.budget = Budget::NONE;
        self.tube.set_branch_cap(u32::MAX);
        let mut cand = self.candidate(sc, state, track)?;
        let mut spent = 0_u32;
        for _ in 0..BRANCH_ROUNDS {
            let Some(flights) = self.raised_past_the_branch(sc, state, track, &cand) else {
                break;
            };
            spent = spent
                .saturating_add(flights)
                .saturating_add(cand.evaluations);
            cand = self.candidate(sc, state, track)?;
        }
        cand.evaluations = cand.evaluations.saturating_add(spent);
        self.commit(sc, state, track, &cand)
    }
}
