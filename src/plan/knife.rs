//! A candidate's depth moved off a waypoint's knife edge.
//!
//! The reference switches to the next track at the first sample at or past
//! its waypoint (contract §3). Where the candidate's flight puts a sample
//! within a hair of the waypoint that ends its track, the same depths flown
//! in other arithmetic (an f64 implementation, or the vehicle itself) can
//! switch one sample earlier or later: the next track's cascade then runs
//! one step on the other reference, and its `J` moves by far more than the
//! rounding. Found by `tools/reference/check_planner.py --seed 1602`
//! (`unseen_1602_2`, track-wise unconstrained): track 3's last sample
//! landed 0.1 mm short of waypoint 3 after 13 574 steps, the f64 flight's
//! one step past it, and track 4's `J` differed by 2.2e-3 relative (the
//! checker allows 1e-3). Over 888 crossings of 256 random lines, the f32
//! and f64 flights of the same depths put the sample nearest a waypoint
//! 0.05 mm apart at the median and 0.8 mm at most.
//!
//! So a candidate whose sample nearest that waypoint lies within [`EDGE`]
//! of it is moved: a probe a few millimetres shallower measures how the
//! sample moves with the depth, and a secant step puts it twice [`EDGE`]
//! from the waypoint, shallower first (safe where the candidate sits on
//! its safe boundary), then deeper. A move is kept only when its flight
//! clears the edge, stays in the search box and as safe as the candidate
//! (or at least `h_a + m_s`), and raises the track's `J` by at most
//! [`J_SHARE`]. At most four flights, taken about once in fifty track
//! ends; within a budget, only flights the candidate's share still has.
//! Where the sample does not move with the depth (a saturated climb or
//! dive through the waypoint), the depth is kept, and the edge stays: on
//! `check_planner.py --seed 1801`, `unseen_1801_6` (horizon), track 4's
//! climb reaches waypoint 4 0.1 mm past it whatever its depth, and track
//! 5's `J` differs from the f64 re-simulation's by 2.1e-3. In horizon
//! mode the call before moves its own depth for such a track where it
//! can (`ahead.rs`).
//!
//! The move is made under declared uncertainty too, shallower only: the
//! declared worlds then certify the moved depth, which costs no more than
//! the candidate's own certificate, but a deeper move can lower a
//! certificate that held by centimetres, and the call then searches
//! (`check_certified.py --seed 2463`, `synthetic_023`: 265 flights for
//! the line became 562). Under declared motion the worlds switch at their
//! own samples and the vehicle margin covers the switch, but the nominal
//! `min_altitude` reported after the edge is one arithmetic's:
//! `check_certified.py --seed 2451`, `synthetic_034` (horizon, `ε_U` and
//! `e_v` declared), track 1 committed on the edge, and tracks 2–5's
//! reported altitudes were 5–6 cm off an f64 re-flight's; moved 2.2 cm
//! shallower, they agree.
//!
//! What no move can avoid, the certificates fly both ways: with one
//! vehicle world (nothing declared, or only the map), a certificate flies
//! the rest of the line from the other switch's state too wherever a track
//! ends on the edge (`certify/flight.rs`), and a committed depth that ends on
//! it leaves that state in the tube as a branch, flown by every later
//! certificate ([`Planner::branch_off_the_edge`]).
//!
//! Track by track, constrained, the committed depth's branch is kept too
//! (the tool's line certificate flies the other switch as well,
//! `certify_line`), and the next track's candidate is aimed past it
//! ([`Planner::raised_past_the_branch`]). On `check_planner.py --seed 2867
//! --vehicle tools/reference/vehicles/stiff.toml`, `unseen_2867_7`, track
//! 3 ended 1.2 mm short of waypoint 3 and could not move (its sample moves
//! 1.6 cm per metre of depth: 0.33 m shallower, past [`MOST`], or 0.17 m
//! deeper, below `h_a`); track 4's candidate cleared `h_a + m_s` by
//! 0.01 mm in its own flight and by −3.4 cm from the other switch's
//! state, and the line was reported `infeasible` there although a depth
//! 7 cm shallower is safe both ways. Aimed past the branch: 60.038 m in
//! its own flight, `constrained`, `J` 1.0041× the f64 best from one
//! switch's state.
//!
//! A move drops the later tracks' certification gaps (`gaps.rs`): they
//! were screened from the depth on the edge, whose other switch can set a
//! later track's least altitude centimetres apart, and the last call of
//! a line aims at its kept gap without screening again
//! (`check_planner.py --seed 3223 --vehicle
//! tools/reference/vehicles/slow.toml`, `unseen_3223_2`: a gap of 8.4 cm
//! kept from the edge lifted the last track's target above a plateau 2 cm
//! over `h_a`, 50 m short of the best plan's depth).
//!
//! In horizon mode, constrained, a call may commit the previous call's
//! continuation instead of its candidate (`commit.rs`): where that
//! continuation's first depth is on the edge and the candidate is not,
//! the call takes the candidate's way (certifies it, or searches), with
//! one vehicle world ([`one_vehicle`]). Under declared motion the
//! candidate's certificate costs a flight of the line per declared world
//! where the kept continuation's is known, and a failed one a search
//! (Monterey 1 with the README's declared uncertainty: call 4 kept a
//! continuation whose sample lies 1.4 mm past waypoint 4, and certifying
//! the candidate instead took the call from 12 flights to 159). There the
//! candidate is certified, and no search made, only where the kept
//! continuation's sample lies within [`INNER`] of the waypoint, half the
//! edge (the f32 and f64 samples were 0.8 mm apart at most, above), and
//! committed where it certifies; else the continuation is kept on its
//! edge. On `check_certified.py --seed 2537 --bounds-kind motion`
//! (Monterey 1, `b2`: `ε_U` 0.005) call 2 kept a continuation whose
//! sample lay 0.1 mm past waypoint 2 (7.6 µm short of it in f64), and
//! tracks 3 and 4's reported altitudes were 7 cm off an f64
//! re-flight's; the candidate, 1.8 cm shallower, certifies (3 flights
//! more) and they agree within a millimetre.

