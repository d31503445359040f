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
//!
//! **What it costs.** A certificate that holds flies every world to the
//! line's end. One that fails need not: the world that set the last
//! certificate's least altitude flies first, and the first world below the
//! floor asked for ends the certificate (`partial`: its altitudes are
//! upper bounds, and `commit.rs` flies the rest before a partial
//! certificate is ever committed or reported). The continuation search of
//! `commit.rs` finds its point in the *critical* worlds alone (every world
//! that has set a certificate's least altitude since the tube restarted,
//! [`Tube::critical`]) and then certifies that point in every world.
//!
//! The vehicle part of the certificate is sampled ([`World::corners`]: the
//! corners and interior levels of the declared box). Between the samples
//! the flight can dip lower where the autopilot saturates (measured: up
//! to 0.75 m at `w_max` = 0.07 m/s on random lines). Every certified
//! altitude is therefore lowered by a *vehicle margin*,
//! `m_v = 15 s × (w_max + U0 sin α_max + U0 ε_U sin θmax)`: the depth the
//! declared current, path offset and speed error can add over 15 s, the
//! autopilot's reaction time (0 when nothing about the vehicle is
//! declared). It is conservative by design, and costs `J` only when
//! vehicle uncertainty is declared. It is at least two samples' climb at
//! the pitch limit, `2 U0 (1 + ε_U) Ts tan θmax`, whenever the vehicle's
//! motion is uncertain: a world between the samples crosses a waypoint up
//! to a sample before or after them, and its flight after the switch is
//! shifted by as much (the checker found an interior flight-path offset
//! 40 mm under the corners with `α_max` = 0.065° and nothing else
//! declared, where the 15 s margin was 27 mm and one sample's climb
//! 72 mm); where tracks are short, the shifts of the switches whose
//! responses overlap add (with a speed error of 0.918 % alone, on tracks
//! of 85 and 166 m, the phases of three switches put a speed between the
//! sampled ones 84 mm under them: 1.4 samples' climb, where the 15 s
//! margin was 35 mm). Above that floor the 15 s margin is taken to cover
//! both: it is the larger by far wherever a current or path offset of
//! practical size is declared (the README's recommended bounds: 1.62 m
//! against 0.15 m).
//!
//! Where a track's least altitude has a kink between two levels of one
//! bound (its lowest point moves from one place of the track to another),
//! the margin need not cover it (0.42 m short, `valley.rs`): along each
//! line of levels, the crossing of the chords outside an interval bounds
//! the interval's floor, and lowers the certificate with the flights.

use core::cell::Cell;

use heapless::Vec;

use crate::model::{ProfileView, Uncertainty, Vehicle};
use crate::num::DEG;
use crate::sim::{MAX_WORLDS, Scenario, SimError, VehicleState, World};

mod flight;
mod states;
mod valley;

pub(in crate::plan) use flight::fly_world;
use valley::{LineRows, Lines};

/// A set of worlds, bit `i % 32` of word `i / 32` for world `i` (words,
/// not a `u128`, so that the planner keeps the alignment of its `f32`s
/// and `u32`s: the C interface stores it in 8-byte-aligned memory).
pub(super) type Worlds = [u32; 3];

const _: () = assert!(MAX_WORLDS <= 96);

/// Every world.
pub(super) const ALL: Worlds = [u32::MAX; 3];

/// Whether world `i` is in `set`.
fn has(set: &Worlds, i: usize) -> bool {
    let (word, bit) = (i / 32, i % 32);
    set.get(word)
        .is_some_and(|w| (w >> u32::try_from(bit).unwrap_or(0)) & 1 == 1)
}

/// Most tracks a line may have in horizon mode: the continuation that a
/// committed depth's safety rests on covers every later track.
pub const MAX_TRACKS: usize = 64;

/// The time over which the vehicle margin accumulates, s (module docs).
const MARGIN_TIME: f32 = 15.0;

/// The vehicle margin `m_v`, m (module docs).
pub(super) fn vehicle_margin<const N: usize>(vehicle: &Vehicle<N>, u: &Uncertainty) -> f32 {
    let u0 = vehicle.speed();
    let pitch = vehicle.autopilot().config().pitch_limit * DEG;
    let (sin_alpha, _) = crate::num::sin_cos(u.flight_path_offset() * DEG);
    let (sin_pitch, cos_pitch) = crate::num::sin_cos(pitch);
    let drift = MARGIN_TIME * (u.vertical_current() + u0 * sin_alpha + u0 * u.speed() * sin_pitch);
    // Two samples' climb at the pitch limit (module docs): where the
    // vehicle's motion is uncertain, a world between the samples switches
    // at each waypoint up to a sample apart from them, and the shifts of
    // overlapping switches add.
    let moves = u.motion_uncertain();
    let step = u0 * (1.0 + u.speed()) * vehicle.sample_time();
    let jitter = if moves {
        step * sin_pitch / cos_pitch.max(0.01)
    } else {
        0.0
    };
    drift.max(2.0 * jitter)
}

