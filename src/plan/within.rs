//! A budgeted call ([`Planner::plan`] with
//! [`super::PlannerConfig::max_evaluations`] set): the budget split, the
//! candidate within its share, the fallback (see `budget.rs`).

use crate::model::ProfileView;
use crate::sim::{Scenario, SimError, TrackScore, VehicleState, World};

use super::budget::Budget;
use super::candidate::Candidate;
use super::certify::{Certificate, fly_world};
use super::commit::{certification_bottom, nominal_only};
use super::fallback::Flown;
use super::flights::Flights;
use super::planner::{MAX_TRACKS, Warm};
use super::status::{Found, OptimizerStop};
use super::{Mode, Plan, PlanError, Planner};

impl<const K: usize, const N: usize> Planner<K, N> {
    /// `depths` certified (one flight per world) if the budget allows it
    /// with `spare` flights more after it, else no certificate.
    pub(super) fn certify_within(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        depths: &[f32],
        (floor, flights): (f32, &mut u32),
        spare: u32,
    ) -> Certificate {
        if self.budget.afford(flights.saturating_add(spare)) {
            self.tube.certify(sc, bottom, depths, (floor, flights))
        } else {
            Certificate::NONE
        }
    }

    /// [`Planner::plan`] within `limit` flights (module docs). Not
    /// inlined: its frame stays off the unbudgeted call's stack.
    #[inline(never)]
    pub(super) fn plan_within(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
        limit: u32,
    ) -> Result<Plan<N>, PlanError> {
        let s = self.setup(sc, state, track)?;
        let (b, fallback_cost) = self.split(sc, state, track, limit)?;
        if fallback_cost > limit {
            return Err(PlanError::BudgetTooSmall {
                needed: fallback_cost,
            });
        }
        self.budget = b;
        self.tube.set_branch_cap(b.limit.saturating_sub(b.tail));
        self.warm_from_continuation(track, sc.waypoints().tracks().saturating_sub(track));
        let saved = self.cfg;
        self.fit_scan(b.candidate, s.h);
        let tried = if b.candidate > 0 {
            self.candidate(sc, state, track)
        } else {
            Err(PlanError::Sim(SimError::FlightBudget))
        };
        self.cfg = saved;
        let tried = match tried {
            Ok(c) => Some(c),
            Err(PlanError::Sim(_)) => None,
            Err(e) => return Err(e),
        };
        let cand = match tried {
            Some(c) => c,
            // (An abandoned candidate is counted as its whole share.)
            None => self.fallback_candidate(sc, state, track, (b.candidate, s.h_safe))?,
        };
        self.commit(sc, state, track, &cand)
    }

    /// The call's budget split (module docs), and what the fallback costs.
    fn split(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
        limit: u32,
    ) -> Result<(Budget, u32), PlanError> {
        let bottom = certification_bottom(sc)?;
        let kept = self.tube.prepare_for(sc, state, track);
        let w = u32::try_from(self.tube.count()).unwrap_or(u32::MAX);
        let nominal = nominal_only(sc, bottom, &self.tube, state);
        let guaranteed = self.cfg.mode == Mode::Horizon && self.cfg.constrained;
        let len = sc.waypoints().tracks().saturating_sub(track);
        let covers = self.previous(track, len).is_some();
        let known = self
            .cont
            .certified
            .filter(|_| guaranteed && kept && covers)
            .map(|c| Certificate {
                first: c.all,
                all: c.all,
                partial: false,
                id: 0,
            });
        // (A tube that owes its worlds' advance, from unbudgeted calls
        // before: one more flight per world, before any certificate.)
        let owed = if self.tube.owes() { w } else { 0 };
        let tail = if nominal { 1 } else { w.saturating_add(1) }.saturating_add(owed);
        let certify = if nominal && (len == 1 || !guaranteed) {
            0
        } else {
            w
        };
        let anchor = match (guaranteed, known) {
            (true, None) => w,
            _ => 0,
        };
        // The fallback (the anchor's flight is its certificate when the
        // nominal world is the only one); the candidate's share leaves
        // room for its certificate and for the anchor after it.
        let fallback = match (guaranteed, nominal, known) {
            (true, true, None) => 1,
            (true, _, _) => anchor.saturating_add(tail),
            (false, _, _) => certify.saturating_add(tail),
        };
        let after = certify.saturating_add(anchor).saturating_add(tail);
        let b = Budget {
            limit,
            certify: w,
            tail,
            anchor,
            known,
            candidate: limit.saturating_sub(after.max(fallback)),
            nominal,
        };
        Ok((b, fallback))
    }