use crate::model::ProfileView;
use crate::sim::{EDGE, Scenario, TrackScore, VehicleState, World, offset};

use super::candidate::{Candidate, boundary_tolerance};
use super::certify::ALL;
use super::chosen::Chosen;
use super::fallback::Flown;
use super::flights::Flights;
use super::planner::MAX_TRACKS;
use super::scan::search_box;
use super::{Mode, Planner};

/// First probe, m of depth.
pub(super) const PROBE: f32 = 5e-3;

/// Longest move, m of depth.
pub(super) const MOST: f32 = 0.25;

/// Under declared motion, the half-width (m) of the knife edge within
/// which a kept continuation is left for the candidate (module docs).
const INNER: f32 = 0.5 * EDGE;

/// Most relative rise of the track's `J` a move may cost.
const J_SHARE: f32 = 1e-3;

/// Whether the declared worlds fly one vehicle, the nominal one: nothing
/// declared, or only the map (its worlds differ in the bottom, which moves
/// no state, so every world switches where the nominal flight does). Then
/// a knife edge's other switch is flown as a world of its own. Under
/// declared motion (speed, path offset, current) each world switches at
/// its own sample, and the vehicle margin's floor of two samples' climb
/// covers the switch (`certify/mod.rs`, `flight.rs`).
pub(super) fn one_vehicle<const N: usize>(sc: &Scenario<'_, N>) -> bool {
    !sc.mission().uncertainty().motion_uncertain()
}

