//! What a call commits, and how safe it is (model contract §11, §12).
//!
//! **Horizon mode, constrained: recursive feasibility.** A depth is
//! committed only with a *continuation*: reference depths for every later
//! track, certified with it to the end of the line in every declared world
//! ([`super::certify`]). The candidate continuation is the call's
//! optimized horizon, then the previous call's continuation beyond it (or,
//! with none, the shallowest allowed depth: the climb). If it does not
//! certify, the call searches the straight path from a certified anchor —
//! the previous call's continuation (flown from the state it predicted, so
//! certified again whenever the vehicle flew the committed depth), else
//! the shallowest depth on every track — towards the candidate, for the
//! last certified point ([`crate::optim::root`] on the certified minimum
//! altitude), and keeps the previous continuation instead where it
//! certifies and its horizon `J` is lower. With no anchor certified, the
//! call is `infeasible` and commits the safest continuation it tried. So whatever the horizon, the
//! iteration cap or the budget, once a call has committed a certified
//! continuation every later call has one: fewer iterations cost `J`, never
//! safety.
//!
//! **Track-wise mode** (the paper's) and **unconstrained** plans commit the
//! candidate alone: its own track is certified and reported, nothing
//! beyond it is promised.

use crate::model::ProfileView;
use crate::sim::{Scenario, TrackScore, VehicleState, World};

use super::candidate::Candidate;
use super::certify::{ALL, Certificate, Tube};
use super::chosen::Chosen;
use super::fallback::{Flown, fly_committed};
use super::knife::one_vehicle;
use super::planner::{Continuation, MAX_TRACKS};
use super::status::Found;
use super::{Mode, Plan, PlanError, PlanStatus, Planner};