    /// Fewer scan points when the scan of the tracks the warm start does
    /// not cover (`h` in all) would leave the optimizer fewer than 2 of the candidate's
    /// `share` of flights, at least 2 per track (the settings are restored
    /// after the call's candidate).
    fn fit_scan(&mut self, share: u32, h: usize) {
        let warm = self.warm.map_or(0, |w| w.len.min(h));
        let new = u32::try_from(h.saturating_sub(warm)).unwrap_or(u32::MAX);
        if new == 0 {
            return;
        }
        let fit = share.saturating_sub(2).checked_div(new).unwrap_or(0).max(2);
        self.cfg.scan_points = self.cfg.scan_points.min(fit);
        self.cfg.track_scan_points = self.cfg.track_scan_points.min(fit);
    }

    /// A budgeted call starts its optimizer from the previous continuation
    /// over the whole horizon (a certified point) instead of scanning the
    /// newly visible track: the scan's flights go to the optimizer. (Not
    /// inlined: its depths are not on the stack of the call's candidate.)
    #[inline(never)]
    fn warm_from_continuation(&mut self, track: usize, len: usize) {
        let Some(p) = self.previous(track, len) else {
            return;
        };
        let h = match self.cfg.mode {
            Mode::TrackWise => 1,
            Mode::Horizon => self.cfg.horizon.min(K).min(len),
        };
        // (A resumed call's warm start already covers the horizon.)
        if self.warm.is_some_and(|w| w.track == track && w.len >= h) {
            return;
        }
        let mu = self.warm.map_or(self.cfg.penalty_weight, |w| w.mu);
        let mut depths = [0.0; K];
        for (dst, src) in depths.iter_mut().zip(p.iter()) {
            *dst = *src;
        }
        self.warm = Some(Warm {
            track,
            depths,
            len: h,
            mu,
            plateaus: 0,
            escapes: false,
        });
    }

    /// The previous continuation for tracks `track..track + len`, if it
    /// covers them all.
    fn previous(&self, track: usize, len: usize) -> Option<[f32; MAX_TRACKS]> {
        let mut a = [0.0; MAX_TRACKS];
        for (i, slot) in a.iter_mut().enumerate().take(len) {
            *slot = self.cont.depth(track.saturating_add(i))?;
        }
        Some(a)
    }

    /// The fallback's candidate: the previous continuation (else the climb)
    /// with its track's nominal flight, after `spent` flights; its
    /// certificate when known, or (the nominal world over the map the only
    /// one) from the same line flight. The workspace and the next call's
    /// warm start follow it.
    #[inline(never)]
    fn fallback_candidate(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
        (spent, h_safe): (u32, f32),
    ) -> Result<Candidate<N>, PlanError> {
        let len = sc.waypoints().tracks().saturating_sub(track);
        let shallow = sc.mission().depth_limits()[0];
        let guaranteed = self.cfg.mode == Mode::Horizon && self.cfg.constrained;
        let mut depths = [shallow; MAX_TRACKS];
        if guaranteed && let Some(p) = self.previous(track, len) {
            depths = p;
        }
        let mut fl = Flights {
            sc: *sc,
            state,
            track,
            count: spent,
            limit: u32::MAX,
        };
        let (flown, cert) = if guaranteed && self.budget.known.is_none() && self.budget.nominal {
            // With no continuation, the terrain rule before the climb, when
            // the budget has a flight for each.
            let fresh = self.previous(track, len).is_none();
            let mut held = None;
            let cap = self.budget.limit.saturating_sub(self.budget.tail);
            if fresh && self.budget.limit.saturating_sub(fl.count) >= 2 {
                let rule = terrain_rule(sc, track, len);
                let d = rule.get(..len).unwrap_or(&[]);
                // (Its branch leaves the climb's flight.)
                let spare = (&mut fl.count, cap.saturating_sub(1));
                if let Ok((f, c)) = fly_line(sc, (state, track), d, spare)
                    && c.all >= h_safe
                {
                    depths = rule;
                    held = Some((f, Some(c)));
                }
            }
            match held {
                Some(h) => h,
                None => {
                    let d = depths.get(..len).unwrap_or(&[]);
                    let (f, c) = fly_line(sc, (state, track), d, (&mut fl.count, cap))?;
                    (f, Some(c))
                }
            }
        } else {
            let (score, next) = fl.fly(depths[0])?;
            let known = self.budget.known.filter(|_| guaranteed);
            let f = Flown {
                depth: depths[0],
                score,
                next,
            };
            (f, known)
        };
        self.follow(track, &depths, len, flown.score.j());
        Ok(Candidate {
            flown,
            found: Found::Optimized(OptimizerStop::Budget),
            iterations: 0,
            evaluations: fl.count,
            h_safe,
            cert,
            previous_j: None,
        })
    }

