//! Certification (model contract §11, §12): a continuation — reference
//! depths for the committed track and every later one — is flown to the
//! end of the line in every world of the declared set ([`World::corners`])
//! over the certification bottom (the map's lower envelope under the map
//! uncertainty, or the map itself), each world from its own state.
//!
//! The worlds' states are a [`Tube`]: after a call commits a depth, each
//! world's state at the next waypoint is the one its own flight of that
//! depth reached, so call after call the certificate covers the line as
//! the real vehicle would fly the committed depths open loop in any world
//! of the set. When the caller's start state is not the one the planner
//! predicted (a closed loop replanning from a measured state), every world
//! starts again from that state.

use heapless::Vec;

use crate::model::ProfileView;
use crate::sim::{MAX_WORLDS, Scenario, SimError, TrackScore, VehicleState, World};

/// The worlds of a certificate and each one's state at the start of
/// `track`.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Tube<const N: usize> {
    worlds: Vec<World, MAX_WORLDS>,
    states: [VehicleState<N>; MAX_WORLDS],
    /// The track those states start, and the nominal state they go with.
    track: usize,
    nominal: Option<VehicleState<N>>,
}

impl<const N: usize> Default for Tube<N> {
    fn default() -> Self {
        Self {
            worlds: Vec::new(),
            states: [VehicleState::trimmed(0.0, 0.0); MAX_WORLDS],
            track: 0,
            nominal: None,
        }
    }
}

/// What a continuation's flights in every world showed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Certificate<const N: usize> {
    /// Least altitude over the worlds on the committed track, m.
    pub first: f32,
    /// Least altitude over the worlds to the end of the line, m
    /// (`-inf` when a flight failed).
    pub all: f32,
    /// Each world's state at the end of the committed track.
    pub next: [VehicleState<N>; MAX_WORLDS],
}

impl<const N: usize> Tube<N> {
    /// Makes the tube ready for a call on `track` from `state`: kept if it
    /// is the state the last commit predicted for this track with the same
    /// worlds, else every world starts from `state`.
    pub fn prepare(
        &mut self,
        worlds: Vec<World, MAX_WORLDS>,
        state: &VehicleState<N>,
        track: usize,
    ) {
        let kept =
            self.track == track && self.nominal.as_ref() == Some(state) && self.worlds == worlds;
        if !kept {
            self.worlds = worlds;
            self.states = [*state; MAX_WORLDS];
            self.track = track;
            self.nominal = Some(*state);
        }
    }

    /// After committing the track the tube starts: the worlds' states
    /// the committed depth's certificate reached, with the nominal state
    /// that goes with them.
    pub fn advance(&mut self, cert: &Certificate<N>, nominal: &VehicleState<N>) {
        self.states = cert.next;
        self.track = self.track.saturating_add(1);
        self.nominal = Some(*nominal);
    }

    /// Whether the only world is the nominal one, starting from `state`:
    /// then a nominal flight of one track from `state` over the map is its
    /// certificate.
    pub fn nominal_only(&self, nominal: &World, state: &VehicleState<N>) -> bool {
        self.worlds.len() == 1
            && self.worlds.first() == Some(nominal)
            && self.states.first() == Some(state)
    }

    /// The certificate of a one-track continuation whose only world's
    /// flight is at hand (see [`Tube::nominal_only`]).
    pub fn from_flight(&self, min_altitude: f32, next: &VehicleState<N>) -> Certificate<N> {
        let mut c = Certificate {
            first: min_altitude,
            all: min_altitude,
            next: self.states,
        };
        if let Some(n) = c.next.first_mut() {
            *n = *next;
        }
        c
    }

    /// Forgets the worlds' states.
    pub fn reset(&mut self) {
        self.nominal = None;
    }

    /// Flies `depths` (the tube's track first, one depth per track) in
    /// every world over `bottom` from its state; counts the flights.
    pub fn certify(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        depths: &[f32],
        flights: &mut u32,
    ) -> Certificate<N> {
        let mut c = Certificate {
            first: f32::INFINITY,
            all: f32::INFINITY,
            next: self.states,
        };
        for (i, w) in self.worlds.iter().enumerate() {
            let (Some(st), Some(next)) = (self.states.get(i), c.next.get_mut(i)) else {
                break;
            };
            match fly_world(sc, w, bottom, st, self.track, depths, flights) {
                Ok((first, all, end_first)) => {
                    c.first = c.first.min(first);
                    c.all = c.all.min(all);
                    *next = end_first;
                }
                Err(_) => {
                    c.first = f32::NEG_INFINITY;
                    c.all = f32::NEG_INFINITY;
                }
            }
        }
        c
    }
}

/// One world's flight of `depths` from `st` on `track`: the least altitude
/// on the first track, to the end, and the state at the first track's end.
fn fly_world<const N: usize>(
    sc: &Scenario<'_, N>,
    w: &World,
    bottom: ProfileView<'_>,
    st: &VehicleState<N>,
    track: usize,
    depths: &[f32],
    flights: &mut u32,
) -> Result<(f32, f32, VehicleState<N>), SimError> {
    let scw = sc.in_world(w, bottom)?;
    let mut score = [TrackScore::default()];
    let mut state = *st;
    let (mut first, mut all) = (f32::INFINITY, f32::INFINITY);
    let mut end_first = state;
    // One flight of the line, flown track by track (runs chain exactly).
    *flights = flights.saturating_add(1);
    for (j, &z) in depths.iter().enumerate() {
        state = scw.simulate(&state, track.saturating_add(j), &[z], &mut score, |_| {})?;
        let h = score
            .first()
            .map_or(f32::NEG_INFINITY, TrackScore::min_altitude);
        all = all.min(h);
        if j == 0 {
            first = h;
            end_first = state;
        }
    }
    Ok((first, all, end_first))
}