impl<const K: usize, const N: usize> Planner<K, N> {
    /// Moves the candidate off the knife edge of the waypoint that ends
    /// its track (module docs), when a next track follows, the candidate's
    /// certificate is not already known, and a move is found; its flights
    /// counted in the candidate's.
    #[inline(never)]
    pub(super) fn off_the_edge(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
        cand: &mut Candidate<N>,
    ) {
        let Some(end) = sc.edge_waypoint(track) else {
            return;
        };
        if cand.cert.is_some() || !sc.on_edge(track, &cand.flown.next) {
            return;
        }
        let v0 = offset(&cand.flown.next, end);
        let mut fl = self.move_flights((sc, state, track), cand, self.budget.candidate);
        let b = search_box::<N, 1>(sc, state, track, 1);
        let (lo, hi) = (b.lo.first().copied(), b.hi.first().copied());
        let box_ = (lo.unwrap_or(f32::NAN), hi.unwrap_or(f32::NAN));
        // Under declared uncertainty, shallower only (module docs).
        let sides: &[f32] = if sc.mission().uncertainty().is_none() {
            &[-1.0, 1.0]
        } else {
            &[-1.0]
        };
        let found = sides
            .iter()
            .find_map(|&side| self.move_off(&mut fl, cand, (end, v0), side, box_));
        cand.evaluations = fl.count;
        if let Some(f) = found {
            self.take_move(cand, track, f);
        }
    }

    /// The flights of a move of the candidate's depth from `state` on
    /// `track`: the candidate's own flights' scenario, counted on from
    /// its evaluations, at most `limit`.
    pub(super) fn move_flights<'s, 'a>(
        &self,
        (sc, state, track): (&Scenario<'a, N>, &'s VehicleState<N>, usize),
        cand: &Candidate<N>,
        limit: u32,
    ) -> Flights<'s, 'a, N> {
        Flights {
            sc: self.penalized(sc, self.horizon_len),
            state,
            track,
            count: cand.evaluations,
            limit,
        }
    }

    /// The candidate moved to `f` (its depth, first in the workspace's
    /// horizon too). The later tracks' gaps were screened from the depth
    /// before the move, which a knife edge's other switch may have set:
    /// the next calls screen their own.
    pub(super) fn take_move(&mut self, cand: &mut Candidate<N>, track: usize, f: Flown<N>) {
        cand.flown = f;
        if let Some(first) = self.work.z.first_mut() {
            *first = f.depth;
        }
        let later = self
            .gaps
            .get_mut(track.saturating_add(1)..)
            .unwrap_or(&mut []);
        later.iter_mut().for_each(|g| *g = 0.0);
    }

    /// With one vehicle world ([`one_vehicle`]), where the committed
    /// flight ends on its waypoint's knife edge, the tube's branch from
    /// the other switch's state (`Tube::branch`): the committed depth's
    /// certificate flew it already (`certify/flight.rs`), and every later
    /// call's certificates fly it too, so that the line stays certified
    /// however the vehicle's arithmetic switches there. A budgeted call
    /// carries no branch: every later call would fly it, and its least
    /// budget would be a flight more (a budgeted call's certificates still
    /// fly an edge's other switch when their flights allow,
    /// `certify/flight.rs`).
    #[inline(never)]
    pub(super) fn branch_off_the_edge(
        &mut self,
        sc: &Scenario<'_, N>,
        (state, track): (&VehicleState<N>, usize),
        flown: &Flown<N>,
        flights: &mut u32,
    ) {
        let budgeted = self.budget.limit != u32::MAX;
        if budgeted || !one_vehicle(sc) || !sc.on_edge(track, &flown.next) {
            return;
        }
        *flights = flights.saturating_add(1);
        let (mut from, mut other) = (*state, flown.next);
        let mut score = [TrackScore::default()];
        let at = (track, flown.depth);
        if sc
            .switch_other_way((&mut from, &mut other), at, &mut score)
            .is_ok()
        {
            self.tube.branch(World::nominal(sc.vehicle()), &other);
        }
    }