/// The worlds of a certificate and each one's state at the start of
/// `track`.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Tube<const N: usize> {
    worlds: Vec<World, MAX_WORLDS>,
    /// The vehicle margin subtracted from every certified altitude, m.
    margin: f32,
    states: [VehicleState<N>; MAX_WORLDS],
    /// How many of the last worlds are branches: the nominal world again,
    /// from the state a committed flight on a knife edge reaches with its
    /// switch the other way ([`Tube::branch`]).
    branches: usize,
    /// A call's flights (as counted into a certificate's `flights`) below
    /// which a knife edge's branch may still be flown, its certificate's
    /// other worlds left room ([`Tube::set_branch_cap`]).
    branch_cap: u32,
    /// The world whose flight set the last certificate's least altitude:
    /// flown first, so that an uncertifiable line is found in one flight.
    worst: Cell<usize>,
    /// The worlds that have set a certificate's least altitude since the
    /// tube was last restarted ([`Worlds`]).
    critical: Cell<Worlds>,
    /// The track those states start, and the nominal state they go with
    /// (at the start of `track + pending.len()`).
    track: usize,
    nominal: Option<VehicleState<N>>,
    /// Depths committed since the states were last all flown, one per
    /// track from `track`: the advance is flown only when a certificate
    /// needs the states (see [`Tube::materialize`]); world `i` has flown
    /// the first `done[i]` of them.
    pending: Vec<f32, MAX_TRACKS>,
    done: [u8; MAX_WORLDS],
    /// The last complete certificate's least altitude on each of its
    /// tracks (less the margin), m, and that certificate's id.
    minima: Cell<[f32; MAX_TRACKS]>,
    minima_of: Cell<u32>,
    /// The last certificate id given.
    ids: Cell<u32>,
    /// The line being certified (`valley.rs`).
    rows: LineRows,
}

impl<const N: usize> Default for Tube<N> {
    fn default() -> Self {
        Self {
            worlds: Vec::new(),
            margin: 0.0,
            states: [VehicleState::trimmed(0.0, 0.0); MAX_WORLDS],
            branches: 0,
            branch_cap: u32::MAX,
            worst: Cell::new(0),
            critical: Cell::new([0; 3]),
            track: 0,
            nominal: None,
            pending: Vec::new(),
            done: [0; MAX_WORLDS],
            minima: Cell::new([f32::NEG_INFINITY; MAX_TRACKS]),
            minima_of: Cell::new(0),
            ids: Cell::new(0),
            rows: LineRows::default(),
        }
    }
}

/// What a continuation's flights in every world showed (less the vehicle
/// margin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Certificate {
    /// Least altitude over the worlds on the committed track, m.
    pub first: f32,
    /// Least altitude over the worlds to the end of the line, m
    /// (`-inf` when a flight failed).
    pub all: f32,
    /// Whether some worlds were left unflown because one already fell
    /// below the floor asked for: `first` and `all` are then upper bounds
    /// (the line is not certified either way).
    pub partial: bool,
    /// Which certificate this is, for its per-track altitudes
    /// ([`Tube::minima_of`]; 0: none kept).
    pub id: u32,
}

impl<const N: usize> Tube<N> {
    /// Whether the only world is the nominal one, starting from `state`:
    /// then a nominal flight of one track from `state` over the map is its
    /// certificate.
    pub fn nominal_only(&self, nominal: &World, state: &VehicleState<N>) -> bool {
        self.margin == 0.0
            && self.worlds.len() == 1
            && self.worlds.first() == Some(nominal)
            && self.states.first() == Some(state)
    }

    /// The certificate of a one-track continuation whose only world's
    /// flight is at hand (see [`Tube::nominal_only`]).
    pub fn of_flight(&self, min_altitude: f32) -> Certificate {
        Certificate {
            first: min_altitude,
            all: min_altitude,
            partial: false,
            id: 0,
        }
    }