/// A later call keeps the previous continuation, whose certificate it
/// knows, unless the candidate lowers the line's `J` (the tracks committed
/// so far and the horizon) by more than this share: re-certifying costs a
/// flight per declared world, and the candidate differs from the kept
/// continuation mostly by what the gaps measured anew moved.
const KEEP_SHARE: f32 = 1e-3;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// Commits the call's depth: certifies it (with its continuation in
    /// horizon mode), moves the worlds' states on, builds the one [`Plan`].
    pub(super) fn commit(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
        cand: &Candidate<N>,
    ) -> Result<Plan<N>, PlanError> {
        let bottom = certification_bottom(sc)?;
        let kept = self.tube.prepare_for(sc, state, track);
        if !kept {
            self.line_j = 0.0;
        }
        let mut flights = cand.evaluations;
        let guaranteed = self.cfg.mode == Mode::Horizon && self.cfg.constrained;
        // Unbudgeted, the worlds' advance is flown only when a certificate
        // needs it (the budget accounts for it at every call).
        let lazy = self.budget.limit == u32::MAX;
        let how = (guaranteed, kept && lazy);
        let at = (state, track);
        let (mut chosen, mut flown) =
            self.choose_flown(sc, bottom, at, (cand, how), &mut flights)?;
        if guaranteed {
            self.anchor_if_cheaper(
                sc,
                bottom,
                at,
                (cand, &mut chosen, &mut flown),
                &mut flights,
            )?;
        }
        // The previous continuation on its waypoint's knife edge (`knife.rs`),
        // the candidate off it: the candidate's way instead.
        if chosen.previous && sc.on_edge(track, &flown.next) && !sc.on_edge(track, &cand.flown.next)
        {
            if one_vehicle(sc) {
                let how = (guaranteed, false);
                (chosen, flown) = self.choose_flown(sc, bottom, at, (cand, how), &mut flights)?;
            } else if let Some(c) =
                self.off_kept_edge((sc, bottom), at, (cand, &flown), &mut flights)
            {
                flown = fly_committed(sc, at, c.depths[0], cand.flown, &mut flights)?;
                chosen = c;
            }
        }
        let how = (guaranteed, lazy);
        Ok(self.settle((sc, bottom), at, cand, (&chosen, flown), how, flights))
    }

    /// After [`Planner::commit`] chose: keeps the continuation, moves the
    /// worlds on past the committed depth (`flown`), builds the [`Plan`].
    /// Not inlined: its frame stays off the choice's (the deepest) stack.
    #[inline(never)]
    fn settle(
        &mut self,
        (sc, bottom): (&Scenario<'_, N>, ProfileView<'_>),
        (state, track): (&VehicleState<N>, usize),
        cand: &Candidate<N>,
        (chosen, flown): (&Chosen<N>, Flown<N>),
        (guaranteed, lazy): (bool, bool),
        mut flights: u32,
    ) -> Plan<N> {
        let depth = chosen.depths[0];
        let minima = if chosen.previous {
            self.cont.minima
        } else {
            self.tube.minima_of(&chosen.cert)
        };
        self.keep(chosen, track, guaranteed);
        self.cont.minima = minima.filter(|_| guaranteed).map(|m| {
            // (The tracks after the committed one.)
            core::array::from_fn(|i| {
                m.get(i.saturating_add(1))
                    .copied()
                    .unwrap_or(f32::NEG_INFINITY)
            })
        });
        let only_nominal = nominal_only(sc, bottom, &self.tube, state);
        self.tube.advance(
            (sc, bottom),
            depth,
            &flown.next,
            (only_nominal, lazy, &mut flights),
        );
        // (Track by track too, constrained: the next track is aimed past
        // the branch, `knife.rs`.)
        if self.cfg.constrained {
            self.branch_off_the_edge(sc, (state, track), &flown, &mut flights);
        }
        let safe = chosen.cert.all >= cand.h_safe;
        self.line_j += flown.score.j();
        self.cont.certified = (guaranteed && safe).then_some(chosen.cert);
        let status = self.status(sc, cand, chosen, safe);
        // The declared worlds' least altitude: with nothing declared, the
        // nominal flight's (a branch world is no declared world: it only
        // makes the certificate, so `safe`, stricter: spec/cli.md).
        let certified = if sc.mission().uncertainty().is_none() {
            flown.score.min_altitude()
        } else {
            chosen.cert.first
        };
        self.answer(flown, cand, (status, safe, certified), flights)
    }

    /// [`Planner::choose`], with the chosen depth's nominal flight.
    fn choose_flown(
        &mut self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        (state, track): (&VehicleState<N>, usize),
        (cand, how): (&Candidate<N>, (bool, bool)),
        flights: &mut u32,
    ) -> Result<(Chosen<N>, Flown<N>), PlanError> {
        let chosen = self.choose(sc, bottom, (state, track), (cand, how), flights)?;
        let depth = chosen.depths[0];
        let flown = fly_committed(sc, (state, track), depth, cand.flown, flights)?;
        Ok((chosen, flown))
    }

    /// The continuation to commit and its certificate: the known one
    /// ([`Planner::known_continuation`]) when `known` allows it, else
    /// ([`Planner::continue_safely`]) with `guaranteed`, else the
    /// candidate's track alone.
    fn choose(
        &mut self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        (state, track): (&VehicleState<N>, usize),
        (cand, (guaranteed, known)): (&Candidate<N>, (bool, bool)),
        flights: &mut u32,
    ) -> Result<Chosen<N>, PlanError> {
        let kept = (guaranteed && known)
            .then(|| self.known_continuation(sc, bottom, (state, track), cand, flights))
            .flatten();
        if let Some(c) = kept {
            return Ok(c);
        }
        self.tube
            .materialize((sc, bottom), (state, track), (ALL, &mut *flights));
        if guaranteed {
            let c = self.continue_safely(sc, bottom, (state, track), cand, flights)?;
            return Ok(self.completed(sc, bottom, c, flights));
        }
        let mut depths = [0.0; MAX_TRACKS];
        depths[0] = cand.flown.depth;
        let at = (f32::NEG_INFINITY, flights);
        let cert = self.certify_one(sc, bottom, (state, &cand.flown), at);
        Ok(Chosen::new(depths, 1, cert))
    }

    /// The previous call's continuation with its certificate, known
    /// without a flight when the worlds start where that call predicted
    /// (the certificate's flights pass through these very states), when
    /// the certificate is more than the nominal flight, and when the
    /// candidate is no better than it on the horizon by more than
    /// [`KEEP_SHARE`] of `Σ J` (the optimizer started from it, so its start
    /// value is the continuation's). Not inlined: its frame stays off the
    /// certifying path's stack.
    #[inline(never)]
    fn known_continuation(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        (state, track): (&VehicleState<N>, usize),
        cand: &Candidate<N>,
        flights: &mut u32,
    ) -> Option<Chosen<N>> {
        if nominal_only(sc, bottom, &self.tube, state) {
            return None;
        }
        let (certified, minima) = (self.cont.certified?, self.cont.minima?);
        let len = sc.waypoints().tracks().saturating_sub(track);
        let shallow = sc.mission().depth_limits()[0];
        let depths = self.previous_continuation(track, len, shallow)?;
        // Its horizon's `Σ J`: known when the optimizer started from it,
        // else one nominal flight.
        let prev_j = match cand.previous_j {
            Some(j) => j,
            None => self.horizon_j(sc, (state, track), (&depths, len), flights)?,
        };
        let line = libm::fabsf(self.line_j) + libm::fabsf(prev_j);
        let better = self.work.j < prev_j - KEEP_SHARE * line;
        if better || certified.partial || len == 0 {
            return None;
        }
        let m = minima.get(..len)?;
        let cert = Certificate {
            first: m.first().copied()?,
            all: m.iter().copied().fold(f32::INFINITY, f32::min),
            partial: false,
            id: 0,
        };
        (cert.all >= cand.h_safe).then_some(Chosen {
            previous: true,
            ..Chosen::new(depths, len, cert)
        })
    }

    /// `Σ J` of the horizon's tracks (at most `len`, the continuation's)
    /// of the continuation `depths` from `state` at `track`: one nominal
    /// flight, counted; `None` where it fails.
    pub(super) fn horizon_j(
        &self,
        sc: &Scenario<'_, N>,
        (state, track): (&VehicleState<N>, usize),
        (depths, len): (&[f32; MAX_TRACKS], usize),
        flights: &mut u32,
    ) -> Option<f32> {
        let h = self.horizon_len.max(1).min(len).min(K);
        let mut scores = [TrackScore::default(); K];
        *flights = flights.saturating_add(1);
        let d = depths.get(..h)?;
        sc.fly(state, track, d, scores.get_mut(..h)?).ok()?;
        Some(scores.iter().take(h).map(TrackScore::j).sum())
    }

    /// The continuation to commit (module docs): the candidate if it
    /// certifies, else the last certified point on the path from an
    /// anchor ([`super::search`]), else the safest tried.
    fn continue_safely(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        (state, track): (&VehicleState<N>, usize),
        cand: &Candidate<N>,
        flights: &mut u32,
    ) -> Result<Chosen<N>, PlanError> {
        let len = sc.waypoints().tracks().saturating_sub(track);
        if len > MAX_TRACKS {
            return Err(PlanError::LineTooLong);
        }
        let shallow = sc.mission().depth_limits()[0];
        let horizon = (&self.work.z, self.horizon_len);
        // (Few continuations held at once, each a quarter of a kilobyte of
        // stack: the safest tried is kept as where it came from, rebuilt
        // at the end.)
        let mut c = self.candidate_continuation((track, len), (cand.flown.depth, horizon), shallow);
        let cert_0 = self.certify_candidate(sc, bottom, (state, cand), (&c, len), flights);
        if cert_0.all >= cand.h_safe {
            return Ok(Chosen::new(c, len, cert_0));
        }
        // The candidate's depth, then the climb: the optimized later depths
        // may lead into a trap that the next call's horizon would see and
        // avoid, while the committed depth alone need not.
        let (c2, cert_c2) = self.then_climb(sc, bottom, cand, ((&c, cert_0), len), flights);
        if cert_c2.all >= cand.h_safe {
            return Ok(Chosen::new(c2, len, cert_c2));
        }
        let mut cert_c = cert_0;
        if cert_c2.all > cert_c.all {
            (c, cert_c) = (c2, cert_c2);
        }
        // Anchors: the previous continuation, then the climb. The safest
        // tried: the candidate (`None`) or an anchor (`Some(is_prev)`).
        let mut best = (None, cert_0);
        let mut a = [shallow; MAX_TRACKS];
        for is_prev in [true, false] {
            if is_prev && !self.previous_into(track, len, &mut a) {
                continue;
            }
            if !is_prev {
                a = [shallow; MAX_TRACKS];
            }
            let cert_a = match self.budget.known_anchor(is_prev, (&a, &c, cert_c), len) {
                Some(known) => known,
                None => {
                    let at = (cand.h_safe, &mut *flights);
                    self.certify_within(sc, bottom, a.get(..len).unwrap_or(&[]), at, 0)
                }
            };
            if cert_a.all >= cand.h_safe {
                let ends = ((&a, cert_a), (&c, cert_c));
                let found = self.search(sc, bottom, ends, len, cand.h_safe, flights);
                return Ok(self.search_committed(sc, bottom, found, cand, flights));
            }
            if cert_a.all > best.1.all {
                best = (Some(is_prev), cert_a);
            }
        }
        let (from, cert) = best;
        match from {
            None => {
                let z = (cand.flown.depth, horizon);
                let c = self.candidate_continuation((track, len), z, shallow);
                Ok(Chosen::new(c, len, cert))
            }
            Some(is_prev) => {
                a = [shallow; MAX_TRACKS];
                if is_prev {
                    let _ = self.previous_into(track, len, &mut a);
                }
                Ok(Chosen {
                    searched: true,
                    ..Chosen::new(a, len, cert)
                })
            }
        }
    }

    /// The candidate's depth, then the shallowest allowed depth on every
    /// later track, with its certificate (the candidate's when that is
    /// the same line).
    fn then_climb(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        cand: &Candidate<N>,
        ((c, cert_c), len): ((&[f32; MAX_TRACKS], Certificate), usize),
        flights: &mut u32,
    ) -> ([f32; MAX_TRACKS], Certificate) {
        let shallow = sc.mission().depth_limits()[0];
        let mut c2 = [shallow; MAX_TRACKS];
        c2[0] = cand.flown.depth;
        if c2.iter().zip(c).all(|(a, b)| a.to_bits() == b.to_bits()) {
            return (c2, cert_c);
        }
        let spare = self.budget.anchor;
        let at = (cand.h_safe, flights);
        let cert = self.certify_within(sc, bottom, c2.get(..len).unwrap_or(&[]), at, spare);
        (c2, cert)
    }

    /// `chosen` with its certificate complete: a partial one (some worlds
    /// left unflown, its altitudes upper bounds) is flown again in every
    /// world, budget permitting (else it is no certificate at all).
    pub(super) fn completed(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        mut chosen: Chosen<N>,
        flights: &mut u32,
    ) -> Chosen<N> {
        if chosen.cert.partial {
            let d = chosen.depths.get(..chosen.len).unwrap_or(&[]);
            let at = (f32::NEG_INFINITY, &mut *flights);
            chosen.cert = self.certify_within(sc, bottom, d, at, 0);
        }
        chosen
    }

    /// The candidate continuation's certificate: known (a budgeted
    /// fallback's), its flight's (one track), or flown.
    pub(super) fn certify_candidate(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        (state, cand): (&VehicleState<N>, &Candidate<N>),
        (c, len): (&[f32; MAX_TRACKS], usize),
        flights: &mut u32,
    ) -> Certificate {
        let c = c.get(..len).unwrap_or(&[]);
        match cand.cert {
            Some(known) => known,
            // (In full: the one-track certificate is the search's end.)
            None if c.len() == 1 => {
                let at = (f32::NEG_INFINITY, flights);
                self.certify_one(sc, bottom, (state, &cand.flown), at)
            }
            None => self.tube.certify(sc, bottom, c, (cand.h_safe, flights)),
        }
    }

    /// The previous call's continuation for tracks `track..track + len`,
    /// if it covers them all (the climb to `shallow`, m, beyond them).
    pub(super) fn previous_continuation(
        &self,
        track: usize,
        len: usize,
        shallow: f32,
    ) -> Option<[f32; MAX_TRACKS]> {
        let mut a = [shallow; MAX_TRACKS];
        self.previous_into(track, len, &mut a).then_some(a)
    }

    /// [`Planner::previous_continuation`] into the first `len` entries of
    /// `a` (in place); false, `a` partly written, where it does not cover
    /// them all.
    fn previous_into(&self, track: usize, len: usize, a: &mut [f32; MAX_TRACKS]) -> bool {
        for (i, slot) in a.iter_mut().enumerate().take(len) {
            let Some(d) = self.cont.depth(track.saturating_add(i)) else {
                return false;
            };
            *slot = d;
        }
        true
    }

    /// The candidate continuation: the call's depth, the rest of its
    /// optimized horizon (`z`, `h` tracks), then the previous continuation
    /// beyond it (or the climb to `shallow`, m).
    pub(super) fn candidate_continuation(
        &self,
        (track, len): (usize, usize),
        (depth, (z, h)): (f32, (&[f32; K], usize)),
        shallow: f32,
    ) -> [f32; MAX_TRACKS] {
        let mut c = [shallow; MAX_TRACKS];
        for (i, slot) in c.iter_mut().enumerate().take(len) {
            let t = track.saturating_add(i);
            *slot = match i {
                0 => depth,
                i if i < h => z.get(i).copied().unwrap_or(shallow),
                _ => self.cont.depth(t).unwrap_or(shallow),
            };
        }
        c
    }

    /// The certificate of the candidate's track alone: its nominal flight
    /// when that is the only world over the map, else the worlds' flights
    /// (partial below `floor`, m, see [`Tube::certify`]).
    fn certify_one(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        (state, flown): (&VehicleState<N>, &Flown<N>),
        (floor, flights): (f32, &mut u32),
    ) -> Certificate {
        if nominal_only(sc, bottom, &self.tube, state) {
            self.tube.of_flight(flown.score.min_altitude())
        } else {
            self.tube
                .certify(sc, bottom, &[flown.depth], (floor, flights))
        }
    }

    /// Keeps the committed continuation and, where the commit moved off
    /// the candidate, restarts the warm start from the committed
    /// continuation (a certified point).
    fn keep(&mut self, chosen: &Chosen<N>, track: usize, guaranteed: bool) {
        self.cont = Continuation::NONE;
        if guaranteed {
            self.cont.track = track.saturating_add(1);
            self.cont.len = chosen.len.saturating_sub(1);
            for (dst, src) in self
                .cont
                .depths
                .iter_mut()
                .zip(chosen.depths.iter().skip(1))
            {
                *dst = *src;
            }
        }
        if let Some(first) = self.work.z.first_mut() {
            *first = chosen.depths[0];
        }
        if (chosen.searched || chosen.previous)
            && let Some(w) = self.warm.as_mut()
        {
            for (dst, src) in w
                .depths
                .iter_mut()
                .zip(chosen.depths.iter().skip(1))
                .take(w.len)
            {
                *dst = *src;
            }
        }
    }

    /// What the plan is: not certified, infeasible; certified on the
    /// constraint's boundary (found on it, or within the penalty margin
    /// and 1 % of `h_r − h_a` of the certified altitude), constrained;
    /// else optimal.
    fn status(
        &self,
        sc: &Scenario<'_, N>,
        cand: &Candidate<N>,
        chosen: &Chosen<N>,
        safe: bool,
    ) -> PlanStatus {
        let m = sc.mission();
        let near = self.cfg.penalty_margin + 0.01 * (m.reference_altitude() - m.min_altitude());
        if !safe {
            PlanStatus::Infeasible
        } else if chosen.searched
            || matches!(cand.found, Found::Boundary(_) | Found::Infeasible(_))
            || chosen.cert.first < cand.h_safe + near
        {
            PlanStatus::Constrained
        } else {
            PlanStatus::Optimal
        }
    }

    /// The one place a [`Plan`] is built and logged.
    fn answer(
        &mut self,
        f: Flown<N>,
        cand: &Candidate<N>,
        (status, safe, certified): (PlanStatus, bool, f32),
        evaluations: u32,
    ) -> Plan<N> {
        let plan = Plan {
            depth: f.depth,
            status,
            optimizer: cand.found.stop(),
            safe,
            j: f.score.j(),
            rms: f.score.rms(),
            min_altitude: f.score.min_altitude(),
            certified_min_altitude: certified,
            objective: self.work.j,
            iterations: cand.iterations,
            evaluations,
            grad_norm: self.work.grad_norm,
            horizon_len: self.horizon_len,
            next_state: f.next,
        };
        crate::log::debug!(
            "plan: depth {=f32} m, {=str} ({=str}), J {=f32} m3, min altitude {=f32} m (certified {=f32} m), {=u32} iterations, {=u32} evaluations",
            plan.depth,
            plan.status.as_str(),
            plan.optimizer.as_str(),
            plan.j,
            plan.min_altitude,
            plan.certified_min_altitude,
            plan.iterations,
            plan.evaluations
        );
        plan
    }
}

/// Whether the only world is the nominal one over the map, from `state`:
/// the nominal flight is then the certificate.
pub(super) fn nominal_only<const N: usize>(
    sc: &Scenario<'_, N>,
    bottom: ProfileView<'_>,
    tube: &Tube<N>,
    state: &VehicleState<N>,
) -> bool {
    let over_map = bottom.positions().as_ptr() == sc.profile().positions().as_ptr();
    over_map && tube.nominal_only(&World::nominal(sc.vehicle()), state)
}

/// The bottom certificates are flown over: the scenario's certification
/// bottom, or the map itself when the map is declared exact.
pub(super) fn certification_bottom<'a, const N: usize>(
    sc: &Scenario<'a, N>,
) -> Result<ProfileView<'a>, PlanError> {
    match sc.certification_bottom() {
        Some(b) => Ok(b),
        None if !sc.mission().uncertainty().map_uncertain() => Ok(sc.profile()),
        None => Err(PlanError::NoCertificationBottom),
    }
}
