//! Planning within a flight budget ([`super::PlannerConfig::max_evaluations`]):
//! a hard bound on every flight of a call — the scan, the optimizer's
//! evaluations, verification and fallback, every certification flight
//! (one per declared world per continuation tried), the committed depth's
//! flight and the worlds' advance.
//!
//! A call first sets aside the flights its *fallback* needs: the previous
//! call's continuation (already certified; without one, the terrain rule —
//! `h_r` above the highest mapped bottom of each track and the next — when
//! it certifies and the budget has its flight, else the climb to the
//! shallowest allowed depth), its committed track flown nominally and the
//! worlds moved on. The candidate gets what is left after that and after
//! its own certification; the optimizer stops on its share
//! (`optimizer: budget`), and a candidate whose scan, verification or
//! boundary search would pass it is abandoned. The commit then certifies
//! the candidate (and, while the budget allows, the candidate with the
//! climb and the search from the anchor), and otherwise commits the
//! fallback: the best *certified* plan found within the budget. So a budget
//! costs `J`, never safety (model contract §11).
//!
//! What the fallback costs, flights (`W` declared worlds; `W = 1` and no
//! advance flight when only the nominal world over the map is declared):
//! - the call starts where the last one predicted and that call was
//!   certified: its continuation's certificate still holds (the worlds'
//!   flights from the kept states are the same flights), so `1 + W`
//!   (`1` nominal). That holds for the same scenario: a caller that changes
//!   the map or the line between calls calls `Planner::reset` first;
//! - otherwise (the first call, a measured start state, an uncertified
//!   last call) the anchor is certified again: `1 + 2 W` (`1` nominal: the
//!   anchor's line flight is its track's flight too).
//!
//! A budget below that is [`PlanError::BudgetTooSmall`], before any flight.

use crate::sim::SimError;

use super::PlanError;
use super::certify::Certificate;

/// One call's flight budget, split.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Budget {
    /// Most flights of the call (`u32::MAX`: none).
    pub limit: u32,
    /// Flights of one certification: one line flight per declared world.
    pub certify: u32,
    /// Flights committing needs after the certificate: the committed
    /// depth's nominal flight and the worlds' advance.
    pub tail: u32,
    /// Flights of certifying the anchor again (0 when its certificate is
    /// known).
    pub anchor: u32,
    /// The previous continuation's certificate from this call's states,
    /// when known without flying.
    pub known: Option<Certificate>,
    /// Flights the candidate may use.
    pub candidate: u32,
    /// The only world is the nominal one over the map.
    pub nominal: bool,
}

impl Budget {
    /// No budget.
    pub const NONE: Self = Self {
        limit: u32::MAX,
        certify: 0,
        tail: 0,
        anchor: 0,
        known: None,
        candidate: u32::MAX,
        nominal: false,
    };

    /// Whether a budget is set.
    fn limited(&self) -> bool {
        self.limit != u32::MAX
    }

    /// Whether one more certification fits after `spent` flights, with
    /// the commit's tail after it.
    pub fn afford(&self, spent: u32) -> bool {
        !self.limited()
            || spent.saturating_add(self.certify).saturating_add(self.tail) <= self.limit
    }

    /// The optimizer's evaluations after the candidate's `spent` flights:
    /// its share less one for the verification flight.
    ///
    /// # Errors
    /// `FlightBudget` when nothing is left for it.
    pub fn optimizer(&self, spent: u32) -> Result<u32, PlanError> {
        if !self.limited() {
            return Ok(u32::MAX);
        }
        match self.candidate.saturating_sub(spent).saturating_sub(1) {
            0 => Err(PlanError::Sim(SimError::FlightBudget)),
            n => Ok(n),
        }
    }

    /// An anchor's certificate known without flying, in a budgeted call:
    /// the previous continuation's, or the candidate's when the anchor is
    /// the candidate itself (`(a, c, cert_c)`, `len` tracks).
    pub fn known_anchor(
        &self,
        is_prev: bool,
        (a, c, cert_c): (&[f32], &[f32], Certificate),
        len: usize,
    ) -> Option<Certificate> {
        if !self.limited() {
            return None;
        }
        let same = a
            .iter()
            .zip(c.iter())
            .take(len)
            .all(|(x, y)| x.to_bits() == y.to_bits());
        if same {
            return Some(cert_c);
        }
        self.known.filter(|_| is_prev)
    }
}

impl Certificate {
    /// No certificate (nothing flown).
    pub(super) const NONE: Self = Self {
        first: f32::NEG_INFINITY,
        all: f32::NEG_INFINITY,
        partial: false,
        id: 0,
    };
}
