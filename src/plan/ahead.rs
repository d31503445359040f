//! A candidate's depth moved so that the next track's end leaves its
//! waypoint's knife edge.
//!
//! `knife.rs` moves a candidate whose own track ends within [`EDGE`] of its
//! waypoint by the candidate's own depth. Where the *next* track of the
//! horizon ends on its waypoint's edge in a saturated climb or dive (its
//! end does not move with its own depth), no later call can move it: the
//! next call commits it on the edge, and every certificate after flies the
//! other switch too (`certify/flight.rs`). That other switch can set the
//! track after it centimetres lower, and the line pays for it:
//! `check_planner.py --seed 3267` (default vehicle, `unseen_3267_0`):
//! track 3 climbs at the pitch limit the whole track and ends 0.3 mm short
//! of waypoint 3 whatever its depth; from the other switch's state track
//! 4's least altitude, set by its arrival, is 11.7 cm lower (59.976 m
//! against 60.094 m); the last call aimed track 4 above that and climbed
//! it 157 m above the best plan's depth: the line 2.52× the f64 best safe
//! plan.
//!
//! So the call before moves its own depth, in the candidate's horizon, as
//! `knife.rs` moves it for its own end: a probe 5 mm shallower, then a
//! secant step that puts the next track's nearest sample twice [`EDGE`]
//! from its waypoint on the side it lies now, each flown over both tracks.
//! The side keeps the switch on the sample the horizon planned with, so
//! the tracks after fly as planned: moved to the other side (the sample
//! 4 mm past the waypoint, a switch a sample earlier), track 4 flew
//! 59.998 m, and the line stayed 2.50×. A move is kept when the
//! candidate's own track stays off its edge and as safe, its `J` within
//! the knife's share, and the next track as safe as it was; the later
//! tracks' gaps go with it (`knife.rs`). Only with one vehicle world,
//! unbudgeted, in horizon mode: one flight of the next track per call to
//! see the edge, two more to see that the next depth cannot move it, and
//! four for the move.

use crate::sim::{EDGE, Scenario, TrackScore, VehicleState, offset};

use super::candidate::Candidate;
use super::fallback::Flown;
use super::flights::Flights;
use super::knife::{MOST, PROBE, one_vehicle};
use super::scan::search_box;
use super::{Mode, Planner};

/// The next track's flight: its score and the state past its waypoint.
type Next<const N: usize> = (TrackScore, VehicleState<N>);

impl<const K: usize, const N: usize> Planner<K, N> {
    /// Moves the candidate's depth so that the next track of its horizon
    /// ends off its waypoint's knife edge (module docs), when that track
    /// cannot move off it itself; its flights counted in the candidate's.
    /// Not inlined: its flights' states stay off the candidate's stack.
    #[inline(never)]
    pub(super) fn off_the_edge_ahead(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
        cand: &mut Candidate<N>,
    ) {
        let wanted = self.cfg.mode == Mode::Horizon
            && self.horizon_len >= 2
            && self.budget.limit == u32::MAX
            && cand.cert.is_none()
            && one_vehicle(sc);
        let next = track.saturating_add(1);
        let (Some(&z_next), Some(end)) = (self.work.z.get(1), sc.edge_waypoint(next)) else {
            return;
        };
        if !wanted || sc.on_edge(track, &cand.flown.next) {
            return;
        }
        let mut fl = self.move_flights((sc, state, track), cand, u32::MAX);
        let found = self.move_for_next(&mut fl, cand, (z_next, end));
        cand.evaluations = fl.count;
        if let Some(f) = found {
            self.take_move(cand, track, f);
        }
    }

