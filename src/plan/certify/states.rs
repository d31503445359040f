//! The worlds' states between calls (the [`Tube`]'s keeping): made
//! ready for a call, moved on by a committed depth, or, unbudgeted, the
//! committed depths kept pending and flown only when a certificate needs
//! the states.

use heapless::Vec;

use crate::model::ProfileView;
use crate::sim::{MAX_WORLDS, Scenario, SimError, TrackScore, VehicleState, World};

use super::{ALL, Tube, Worlds, has, vehicle_margin};

impl<const N: usize> Tube<N> {
    /// [`Tube::prepare`] with the worlds and vehicle margin `sc` declares.
    /// Not inlined: the worlds' list stays off its callers' stack.
    #[inline(never)]
    pub fn prepare_for(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
    ) -> bool {
        let u = sc.mission().uncertainty();
        let worlds = (
            World::corners(sc.vehicle(), u),
            vehicle_margin(sc.vehicle(), u),
        );
        self.prepare(worlds, state, track)
    }

    /// How many worlds the tube flies.
    pub fn count(&self) -> usize {
        self.worlds.len()
    }

    /// Makes the tube ready for a call on `track` from `state`: kept if it
    /// is the state the last commit predicted for this track with the same
    /// worlds, else every world starts from `state`. Returns whether it
    /// was kept.
    pub fn prepare(
        &mut self,
        (worlds, margin): (Vec<World, MAX_WORLDS>, f32),
        state: &VehicleState<N>,
        track: usize,
    ) -> bool {
        self.margin = margin;
        let declared = self.worlds.len().saturating_sub(self.branches);
        let kept = self.at() == track
            && self.nominal.as_ref() == Some(state)
            && self.worlds.get(..declared) == Some(&worlds[..]);
        if !kept {
            self.worlds = worlds;
            self.branches = 0;
            self.states.fill(*state);
            self.critical.set([0; 3]);
            self.pending.clear();
            self.done = [0; MAX_WORLDS];
            self.track = track;
            self.nominal = Some(*state);
        }
        kept
    }

    /// The states of the worlds in `mask` ([`Worlds`]) flown through the
    /// pending depths (one flight per world not yet there), so that a
    /// certificate can start from them; once every world is there, the
    /// tube is at the call's track. A world whose flight fails leaves no
    /// state: every world then starts again from `state`, the call's (on
    /// `track`).
    pub fn materialize(
        &mut self,
        (sc, bottom): (&Scenario<'_, N>, ProfileView<'_>),
        (state, track): (&VehicleState<N>, usize),
        (mask, flights): (Worlds, &mut u32),
    ) {
        let n = self.pending.len();
        let mut failed = false;
        for (i, (w, st)) in self.worlds.iter().zip(self.states.iter_mut()).enumerate() {
            let Some(done) = self.done.get_mut(i) else {
                continue;
            };
            let from = usize::from(*done);
            if from >= n || !has(&mask, i) {
                continue;
            }
            *flights = flights.saturating_add(1);
            let rest = self.pending.get(from..).unwrap_or(&[]);
            let at = self.track.saturating_add(from);
            match sc
                .in_world(w, bottom)
                .and_then(|scw| fly_on(&scw, st, at, rest))
            {
                Ok(next) => {
                    *st = next;
                    *done = u8::try_from(n).unwrap_or(u8::MAX);
                }
                Err(_) => {
                    failed = true;
                    break;
                }
            }
        }
        if failed {
            self.forget_branches();
            self.states.fill(*state);
            self.critical.set([0; 3]);
            self.track = track;
            self.pending.clear();
            self.done = [0; MAX_WORLDS];
            return;
        }
        let all = self
            .done
            .iter()
            .take(self.worlds.len())
            .all(|&d| usize::from(d) >= n);
        if all {
            self.track = self.track.saturating_add(n);
            self.pending.clear();
            self.done = [0; MAX_WORLDS];
        }
    }

    /// Adds a branch ([`Tube::branches`]): `world` (the nominal one) again,
    /// from `state`, where the last committed depth's nominal flight
    /// reached the track the tube is at with its switch the other way
    /// ([`Scenario::switch_other_way`]). None is added where the worlds
    /// are full or the tube holds no states.
    pub fn branch(&mut self, world: World, state: &VehicleState<N>) {
        let i = self.worlds.len();
        if self.nominal.is_none() || self.worlds.push(world).is_err() {
            return;
        }
        if let (Some(st), Some(done)) = (self.states.get_mut(i), self.done.get_mut(i)) {
            *st = *state;
            // (At the call's track already: past every pending depth.)
            *done = u8::try_from(self.pending.len()).unwrap_or(u8::MAX);
            self.branches = self.branches.saturating_add(1);
        } else {
            self.worlds.truncate(i);
        }
    }