    /// Track by track, constrained, with nothing declared (called by the
    /// unbudgeted call alone, `planner.rs`: a budgeted call keeps no
    /// branch):
    /// where the track before ended on its waypoint's knife edge (the
    /// tube holds its branch at this track, [`Planner::branch_off_the_edge`])
    /// and the candidate `c` clears `h_safe` in its own flight but not
    /// from the other switch's state, raises the track's gap (`gaps.rs`)
    /// by the branch's shortfall and a tenth of a boundary tolerance, and
    /// returns the certificate's flights (two): the caller aims the
    /// candidate again, at most three times (`planner.rs`, module docs).
    /// `None` where nothing is to be raised. Not inlined: its frame stays
    /// off the candidate's stack.
    #[inline(never)]
    pub(super) fn raised_past_the_branch(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
        c: &Candidate<N>,
    ) -> Option<u32> {
        let m = sc.mission();
        let wanted = self.cfg.mode == Mode::TrackWise
            && self.cfg.constrained
            && m.uncertainty().is_none()
            && self.tube.branched_at(state, track);
        let h_safe = self.cfg.certified_altitude(m);
        if !wanted || c.flown.score.min_altitude() < h_safe {
            return None;
        }
        // (Nothing declared: the map is the certification bottom.)
        let bottom = sc.profile();
        let mut flights = 0_u32;
        self.tube
            .materialize((sc, bottom), (state, track), (ALL, &mut flights));
        let at = (f32::NEG_INFINITY, &mut flights);
        let short = h_safe - self.tube.certify(sc, bottom, &[c.flown.depth], at).all;
        // (A failed flight's certificate is −∞: nothing to aim at.)
        if short <= 0.0 || !short.is_finite() {
            return None;
        }
        let more = 0.1 * boundary_tolerance(m.reference_altitude() - m.min_altitude());
        *self.gaps.get_mut(track)? += short + more;
        Some(flights)
    }

    /// Under declared motion, where the previous call's continuation,
    /// kept, ends its first track (`kept`, its nominal flight) within
    /// [`INNER`] of the waypoint and the candidate does not end on the
    /// edge: the candidate continuation if it certifies, no search made
    /// (module docs). Not inlined: its frame stays off the commit's stack.
    #[inline(never)]
    pub(super) fn off_kept_edge(
        &mut self,
        (sc, bottom): (&Scenario<'_, N>, ProfileView<'_>),
        (state, track): (&VehicleState<N>, usize),
        (cand, kept): (&Candidate<N>, &Flown<N>),
        flights: &mut u32,
    ) -> Option<Chosen<N>> {
        let end = sc.edge_waypoint(track)?;
        let len = sc.waypoints().tracks().saturating_sub(track);
        if libm::fabsf(offset(&kept.next, end)) >= INNER || len > MAX_TRACKS {
            return None;
        }
        self.tube
            .materialize((sc, bottom), (state, track), (ALL, &mut *flights));
        let shallow = sc.mission().depth_limits()[0];
        let horizon = (&self.work.z, self.horizon_len);
        let c = self.candidate_continuation((track, len), (cand.flown.depth, horizon), shallow);
        let cert = self.certify_candidate(sc, bottom, (state, cand), (&c, len), flights);
        // (A failed certificate stops at its first world below `h_safe`:
        // not flown in full for nothing.)
        if cert.all < cand.h_safe {
            return None;
        }
        let chosen = self.completed(sc, bottom, Chosen::new(c, len, cert), flights);
        (chosen.cert.all >= cand.h_safe).then_some(chosen)
    }

    /// One side's move (`side` −1: shallower, +1: deeper): the probe,
    /// then the secant step to twice [`EDGE`] past the waypoint's
    /// nearest sample; the first flight that [`Planner::keeps`] accepts.
    fn move_off(
        &self,
        fl: &mut Flights<'_, '_, N>,
        cand: &Candidate<N>,
        (end, v0): (f32, f32),
        side: f32,
        (lo, hi): (f32, f32),
    ) -> Option<Flown<N>> {
        let z0 = cand.flown.depth;
        let z1 = z0 + side * PROBE;
        let (s1, n1) = fl.fly(z1).ok()?;
        let v1 = offset(&n1, end);
        let probe = Flown {
            depth: z1,
            score: s1,
            next: n1,
        };
        if self.keeps(cand, &probe, v1, (lo, hi)) {
            return Some(probe);
        }
        // How the nearest sample moves per metre of depth.
        let slope = (v1 - v0) / (z1 - z0);
        // The target on the side this direction moves the sample to.
        let target = if slope * side > 0.0 { 2.0 } else { -2.0 } * EDGE;
        let dz = (target - v0) / slope;
        let forward = dz * side > 0.0 && libm::fabsf(dz) <= MOST;
        if !forward {
            return None;
        }
        let z2 = z0 + dz;
        let (s2, n2) = fl.fly(z2).ok()?;
        let second = Flown {
            depth: z2,
            score: s2,
            next: n2,
        };
        self.keeps(cand, &second, offset(&n2, end), (lo, hi))
            .then_some(second)
    }