    /// The workspace after a fallback: the horizon is the continuation's
    /// first tracks, its objective the committed track's `j` (m³); the next call starts warm from the
    /// continuation `depths` (`len` tracks from `track`).
    fn follow(&mut self, track: usize, depths: &[f32; MAX_TRACKS], len: usize, j: f32) {
        let h = match self.cfg.mode {
            Mode::TrackWise => 1,
            Mode::Horizon => self.cfg.horizon.min(K).min(len),
        };
        self.work.z = [0.0; K];
        for (dst, src) in self.work.z.iter_mut().zip(depths.iter()).take(h) {
            *dst = *src;
        }
        self.work.j = j;
        self.work.grad_norm = 0.0;
        self.work.iterations = 0;
        self.work.history.clear();
        let _ = self.work.history.push(j);
        self.horizon_len = h.max(1);
        let warm_len = h.saturating_sub(1);
        self.warm = (self.cfg.mode == Mode::Horizon && warm_len > 0).then(|| {
            let mut w = [0.0; K];
            for (dst, src) in w.iter_mut().zip(depths.iter().skip(1)) {
                *dst = *src;
            }
            Warm {
                track: track.saturating_add(1),
                depths: w,
                len: warm_len,
                mu: self.cfg.penalty_weight,
                plateaus: 0,
                escapes: false,
            }
        });
    }
}

/// The nominal line flight of `depths` from `state` on `track` (one flight,
/// over the map): the first track's flight and the certificate it is when
/// the nominal world over the map is the only one. Where a track ends on
/// its waypoint's knife edge, the line is flown again as a certificate's
/// world is, each edge's switch the other way too (`certify/flight.rs`),
/// while `count` leaves room below `cap` (else the nominal switch alone,
/// the contract's certificate).
#[inline(never)]
fn fly_line<const N: usize>(
    sc: &Scenario<'_, N>,
    (state, track): (&VehicleState<N>, usize),
    depths: &[f32],
    (count, cap): (&mut u32, u32),
) -> Result<(Flown<N>, Certificate), PlanError> {
    *count = count.saturating_add(1);
    let mut st = *state;
    let mut first: Option<Flown<N>> = None;
    let (mut all, mut branched) = (f32::INFINITY, false);
    for (j, &z) in depths.iter().enumerate() {
        let mut score = [TrackScore::default()];
        let t = track.saturating_add(j);
        match sc.fly(&st, t, &[z], &mut score) {
            Ok(next) => {
                let s = score[0];
                all = all.min(s.min_altitude());
                if first.is_none() {
                    first = Some(Flown {
                        depth: z,
                        score: s,
                        next,
                    });
                }
                // (Once: the whole line again, with every edge's branch;
                // no flights left for it, the nominal switch alone, §11's.)
                let more = j.saturating_add(1) < depths.len();
                if more && !branched && sc.on_edge(t, &next) && count.saturating_add(1) < cap {
                    branched = true;
                    let (w, bottom) = (World::nominal(sc.vehicle()), sc.profile());
                    let at = (state, track);
                    let (_, a) = fly_world(sc, &w, bottom, at, depths, (0.0, &[]), (count, cap));
                    all = all.min(a);
                }
                st = next;
            }
            Err(e) if first.is_none() => return Err(e.into()),
            Err(_) => {
                all = f32::NEG_INFINITY;
                break;
            }
        }
    }
    let f = first.ok_or(PlanError::Sim(SimError::TrackRange))?;
    let cert = Certificate {
        first: f.score.min_altitude(),
        all,
        partial: false,
        id: 0,
    };
    Ok((f, cert))
}

/// The terrain rule: on each track, `h_r` above the highest mapped bottom
/// of that track and the next (so that the vehicle is up before a rise),
/// within the depth limits, m.
#[inline(never)]
fn terrain_rule<const N: usize>(
    sc: &Scenario<'_, N>,
    track: usize,
    len: usize,
) -> [f32; MAX_TRACKS] {
    let m = sc.mission();
    let [lo, hi] = m.depth_limits();
    let wp = sc.waypoints().positions();
    let p = sc.profile();
    let mut out = [lo; MAX_TRACKS];
    for (j, slot) in out.iter_mut().enumerate().take(len) {
        let t = track.saturating_add(j);
        let a = wp.get(t).copied().unwrap_or(0.0);
        let b = wp
            .get(t.saturating_add(2))
            .or_else(|| wp.get(t.saturating_add(1)))
            .copied()
            .unwrap_or(a);
        let ends = [a, b].into_iter().filter_map(|x| p.depth_at(x).ok());
        let inside = p
            .positions()
            .iter()
            .zip(p.depths())
            .filter(|(x, _)| **x >= a && **x <= b)
            .map(|(_, d)| *d);
        let top = ends.chain(inside).fold(f32::INFINITY, f32::min);
        if top.is_finite() {
            *slot = (top - m.reference_altitude()).max(lo).min(hi);
        }
    }
    out
}