    /// The per-track least altitudes of certificate `c` (m, less the
    /// margin; one per track of its continuation), if it was the last
    /// complete one.
    pub fn minima_of(&self, c: &Certificate) -> Option<[f32; MAX_TRACKS]> {
        (c.id != 0 && c.id == self.minima_of.get() && !c.partial).then(|| self.minima.get())
    }

    /// Sets the flight count (of the call, as certificates count it) that
    /// a knife edge's branch may not reach, its certificate's other
    /// worlds left room: a budgeted call's limit less what its commit
    /// needs after the certificate (`u32::MAX`: no budget). Where a branch
    /// is not affordable, the certificate is the nominal switch's alone
    /// (model contract §11's).
    pub fn set_branch_cap(&mut self, cap: u32) {
        self.branch_cap = cap;
    }

    /// Forgets the worlds' states.
    pub fn reset(&mut self) {
        self.nominal = None;
    }

    /// Flies `depths` (the tube's track first, one depth per track) in
    /// every world over `bottom` from its state; counts the flights. The
    /// world that was worst last time flies first, the rest in index
    /// order (a line's worlds in a row, `valley.rs`); once a world's least
    /// altitude (less the margin) is below `floor` (m) the rest are left
    /// unflown and the certificate is `partial` (`f32::NEG_INFINITY`: fly
    /// them all).
    pub fn certify(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        depths: &[f32],
        (floor, flights): (f32, &mut u32),
    ) -> Certificate {
        let n = self.worlds.len();
        let start = self.worst.get().min(n.saturating_sub(1));
        let order = core::iter::once(start).chain((0..n).filter(move |&i| i != start));
        let mut per_track = [f32::INFINITY; MAX_TRACKS];
        let at = (floor, flights, &mut per_track);
        let (c, worst) = self.fly_worlds(sc, bottom, depths, order, at);
        if let Some(i) = worst {
            self.worst.set(i);
        }
        self.mark_worst();
        c
    }

    /// Flies `depths` in the worlds `order` names (indices; ascending but
    /// for the first), each from its state, into one certificate (less
    /// the margin), with the world that set its least altitude; `partial`
    /// when it stopped with worlds left because that altitude fell below
    /// `floor` (m). The floors between a line's levels (`valley.rs`: a
    /// line's worlds flown in a row, hence the ascending order) lower it
    /// too. A certificate of every world keeps its per-track altitudes
    /// ([`Tube::minima_of`]).
    fn fly_worlds(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        depths: &[f32],
        order: impl Iterator<Item = usize>,
        (floor, flights, per_track): (f32, &mut u32, &mut [f32; MAX_TRACKS]),
    ) -> (Certificate, Option<usize>) {
        let mut c = Certificate {
            first: f32::INFINITY,
            all: f32::INFINITY,
            partial: false,
            id: 0,
        };
        *per_track = [f32::INFINITY; MAX_TRACKS];
        let mut lines = Lines::new(&self.rows, &self.worlds, self.branches);
        let tracks = depths.len();
        let mut flown = 0_usize;
        let mut worst = None;
        let mut order = order.peekable();
        while let Some(i) = order.next() {
            let (Some(w), Some(st)) = (self.worlds.get(i), self.states.get(i)) else {
                continue;
            };
            let at = (st, self.at());
            let (row, floors) = lines.slot(i, &self.worlds, (tracks, &mut *per_track));
            c.first = c.first.min(floors.0);
            c.all = c.all.min(floors.1);
            // (Room for every world's flight after a branch.)
            let worlds = u32::try_from(self.worlds.len()).unwrap_or(u32::MAX);
            let cap = self.branch_cap.saturating_sub(worlds);
            let own = row.unwrap_or_else(|| Cell::from_mut(&mut per_track[..]).as_slice_of_cells());
            let (first, all) = fly_world(
                sc,
                w,
                bottom,
                at,
                depths,
                (self.margin, own),
                (flights, cap),
            );
            if let Some(row) = row {
                per_track
                    .iter_mut()
                    .zip(row)
                    .for_each(|(p, h)| *p = p.min(h.get()));
            }
            flown = flown.saturating_add(1);
            c.first = c.first.min(first - self.margin);
            if all - self.margin < c.all {
                c.all = all - self.margin;
                worst = Some(i);
            }
            if c.all < floor && order.peek().is_some() {
                c.partial = true;
                break;
            }
        }
        let floors = lines.finish(&self.worlds, (tracks, &mut *per_track));
        c.first = c.first.min(floors.0);
        c.all = c.all.min(floors.1);
        if !c.partial && flown == self.worlds.len() {
            let id = self.ids.get().wrapping_add(1).max(1);
            self.ids.set(id);
            self.minima.set(*per_track);
            self.minima_of.set(id);
            c.id = id;
        }
        (c, worst)
    }