    /// Whether the tube holds a knife edge's branch ([`Tube::branch`]) at
    /// the start of `track`, its nominal world at `state`: the state the
    /// last commit predicted.
    pub fn branched_at(&self, state: &VehicleState<N>, track: usize) -> bool {
        self.branches > 0 && self.at() == track && self.nominal.as_ref() == Some(state)
    }

    /// Drops the branch worlds.
    fn forget_branches(&mut self) {
        let declared = self.worlds.len().saturating_sub(self.branches);
        self.worlds.truncate(declared);
        self.branches = 0;
    }

    /// Whether some worlds have pending depths left to fly.
    pub fn owes(&self) -> bool {
        !self.pending.is_empty()
    }

    /// The track the worlds' flights start: the call's.
    pub(super) fn at(&self) -> usize {
        self.track.saturating_add(self.pending.len())
    }

    /// After committing `depth` on the track the tube is at: each world's
    /// state at the track's end, flown (or, when the nominal world over
    /// the map is the only one, the nominal flight's `nominal`), with the
    /// nominal state that goes with them; or, `lazy`, the depth pending
    /// until a certificate needs the states ([`Tube::materialize`]). A
    /// world whose flight fails keeps no state: the tube is forgotten,
    /// and the next call starts every world afresh.
    pub fn advance(
        &mut self,
        (sc, bottom): (&Scenario<'_, N>, ProfileView<'_>),
        depth: f32,
        nominal: &VehicleState<N>,
        (only_nominal, lazy, flights): (bool, bool, &mut u32),
    ) {
        if lazy && !only_nominal && self.nominal.is_some() && self.pending.push(depth).is_ok() {
            self.nominal = Some(*nominal);
            return;
        }
        if !self.pending.is_empty() {
            // (Every world's state at the tube's track first.)
            if let Some(state) = self.nominal {
                let track = self.at();
                self.materialize((sc, bottom), (&state, track), (ALL, flights));
            }
        }
        if only_nominal {
            if let Some(s) = self.states.first_mut() {
                *s = *nominal;
            }
        } else {
            for (w, st) in self.worlds.iter().zip(self.states.iter_mut()) {
                *flights = flights.saturating_add(1);
                let next = sc
                    .in_world(w, bottom)
                    .and_then(|scw| fly_on(&scw, st, self.track, &[depth]));
                match next {
                    Ok(n) => *st = n,
                    Err(_) => {
                        self.nominal = None;
                        return;
                    }
                }
            }
        }
        self.track = self.track.saturating_add(1);
        self.nominal = Some(*nominal);
    }
}

/// Tracks flown per call by [`fly_on`] (its score buffer's length).
const FLY_CHUNK: usize = 4;

/// The state after flying `depths` from `st` on `track`, a few tracks per
/// flight call (the scores are not needed, so the buffer stays small;
/// the state is the same as one call's, step for step).
fn fly_on<const N: usize>(
    sc: &Scenario<'_, N>,
    st: &VehicleState<N>,
    track: usize,
    depths: &[f32],
) -> Result<VehicleState<N>, SimError> {
    let mut scores = [TrackScore::default(); FLY_CHUNK];
    let mut state = *st;
    for (c, chunk) in depths.chunks(FLY_CHUNK).enumerate() {
        let at = track.saturating_add(c.saturating_mul(FLY_CHUNK));
        let s = scores.get_mut(..chunk.len()).ok_or(SimError::ScoreBuffer)?;
        state = sc.fly(&state, at, chunk, s)?;
    }
    Ok(state)
}

#[cfg(test)]
mod tests {
    use super::super::*;
    use crate::model::{Mission, Profile, Uncertainty, Vehicle, Waypoints};
    use crate::sim::TrackScore;