    /// The moved candidate, if the next track (at `z_next`) ends on the
    /// edge of waypoint `end` (m), cannot leave it by its own depth, and a
    /// move of the candidate's depth takes it off.
    fn move_for_next(
        &self,
        fl: &mut Flights<'_, '_, N>,
        cand: &Candidate<N>,
        (z_next, end): (f32, f32),
    ) -> Option<Flown<N>> {
        let first = fl.fly_from(&cand.flown.next, 1, z_next).ok()?;
        let v0 = offset(&first.1, end);
        if libm::fabsf(v0) >= EDGE {
            return None;
        }
        // Can the next track's own depth move its end (`knife.rs`, in the
        // next call)? Probed both ways: a saturated track moves neither.
        for side in [-1.0_f32, 1.0] {
            let (_, n) = fl
                .fly_from(&cand.flown.next, 1, z_next + side * PROBE)
                .ok()?;
            let slope = (offset(&n, end) - v0) / PROBE;
            if libm::fabsf(slope) * MOST >= 4.0 * EDGE {
                return None;
            }
        }
        let b = search_box::<N, 1>(&fl.sc, fl.state, fl.track, 1);
        let (lo, hi) = (b.lo.first().copied()?, b.hi.first().copied()?);
        self.step_for_next(fl, cand, (z_next, end, v0, &first), (lo, hi))
    }

    /// The move for the next track's edge: a probe shallower, then the
    /// secant step that puts the next track's nearest sample twice
    /// [`EDGE`] from its waypoint on the side it lies now (the switch
    /// stays on the sample it is on, and the tracks after fly as the
    /// horizon planned them; a deeper step only with nothing declared,
    /// as `knife.rs`); the first whose flights
    /// [`Planner::keeps_ahead`] accepts.
    fn step_for_next(
        &self,
        fl: &mut Flights<'_, '_, N>,
        cand: &Candidate<N>,
        (z_next, end, v0, first): (f32, f32, f32, &Next<N>),
        (lo, hi): (f32, f32),
    ) -> Option<Flown<N>> {
        let z0 = cand.flown.depth;
        let (sc, track) = (fl.sc, fl.track);
        let mut fly = |z: f32| -> Option<(Flown<N>, Next<N>)> {
            let (score, next) = fl.fly(z).ok()?;
            let after = fl.fly_from(&next, 1, z_next).ok()?;
            let flown = Flown {
                depth: z,
                score,
                next,
            };
            Some((flown, after))
        };
        let target = if v0 < 0.0 { -2.0 } else { 2.0 } * EDGE;
        let z1 = z0 - PROBE;
        let probe = fly(z1)?;
        let v1 = offset(&probe.1.1, end);
        if self.keeps_ahead((&sc, track), cand, (&probe, first), (v1, target), (lo, hi)) {
            return Some(probe.0);
        }
        let dz = (target - v0) * (z1 - z0) / (v1 - v0);
        let deeper = dz > 0.0 && !sc.mission().uncertainty().is_none();
        // (A next track that the probe did not move gives no step: NaN.)
        let within = libm::fabsf(dz) <= MOST;
        if !within || deeper {
            return None;
        }
        let second = fly(z0 + dz)?;
        let v2 = offset(&second.1.1, end);
        self.keeps_ahead((&sc, track), cand, (&second, first), (v2, target), (lo, hi))
            .then_some(second.0)
    }

    /// Whether a moved depth's flights (`moved`: its own track and the
    /// next, the next track's nearest sample at `v` from its waypoint, on
    /// the side of `target`) may replace the candidate: its own track kept
    /// as `knife.rs` keeps a move (off its own edge too), and the next
    /// track as safe as it was (`before`).
    fn keeps_ahead(
        &self,
        (sc, track): (&Scenario<'_, N>, usize),
        cand: &Candidate<N>,
        (moved, before): (&(Flown<N>, Next<N>), &Next<N>),
        (v, target): (f32, f32),
        box_: (f32, f32),
    ) -> bool {
        let ((f, (s, _)), (s0, _)) = (moved, before);
        let own = sc
            .edge_waypoint(track)
            .map_or(f32::INFINITY, |e| offset(&f.next, e));
        let floor = s0.min_altitude().min(cand.h_safe);
        let safe = !self.cfg.constrained || s.min_altitude() >= floor;
        let off = libm::fabsf(v) >= EDGE && v * target > 0.0;
        safe && off && self.keeps(cand, f, own, box_)
    }
}