    /// Adds the worst world to the critical ones.
    fn mark_worst(&self) {
        let i = self.worst.get();
        let mut set = self.critical.get();
        if let Some(w) = set.get_mut(i / 32) {
            *w |= 1 << u32::try_from(i % 32).unwrap_or(0);
        }
        self.critical.set(set);
    }

    /// The critical worlds ([`Worlds`]), never none: the worst
    /// world at least.
    pub fn critical(&self) -> Worlds {
        self.mark_worst();
        self.critical.get()
    }

    /// Flies `depths` as [`Tube::certify`] does, in the worlds of `mask`
    /// only ([`Worlds`]): the certificate is `partial` unless the
    /// mask holds every world; its altitudes bound the full one's from
    /// above.
    pub fn certify_only(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        depths: &[f32],
        mask: Worlds,
        flights: &mut u32,
    ) -> Certificate {
        let mut per_track = [f32::INFINITY; MAX_TRACKS];
        self.screen(sc, bottom, depths, mask, (flights, &mut per_track))
    }

    /// [`Tube::certify_only`] with each track's least altitude over those
    /// worlds (less the margin) into `per_track`, m.
    pub fn screen(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        depths: &[f32],
        mask: Worlds,
        (flights, per_track): (&mut u32, &mut [f32; MAX_TRACKS]),
    ) -> Certificate {
        let n = self.worlds.len();
        let order = (0..n).filter(|&i| has(&mask, i));
        let at = (f32::NEG_INFINITY, flights, per_track);
        let (mut c, _) = self.fly_worlds(sc, bottom, depths, order, at);
        c.partial = (0..n).any(|i| !has(&mask, i));
        c
    }

    /// The worlds that sink the vehicle most: the flight-path offset and
    /// the vertical current at their declared bounds (every speed), with
    /// the critical ones ([`Tube::critical`]). On the Monterey lines the
    /// critical worlds are these.
    pub fn sinking(&self) -> Worlds {
        let top =
            |f: fn(&World) -> f32| self.worlds.iter().map(f).fold(f32::NEG_INFINITY, f32::max);
        let (alpha, w) = (top(|w| w.flight_path_offset), top(|w| w.vertical_current));
        let mut set = self.critical();
        for (i, world) in self.worlds.iter().enumerate() {
            if world.flight_path_offset >= alpha
                && world.vertical_current >= w
                && let Some(word) = set.get_mut(i / 32)
            {
                *word |= 1 << u32::try_from(i % 32).unwrap_or(0);
            }
        }
        set
    }
}

