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
//! altitude). With no anchor certified, the call is `infeasible` and
//! commits the safest continuation it tried. So whatever the horizon, the
//! iteration cap or the budget, once a call has committed a certified
//! continuation every later call has one: fewer iterations cost `J`, never
//! safety.
//!
//! **Track-wise mode** (the paper's) and **unconstrained** plans commit the
//! candidate alone: its own track is certified and reported, nothing
//! beyond it is promised.

use crate::model::ProfileView;
use crate::optim::root::{self, RootTol};
use crate::sim::{Scenario, VehicleState, World};

use super::candidate::Candidate;
use super::certify::{Certificate, Tube, vehicle_margin};
use super::fallback::Flown;
use super::flights::Flights;
use super::planner::{Continuation, MAX_TRACKS};
use super::status::Found;
use super::{Mode, Plan, PlanError, PlanStatus, Planner};

/// The certified-altitude tolerance of the continuation search, m (as the
/// single track's boundary search: 0.2 % of `h_r − h_a`, 1 mm to 2 cm).
const SEARCH_SHARE: f32 = 0.002;

/// The search stops when the step along the path is this short (of 1).
const SEARCH_WIDTH: f32 = 1e-3;

/// Most rounds of the continuation search (a round: a root search in the
/// critical worlds, then the point found certified in every world).
const SEARCH_ROUNDS: u32 = 4;