    /// The lazy advance flies the same states as the eager one, world by
    /// world (the screening worlds first, then the rest), and a complete
    /// certificate's per-track altitudes are the ones the next track's
    /// certificate finds again.
    #[test]
    fn lazy_advance_equals_the_eager_one() {
        let v = Vehicle::c_auv4().unwrap();
        let p =
            Profile::<8>::new(&[0.0, 400.0, 700.0, 2200.0], &[300.0, 300.0, 180.0, 200.0]).unwrap();
        let w = Waypoints::<4>::new(&[0.0, 600.0, 1400.0, 2100.0]).unwrap();
        let u = Uncertainty::new(0.0, 0.0, 0.0, 0.05, 1.0, 0.05).unwrap();
        let sc = Scenario::new(&v, &p, &w, Mission::default().with_uncertainty(u)).unwrap();
        let start = sc.start_state(220.0);
        let worlds = || (World::corners(&v, &u), vehicle_margin(&v, &u));
        let (mut eager, mut lazy) = (Tube::default(), Tube::default());
        eager.prepare(worlds(), &start, 0);
        lazy.prepare(worlds(), &start, 0);
        let mut flights = 0;
        let depths = [230.0, 110.0, 120.0];
        let full = eager.certify(&sc, p.view(), &depths, (f32::NEG_INFINITY, &mut flights));
        let minima = eager.minima_of(&full).unwrap();
        let mut st = [TrackScore::default(); 2];
        let next = sc.fly(&start, 0, &depths[..2], &mut st).unwrap();
        let mut n1 = [TrackScore::default()];
        let after1 = sc.fly(&start, 0, &depths[..1], &mut n1).unwrap();
        for (tube, lazy_one) in [(&mut eager, false), (&mut lazy, true)] {
            tube.advance(
                (&sc, p.view()),
                230.0,
                &after1,
                (false, lazy_one, &mut flights),
            );
            assert!(tube.prepare(worlds(), &after1, 1));
            tube.advance(
                (&sc, p.view()),
                110.0,
                &next,
                (false, lazy_one, &mut flights),
            );
            assert!(tube.prepare(worlds(), &next, 2));
        }
        assert!(lazy.owes() && !eager.owes());
        // The sinking worlds first, then every world.
        let mut few = 0;
        let sinking = lazy.sinking();
        lazy.materialize((&sc, p.view()), (&next, 2), (sinking, &mut few));
        assert!(lazy.owes() && few > 0 && (few as usize) < World::corners(&v, &u).len());
        lazy.materialize((&sc, p.view()), (&next, 2), (ALL, &mut few));
        assert!(!lazy.owes());
        assert_eq!(lazy.states, eager.states);
        // Track 3's certificate from the kept states: the full one's third
        // track, bit for bit.
        let last = lazy.certify(
            &sc,
            p.view(),
            &depths[2..],
            (f32::NEG_INFINITY, &mut flights),
        );
        assert_eq!(last.all.to_bits(), minima[2].to_bits());
    }

    /// A branch world is kept with the tube and flown by its certificates
    /// (its own state's flight counts), and dropped when the tube starts
    /// again.
    #[test]
    fn a_branch_is_kept_and_flown_until_the_tube_restarts() {
        let v = Vehicle::c_auv4().unwrap();
        let p =
            Profile::<8>::new(&[0.0, 400.0, 700.0, 2200.0], &[300.0, 300.0, 180.0, 200.0]).unwrap();
        let w = Waypoints::<4>::new(&[0.0, 600.0, 1400.0, 2100.0]).unwrap();
        let sc = Scenario::new(&v, &p, &w, Mission::default()).unwrap();
        let u = Uncertainty::NONE;
        let start = sc.start_state(220.0);
        let worlds = || (World::corners(&v, &u), vehicle_margin(&v, &u));
        let mut tube = Tube::default();
        tube.prepare(worlds(), &start, 0);
        let mut s = [TrackScore::default()];
        let next = sc.fly(&start, 0, &[230.0], &mut s).unwrap();
        let (mut from, mut other) = (start, next);
        sc.switch_other_way((&mut from, &mut other), (0, 230.0), &mut s)
            .unwrap();
        let mut flights = 0;
        tube.advance((&sc, p.view()), 230.0, &next, (true, true, &mut flights));
        tube.branch(World::nominal(&v), &other);
        assert_eq!(tube.count(), 2);
        assert!(!tube.nominal_only(&World::nominal(&v), &next));
        assert!(tube.prepare(worlds(), &next, 1));
        assert_eq!(tube.count(), 2);
        // Each world flies from its own state: the branch's altitudes
        // bound the certificate.
        let depths = [110.0, 120.0];
        let mut few = 0;
        let c = tube.certify(&sc, p.view(), &depths, (f32::NEG_INFINITY, &mut few));
        assert!(few >= 2 && !c.partial);
        let mut one = [TrackScore::default(); 2];
        sc.fly(&other, 1, &depths, &mut one).unwrap();
        let branch_least = one
            .iter()
            .map(TrackScore::min_altitude)
            .fold(f32::INFINITY, f32::min);
        assert!(c.all <= branch_least);
        // Another start: the tube restarts without it.
        assert!(!tube.prepare(worlds(), &other, 1));
        assert_eq!(tube.count(), 1);
    }
}
