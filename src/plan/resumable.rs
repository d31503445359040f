//! [`Resumable`]: one planner call spread over many short steps, for
//! super-loop firmware without an RTOS (and for any task that must yield).
//!
//! **Design.** Each [`Resumable::step`] is one complete budgeted call
//! ([`super::PlannerConfig::max_evaluations`] = the step's flights) on a
//! copy of the planner as it was when the call began, warm-started from
//! the best horizon the earlier steps found: the optimizer re-enters from
//! its saved best point, and every step ends with a certified plan (the
//! budget's fallback: the previous call's continuation). The best
//! certified plan so far is kept; [`Step::Done`] comes when a step's
//! optimizer converges, when a step no longer improves the horizon
//! objective, or when the call's total budget is spent. Nothing allocates:
//! the state is three planners (the start, the best, the step's) and a
//! plan, about 3 × `size_of::<Planner<K, N>>()`.
//!
//! **What it costs against one blocking call.** Every step pays its own
//! certification and fallback reserve, and BFGS restarts each step from
//! the best point with a fresh metric (the curvature learnt is lost), so a
//! resumable call flies more in all and, for the same total flights,
//! reaches a higher `J` (BENCHMARKS.md, "Planning within a budget"). Its
//! safety is the budgeted call's: never worse than the previous
//! continuation.

use crate::sim::{Scenario, VehicleState};

use super::planner::Warm;
use super::{OptimizerStop, Plan, PlanError, Planner};

/// What a step of a resumable call returns.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Step<const N: usize> {
    /// Not done: call [`Resumable::step`] again. The best certified plan
    /// so far is [`Resumable::best`].
    Pending,
    /// The call's plan; the planner has moved on to the next track.
    Done(Plan<N>),
}

/// A planner whose calls run as bounded steps: each [`Resumable::step`]
/// is one budgeted call of at most its flights, on a copy of the planner
/// as the call began, warm-started from the best horizon found so far; the
/// best certified plan is kept, and [`Step::Done`] comes when a step's
/// optimizer converges, a step no longer improves, or the total budget is
/// spent. No allocation: three planners and a plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Resumable<const K: usize, const N: usize = 3> {
    /// The planner as the call began (after it: as the best step left it).
    start: Planner<K, N>,
    /// The best step's planner and plan.
    best: Option<(Planner<K, N>, Plan<N>)>,
    /// The call: its start state and track.
    call: Option<(VehicleState<N>, usize)>,
    /// Flights spent by the call, and its total budget.
    spent: u32,
    total: u32,
}

impl<const K: usize, const N: usize> Resumable<K, N> {
    /// A resumable form of `planner` (its settings, warm start,
    /// continuation and worlds' states carry on).
    pub fn new(planner: Planner<K, N>) -> Self {
        Self {
            start: planner,
            best: None,
            call: None,
            spent: 0,
            total: 0,
        }
    }

    /// The planner between calls (and as the current call began).
    pub fn planner(&self) -> &Planner<K, N> {
        &self.start
    }

    /// Begins the call planning `track` from `state` (as
    /// [`Planner::plan`]) within `total` flights over all its steps
    /// (`u32::MAX`: until the optimizer converges). A call in progress is
    /// dropped.
    pub fn begin(&mut self, state: &VehicleState<N>, track: usize, total: u32) {
        self.best = None;
        self.call = Some((*state, track));
        self.spent = 0;
        self.total = total;
    }

    /// Flights spent by the call so far.
    pub fn spent(&self) -> u32 {
        self.spent
    }

    /// The best certified plan of the call so far (the last step's when
    /// none is certified).
    pub fn best(&self) -> Option<&Plan<N>> {
        self.best.as_ref().map(|b| &b.1)
    }

    /// One step of at most `flights` flights (at least the fallback's: see
    /// [`PlanError::BudgetTooSmall`]).
    ///
    /// # Errors
    /// [`PlanError`] as [`Planner::plan`]; [`PlanError::TrackRange`] when
    /// no call was begun.
    pub fn step(&mut self, sc: &Scenario<'_, N>, flights: u32) -> Result<Step<N>, PlanError> {
        let (state, track) = self.call.ok_or(PlanError::TrackRange)?;
        let left = self.total.saturating_sub(self.spent);
        let mut attempt = self.start.clone();
        attempt.cfg.max_evaluations = flights.min(left).max(1);
        if let Some((b, _)) = &self.best {
            attempt.warm = Some(Warm {
                track,
                depths: b.work.z,
                len: b.horizon_len,
                mu: b.warm.map_or(b.cfg.penalty_weight, |w| w.mu),
                plateaus: 0,
                escapes: false,
            });
        }
        let plan = attempt.plan(sc, &state, track)?;
        // (The attempt's settings are the planner's again.)
        attempt.cfg.max_evaluations = self.start.cfg.max_evaluations;
        self.spent = self.spent.saturating_add(plan.evaluations);
        let improved = match &self.best {
            None => true,
            Some((_, b)) => {
                (plan.safe && !b.safe) || (plan.safe == b.safe && plan.objective < b.objective)
            }
        };
        if improved {
            self.best = Some((attempt, plan));
        }
        let converged = plan.optimizer == OptimizerStop::Converged;
        if converged || !improved || self.spent >= self.total {
            return Ok(self.finish());
        }
        Ok(Step::Pending)
    }

    /// Ends the call with its best plan.
    fn finish(&mut self) -> Step<N> {
        self.call = None;
        match self.best.take() {
            Some((p, plan)) => {
                self.start = p;
                Step::Done(plan)
            }
            None => Step::Pending,
        }
    }
}