/// The search path's ends: the certified anchor and the candidate, each
/// with its certificate.
type Ends<'c, const N: usize> = (
    (&'c [f32; MAX_TRACKS], Certificate),
    (&'c [f32; MAX_TRACKS], Certificate),
);

/// A search bracket: the safe end and the unsafe one, each a point on the
/// path (of 1) with its certified margin over `h_safe`, m.
type Bracket = ((f32, f32), (f32, f32));

/// A continuation with its certificate.
#[derive(Clone, Copy, Debug)]
struct Chosen<const N: usize> {
    depths: [f32; MAX_TRACKS],
    len: usize,
    cert: Certificate,
    /// Whether it was found on the search path (not the candidate itself).
    searched: bool,
}

impl<const K: usize, const N: usize> Planner<K, N> {
    /// Commits the call's depth: certifies it (with its continuation in
    /// horizon mode), moves the worlds' states on, builds the one [`Plan`].
    pub(super) fn commit(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
        cand: Candidate<N>,
    ) -> Result<Plan<N>, PlanError> {
        let bottom = certification_bottom(sc)?;
        let u = sc.mission().uncertainty();
        let worlds = (
            World::corners(sc.vehicle(), u),
            vehicle_margin(sc.vehicle(), u),
        );
        self.tube.prepare(worlds, state, track);
        let mut flights = cand.evaluations;
        let guaranteed = self.cfg.mode == Mode::Horizon && self.cfg.constrained;
        let chosen = if guaranteed {
            let c = self.continue_safely(sc, bottom, (state, track), &cand, &mut flights)?;
            self.completed(sc, bottom, c, &mut flights)
        } else {
            let mut depths = [0.0; MAX_TRACKS];
            depths[0] = cand.flown.depth;
            let at = (f32::NEG_INFINITY, &mut flights);
            let cert = self.certify_one(sc, bottom, (state, &cand.flown), at);
            Chosen {
                depths,
                len: 1,
                cert,
                searched: false,
            }
        };
        let depth = chosen.depths[0];
        let flown = if depth.to_bits() == cand.flown.depth.to_bits() {
            cand.flown
        } else {
            let mut fl = Flights {
                sc: *sc,
                state,
                track,
                count: flights,
                limit: u32::MAX,
            };
            let (score, next) = fl.fly(depth)?;
            flights = fl.count;
            Flown { depth, score, next }
        };
        self.keep(&chosen, track, guaranteed);
        let only_nominal = nominal_only(sc, bottom, &self.tube, state);
        self.tube.advance(
            (sc, bottom),
            depth,
            &flown.next,
            (only_nominal, &mut flights),
        );
        let safe = chosen.cert.all >= cand.h_safe;
        self.cont.certified = (guaranteed && safe).then_some(chosen.cert);
        let status = self.status(sc, &cand, &chosen, safe);
        Ok(self.answer(flown, &chosen, &cand, (status, safe), flights))
    }

    /// The continuation to commit (module docs): the candidate if it
    /// certifies, else the last certified point on the path from an
    /// anchor, else the safest tried.
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
        let c = self.candidate_continuation(track, len, cand.flown.depth, shallow);
        let cert_c = self.certify_candidate(sc, bottom, (state, cand), (&c, len), flights);
        let candidate = Chosen {
            depths: c,
            len,
            cert: cert_c,
            searched: false,
        };
        if cert_c.all >= cand.h_safe {
            return Ok(candidate);
        }
        // The candidate's depth, then the climb: the optimized later depths
        // may lead into a trap that the next call's horizon would see and
        // avoid, while the committed depth alone need not.
        let mut c2 = [shallow; MAX_TRACKS];
        c2[0] = cand.flown.depth;
        // (The same line as the candidate when its tail is the climb
        // already: its certificate is at hand.)
        let same = c2.iter().zip(&c).all(|(a, b)| a.to_bits() == b.to_bits());
        let cert_c2 = if same {
            cert_c
        } else {
            let spare = self.budget.anchor;
            let at = (cand.h_safe, &mut *flights);
            self.certify_within(sc, bottom, c2.get(..len).unwrap_or(&[]), at, spare)
        };
        if cert_c2.all >= cand.h_safe {
            return Ok(Chosen {
                depths: c2,
                len,
                cert: cert_c2,
                searched: false,
            });
        }
        let (c, cert_c) = if cert_c2.all > cert_c.all {
            (c2, cert_c2)
        } else {
            (c, cert_c)
        };
        // Anchors: the previous continuation, then the climb.
        let prev = self.previous_continuation(track, len, shallow);
        let mut best = candidate;
        let anchors = prev.map(|p| (p, true)).into_iter();
        for (a, is_prev) in anchors.chain([([shallow; MAX_TRACKS], false)]) {
            let cert_a = match self.budget.known_anchor(is_prev, (&a, &c, cert_c), len) {
                Some(known) => known,
                None => {
                    let at = (cand.h_safe, &mut *flights);
                    self.certify_within(sc, bottom, a.get(..len).unwrap_or(&[]), at, 0)
                }
            };
            if cert_a.all >= cand.h_safe {
                let ends = ((&a, cert_a), (&c, cert_c));
                return Ok(self.search(sc, bottom, ends, len, cand.h_safe, flights));
            }
            if cert_a.all > best.cert.all {
                best = Chosen {
                    depths: a,
                    len,
                    cert: cert_a,
                    searched: true,
                };
            }
        }
        Ok(best)
    }

    /// `chosen` with its certificate complete: a partial one (some worlds
    /// left unflown, its altitudes upper bounds) is flown again in every
    /// world, budget permitting (else it is no certificate at all).
    fn completed(
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
    fn certify_candidate(
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
    /// if it covers them all.
    fn previous_continuation(
        &self,
        track: usize,
        len: usize,
        shallow: f32,
    ) -> Option<[f32; MAX_TRACKS]> {
        let mut a = [shallow; MAX_TRACKS];
        for (i, slot) in a.iter_mut().enumerate().take(len) {
            *slot = self.cont.depth(track.saturating_add(i))?;
        }
        Some(a)
    }

    /// The candidate continuation: the call's depth, its optimized
    /// horizon, then the previous continuation beyond it (or the climb to
    /// `shallow`, m).
    fn candidate_continuation(
        &self,
        track: usize,
        len: usize,
        depth: f32,
        shallow: f32,
    ) -> [f32; MAX_TRACKS] {
        let mut c = [shallow; MAX_TRACKS];
        for (i, slot) in c.iter_mut().enumerate().take(len) {
            let t = track.saturating_add(i);
            *slot = match i {
                0 => depth,
                i if i < self.horizon_len => self.work.z.get(i).copied().unwrap_or(shallow),
                _ => self.cont.depth(t).unwrap_or(shallow),
            };
        }
        c
    }

    /// The last certified point on the path `a + t (c − a)`, `t ∈ [0, 1]`,
    /// from the certified anchor `a` towards the candidate `c`.
    ///
    /// The root search flies only the *critical* worlds (those that have
    /// set a certificate's least altitude, [`Tube::critical`]): their
    /// least altitude bounds the certificate from above, so a point they
    /// reject is rejected. The point found is then certified in every
    /// world; if another world rejects it, that world becomes critical, the
    /// point becomes the bracket's unsafe end and the search goes on (at
    /// most [`SEARCH_ROUNDS`] rounds, then the last certified point).
    fn search(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        ((a, cert_a), (c, cert_c)): Ends<'_, N>,
        len: usize,
        h_safe: f32,
        flights: &mut u32,
    ) -> Chosen<N> {
        let at = |t: f32| -> [f32; MAX_TRACKS] {
            core::array::from_fn(|i| {
                let (ai, ci) = (
                    a.get(i).copied().unwrap_or(0.0),
                    c.get(i).copied().unwrap_or(0.0),
                );
                ai + t * (ci - ai)
            })
        };
        let m = sc.mission();
        let rule = RootTol {
            tol: (SEARCH_SHARE * (m.reference_altitude() - m.min_altitude())).clamp(1e-3, 0.02),
            width: SEARCH_WIDTH,
            steps: self.cfg.bisection_steps,
        };
        let mut good = (0.0, cert_a);
        let mut bad = (1.0, cert_c.all - h_safe);
        for _ in 0..SEARCH_ROUNDS {
            let ends = ((good.0, good.1.all - h_safe), bad);
            let ends = (ends, h_safe);
            let Some((t, screened)) =
                self.screened_root(sc, bottom, (&at, len), ends, rule, flights)
            else {
                break;
            };
            // (Every world flown already when all are critical.)
            let cert = if screened.partial {
                if !self.budget.afford(*flights) {
                    break;
                }
                let d = at(t);
                let d = d.get(..len).unwrap_or(&[]);
                self.tube.certify(sc, bottom, d, (h_safe, &mut *flights))
            } else {
                screened
            };
            if cert.all >= h_safe {
                good = (t, cert);
                break;
            }
            bad = (t, cert.all - h_safe);
        }
        Chosen {
            depths: if good.0 > 0.0 { at(good.0) } else { *a },
            len,
            cert: good.1,
            searched: true,
        }
    }

    /// One round of [`Planner::search`]: the boundary of the critical
    /// worlds' certificate between `good` and `bad` (`t` with its margin
    /// over `h_safe`, m) with that certificate, or `None` where it did not
    /// move off `good`.
    fn screened_root<F: Fn(f32) -> [f32; MAX_TRACKS]>(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        (at, len): (&F, usize),
        ((good, bad), h_safe): (Bracket, f32),
        rule: RootTol,
        flights: &mut u32,
    ) -> Option<(f32, Certificate)> {
        let budget = self.budget;
        let mask = self.tube.critical();
        let r = root::safe_boundary((good.0, Some(good.1)), (bad.0, Some(bad.1)), rule, |t| {
            if !budget.afford(*flights) {
                return Err(());
            }
            let d = at(t);
            let d = d.get(..len).unwrap_or(&[]);
            let cert = self.tube.certify_only(sc, bottom, d, mask, flights);
            Ok::<_, ()>((cert.all - h_safe, cert))
        });
        let root = r.ok()?;
        root.at.filter(|_| root.z > good.0).map(|c| (root.z, c))
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
        if chosen.searched
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
        chosen: &Chosen<N>,
        cand: &Candidate<N>,
        (status, safe): (PlanStatus, bool),
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
            certified_min_altitude: chosen.cert.first,
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