    /// Whether a moved depth's flight `f`, its nearest sample at `v` from
    /// the waypoint, may replace the candidate (module docs).
    pub(super) fn keeps(
        &self,
        cand: &Candidate<N>,
        f: &Flown<N>,
        v: f32,
        (lo, hi): (f32, f32),
    ) -> bool {
        let (s0, s): (&TrackScore, &TrackScore) = (&cand.flown.score, &f.score);
        let floor = s0.min_altitude().min(cand.h_safe);
        let safe = !self.cfg.constrained || s.min_altitude() >= floor;
        let j_ok = s.j() <= s0.j() + J_SHARE * libm::fabsf(s0.j());
        libm::fabsf(v) >= EDGE && f.depth >= lo && f.depth <= hi && safe && j_ok
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Mission, Profile, Uncertainty, Vehicle, Waypoints};
    use crate::plan::status::Found;
    use crate::plan::{Mode, OptimizerStop, PlannerConfig, certify_line};

    /// Track 1 flown at `z`: its score and the state past waypoint 1.
    fn fly(sc: &Scenario<'_, 3>, start: &VehicleState<3>, z: f32) -> Flown<3> {
        let mut s = [TrackScore::default()];
        let next = sc.fly(start, 0, &[z], &mut s).unwrap();
        Flown {
            depth: z,
            score: s[0],
            next,
        }
    }

    /// A depth whose flight puts a sample within 0.1 mm of waypoint 1
    /// (`end`): a 1 cm scan for a zero crossing of the nearest sample's
    /// offset (not one of its jumps by a step), then bisection.
    fn on_the_edge(sc: &Scenario<'_, 3>, start: &VehicleState<3>, end: f32) -> Flown<3> {
        let v = |z: f32| offset(&fly(sc, start, z).next, end);
        let near = |a: f32| libm::fabsf(a) < 0.04;
        let mut a = 200.0_f32;
        while !(near(v(a)) && near(v(a + 0.01)) && v(a) * v(a + 0.01) <= 0.0) {
            a += 0.01;
            assert!(a < 260.0, "no crossing");
        }
        let (mut lo, mut hi) = (a, a + 0.01);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if v(mid) * v(lo) <= 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let f = fly(sc, start, lo);
        assert!(libm::fabsf(offset(&f.next, end)) < 1e-4);
        f
    }

    fn candidate(flown: Flown<3>, h_safe: f32) -> Candidate<3> {
        Candidate {
            flown,
            found: Found::Optimized(OptimizerStop::Converged),
            iterations: 0,
            evaluations: 0,
            h_safe,
            cert: None,
            previous_j: None,
        }
    }