/// Certifies a fixed line (model contract §12): `depths` (one per track
/// from `first`) flown open loop from `start` in every declared world over
/// `bottom` (the certification bottom, or the map when the map is exact).
/// Writes each track's least altitude over the worlds and the floors
/// between a line's levels (`valley.rs`, the first [`MAX_TRACKS`] tracks),
/// less the vehicle margin (module docs), into `least` (m; `-inf` where a
/// world's flight fails).
///
/// # Errors
/// [`SimError`] for bad arguments (`least` shorter than `depths`, tracks
/// past the line, a waypoint outside `bottom`).
pub fn certify_line<const N: usize>(
    sc: &Scenario<'_, N>,
    bottom: ProfileView<'_>,
    start: &VehicleState<N>,
    (first, depths): (usize, &[f32]),
    least: &mut [f32],
) -> Result<(), SimError> {
    let least = least.get_mut(..depths.len()).ok_or(SimError::ScoreBuffer)?;
    least.iter_mut().for_each(|l| *l = f32::INFINITY);
    // Every world shares the waypoints' check against `bottom`.
    sc.in_world(&World::nominal(sc.vehicle()), bottom)?;
    let u = sc.mission().uncertainty();
    let margin = vehicle_margin(sc.vehicle(), u);
    let mut flights = 0;
    let worlds = World::corners(sc.vehicle(), u);
    let keep = LineRows::default();
    let mut lines = Lines::new(&keep, &worlds, 0);
    let mut per_track = [f32::INFINITY; MAX_TRACKS];
    let all = Cell::from_mut(&mut *least).as_slice_of_cells();
    for (i, w) in worlds.iter().enumerate() {
        let at = (start, first);
        let (row, _) = lines.slot(i, &worlds, (depths.len(), &mut per_track));
        let count = (&mut flights, u32::MAX);
        match row {
            Some(row) => {
                fly_world(sc, w, bottom, at, depths, (margin, row), count);
                per_track
                    .iter_mut()
                    .zip(row)
                    .for_each(|(p, h)| *p = p.min(h.get()));
                if depths.len() > MAX_TRACKS {
                    // (The tracks past the rows' reach, flown again.)
                    let count = (&mut flights, u32::MAX);
                    fly_world(sc, w, bottom, at, depths, (margin, all), count);
                }
            }
            None => {
                fly_world(sc, w, bottom, at, depths, (margin, all), count);
            }
        }
    }
    lines.finish(&worlds, (depths.len(), &mut per_track));
    for (l, &p) in all.iter().zip(&per_track) {
        l.set(l.get().min(p));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Mission, Profile, Waypoints};

    /// The vehicle margin: 0 with nothing about the vehicle declared, 15 s
    /// of drift, and at least two samples' climb at the pitch limit when
    /// the motion is uncertain (the default vehicle: 2 × 1.5 m/s × 0.1 s ×
    /// tan 25° = 139.9 mm).
    #[test]
    fn the_vehicle_margin_is_at_least_two_samples_climb() {
        let v = Vehicle::c_auv4().unwrap();
        let m = |alpha: f32, w: f32| {
            vehicle_margin(&v, &Uncertainty::new(5.0, 0.0, 1.0, 0.0, alpha, w).unwrap())
        };
        assert_eq!(m(0.0, 0.0), 0.0);
        let climb = 2.0 * 1.5 * 0.1 * libm::tanf(25.0_f32.to_radians());
        assert!((m(0.01, 0.0) - climb).abs() < 1e-5, "{}", m(0.01, 0.0));
        assert!((m(0.0, 0.001) - climb).abs() < 1e-5);
        assert!((m(0.0, 0.07) - 15.0 * 0.07).abs() < 1e-4);
    }

    /// A partial certificate bounds the full one from above, and the
    /// critical worlds, or all of them, give the full certificate's value
    /// where they hold the worst world.
    #[test]
    fn partial_and_screened_certificates_bound_the_full_one() {
        let v = Vehicle::c_auv4().unwrap();
        let p =
            Profile::<8>::new(&[0.0, 400.0, 700.0, 1500.0], &[300.0, 300.0, 180.0, 200.0]).unwrap();
        let w = Waypoints::<4>::new(&[0.0, 600.0, 1400.0]).unwrap();
        let u = Uncertainty::new(0.0, 0.0, 0.0, 0.05, 1.0, 0.05).unwrap();
        let sc = Scenario::new(&v, &p, &w, Mission::default().with_uncertainty(u)).unwrap();
        let start = sc.start_state(220.0);
        let mut tube = Tube::default();
        let worlds = World::corners(&v, &u);
        let n = worlds.len();
        tube.prepare((worlds, vehicle_margin(&v, &u)), &start, 0);
        let mut flights = 0;
        let depths = [230.0, 110.0];
        let full = tube.certify(&sc, p.view(), &depths, (f32::NEG_INFINITY, &mut flights));
        assert!(!full.partial && full.all.is_finite() && n == MAX_WORLDS);
        assert_eq!(flights as usize, n);
        // Asked for a floor above it: stops after the worst world, first.
        let mut few = 0;
        let part = tube.certify(&sc, p.view(), &depths, (full.all + 1.0, &mut few));
        assert!(part.partial && few == 1, "{part:?} after {few} flights");
        assert_eq!(part.all.to_bits(), full.all.to_bits());
        // The critical worlds hold the worst one: the same least altitude,
        // from fewer flights; all worlds: the full certificate itself.
        let mut screened = 0;
        let c = tube.certify_only(&sc, p.view(), &depths, tube.critical(), &mut screened);
        assert!(c.partial && (screened as usize) < n);
        assert_eq!(c.all.to_bits(), full.all.to_bits());
        assert!(c.first >= full.first);
        let all = tube.certify_only(&sc, p.view(), &depths, [u32::MAX; 3], &mut screened);
        assert!(!all.partial);
        assert_eq!(
            (all.all.to_bits(), all.first.to_bits()),
            (full.all.to_bits(), full.first.to_bits())
        );
    }
}