    /// A candidate whose track ends a hair from its waypoint is moved off
    /// it, unconstrained and on its safe boundary alike, with or without
    /// declared motion, for little `J`; one on the line's last track is
    /// left.
    #[test]
    fn a_candidate_on_a_waypoints_knife_edge_is_moved_off_it() {
        let v = Vehicle::c_auv4().unwrap();
        let p =
            Profile::<8>::new(&[0.0, 400.0, 700.0, 1500.0], &[300.0, 300.0, 180.0, 200.0]).unwrap();
        let w = Waypoints::<4>::new(&[0.0, 600.0, 1400.0]).unwrap();
        let sc = Scenario::new(&v, &p, &w, Mission::default()).unwrap();
        let start = sc.start_state(220.0);
        let edge = on_the_edge(&sc, &start, 600.0);
        // Nothing declared, and the vehicle's motion declared (its
        // nominal flight the same).
        let u = Uncertainty::new(0.0, 0.0, 0.0, 0.05, 0.5, 0.02).unwrap();
        let declared = Scenario::new(&v, &p, &w, Mission::default().with_uncertainty(u)).unwrap();
        for (sc, constrained) in [(sc, false), (sc, true), (declared, true)] {
            let cfg = PlannerConfig {
                mode: Mode::TrackWise,
                constrained,
                ..PlannerConfig::default()
            };
            let mut planner = Planner::<1, 3>::new(cfg).unwrap();
            // On its boundary: the moved depth must stay as safe.
            let mut c = candidate(edge, edge.score.min_altitude());
            planner.off_the_edge(&sc, &start, 0, &mut c);
            let moved = c.flown;
            assert!(libm::fabsf(offset(&moved.next, 600.0)) >= EDGE, "{moved:?}");
            assert!(libm::fabsf(moved.depth - edge.depth) <= MOST);
            assert!(moved.score.j() <= (1.0 + J_SHARE) * edge.score.j());
            assert!((1..=4).contains(&c.evaluations), "{}", c.evaluations);
            assert_eq!(planner.work.z[0].to_bits(), moved.depth.to_bits());
            // The same flight as a fresh one at the moved depth.
            assert_eq!(fly(&sc, &start, moved.depth).next, moved.next);
            if constrained {
                assert!(moved.score.min_altitude() >= edge.score.min_altitude());
            }
        }
        // The line's last track: no next track, nothing moved.
        let mut planner = Planner::<1, 3>::new(PlannerConfig::default()).unwrap();
        let mut c = candidate(edge, 0.0);
        planner.off_the_edge(&sc, &edge.next, 1, &mut c);
        assert_eq!(
            (c.flown.depth.to_bits(), c.evaluations),
            (edge.depth.to_bits(), 0)
        );
    }

    /// With only the map declared (one vehicle world), a certificate of a
    /// line whose first track ends on its waypoint's knife edge bounds the
    /// next track's flight from either switch: the f64 checker's flight of
    /// the same depths may switch the other way, and no vehicle margin
    /// covers a sample's shift there.
    #[test]
    fn with_only_the_map_declared_a_certificate_flies_both_switches() {
        let v = Vehicle::c_auv4().unwrap();
        let (xs, bs) = ([0.0, 400.0, 700.0, 1500.0], [300.0, 300.0, 180.0, 200.0]);
        let p = Profile::<8>::new(&xs, &bs).unwrap();
        let w = Waypoints::<4>::new(&[0.0, 600.0, 1400.0]).unwrap();
        let sc = Scenario::new(&v, &p, &w, Mission::default()).unwrap();
        let start = sc.start_state(220.0);
        let edge = on_the_edge(&sc, &start, 600.0);
        // The map 2 m shallower: the certification bottom of e_v = 2 m.
        let u = Uncertainty::new(0.0, 0.0, 2.0, 0.0, 0.0, 0.0).unwrap();
        let raised = Profile::<8>::new(&xs, &bs.map(|b| b - 2.0)).unwrap();
        let scu = Scenario::new(&v, &p, &w, Mission::default().with_uncertainty(u)).unwrap();
        let over = sc.in_world(&World::nominal(&v), raised.view()).unwrap();
        let mut other = edge.next;
        let mut s = [TrackScore::default()];
        over.switch_other_way((&mut start.clone(), &mut other), (0, edge.depth), &mut s)
            .unwrap();
        let mut apart = 0.0_f32;
        for z2 in [100.0, 130.0, 160.0, 190.0, 220.0, 250.0] {
            let mut least = [0.0; 2];
            certify_line(
                &scu,
                raised.view(),
                &start,
                (0, &[edge.depth, z2]),
                &mut least,
            )
            .unwrap();
            let h = |from: &VehicleState<3>| {
                let mut s = [TrackScore::default()];
                over.fly(from, 1, &[z2], &mut s).unwrap();
                s[0].min_altitude()
            };
            let (nominal, switched) = (h(&edge.next), h(&other));
            assert!(
                least[1] <= nominal.min(switched),
                "{z2}: {least:?}, {nominal}, {switched}"
            );
            apart = apart.max(nominal - switched);
        }
        // The other switch flies lower somewhere: the test can fail.
        assert!(apart > 1e-3, "{apart}");
    }
}
