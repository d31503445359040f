//! A flight whose waypoint switch falls one sample the other way.
//!
//! The reference switches to the next track at the first sample at or past
//! its waypoint (contract §3). Where a sample lands within a hair of the
//! waypoint, the same depths flown in other arithmetic (an f64
//! implementation, or the vehicle's own) can switch one sample earlier or
//! later, and the next track's flight differs by far more than the
//! rounding. [`Scenario::on_edge`] says when a flight's end is that
//! close ([`EDGE`]); [`Scenario::switch_other_way`] gives the state the
//! other switch starts the next track from, so that a planner can fly
//! both.
//!
//! Over 888 crossings of 256 random lines, the f32 and f64 flights of the
//! same depths put the sample nearest a waypoint 0.05 mm apart at the
//! median and 0.8 mm at most (`plan/knife.rs`).

use crate::num::Comp;

use super::{Scenario, SimError, TrackScore, VehicleState};

/// Least distance, m, of the samples either side of a waypoint from it
/// for a flight's switch there to be the same in any arithmetic: the
/// knife edge's half-width.
pub(crate) const EDGE: f32 = 2e-3;

/// The signed distance, m, from waypoint `end` to the nearer of the two
/// samples around it in a flight ending at `next` (the first sample at or
/// past it): positive for the one past it, negative for the one before.
pub(crate) fn offset<const N: usize>(next: &VehicleState<N>, end: f32) -> f32 {
    let after = next.x.minus(end);
    let before = next.x_prev.minus(end);
    if after <= -before { after } else { before }
}

impl<const N: usize> Scenario<'_, N> {
    /// Waypoint `X_{track+1}`, m, when a track follows it (the knife
    /// edge is then the next track's).
    pub(crate) fn edge_waypoint(&self, track: usize) -> Option<f32> {
        let wp = self.waypoints.positions();
        let end = wp.get(track.saturating_add(1)).copied()?;
        (track.saturating_add(2) < wp.len()).then_some(end)
    }

    /// Whether a flight of track `track` ending at `next` puts a sample
    /// within [`EDGE`] of the waypoint ending it, a track following.
    pub(crate) fn on_edge(&self, track: usize, next: &VehicleState<N>) -> bool {
        // (NaN is not near.)
        self.edge_waypoint(track)
            .is_some_and(|end| libm::fabsf(offset(next, end)) < EDGE)
    }

    /// The flight of track `track` at reference `depth` (m) from `start`,
    /// whose own end is `next` (the first sample at or past waypoint
    /// `X_{track+1}`), with its switch one sample the other way from the
    /// sample nearer the waypoint: one sample later where `next` is the
    /// nearer, one sample earlier where the sample before it is. Its end
    /// state replaces `next`; a state one sample early lies short of the
    /// waypoint by less than the nearer sample's distance and is put at
    /// `X_{track+1}` (a move of that distance along track, so that the
    /// next track can start from it), its previous sample where it was.
    /// `start` is used up (moved along track) and `score` scored anew.
    /// (In place: a certificate's flight holds no more states for it.)
    ///
    /// # Errors
    /// [`SimError`] for a track past the line or a flight that fails.
    #[inline(always)]
    pub(crate) fn switch_other_way(
        &self,
        (start, next): (&mut VehicleState<N>, &mut VehicleState<N>),
        (track, depth): (usize, f32),
        score: &mut [TrackScore; 1],
    ) -> Result<(), SimError> {
        let wp = self.waypoints.positions();
        let end = *wp
            .get(track.saturating_add(1))
            .ok_or(SimError::TrackRange)?;
        let (after, before) = (next.x.minus(end), next.x_prev.minus(end));
        if after <= -before {
            // One sample later: the run ends half a step past `next`.
            let stop = next.x.value() + 0.5 * next.x.diff(next.x_prev);
            *next = self.fly_to(start, (track, &[depth]), score, Some(stop))?;
            return Ok(());
        }
        // One sample earlier: the flight moved on along track by what the
        // sample before `next` lacks of the waypoint (and a hair), which
        // moves no state but the position (the loop's dynamics do not
        // depend on it), so that sample is the first past the waypoint.
        let shift = -before + EDGE * 1e-3;
        start.x = start.x.add(shift);
        start.x_prev = start.x_prev.add(shift);
        *next = self.fly_to(start, (track, &[depth]), score, None)?;
        next.x = Comp::new(end);
        next.x_prev = next.x_prev.add(-shift);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Mission, Profile, Vehicle, Waypoints};

    /// The other switch ends one sample after the flight's own end where
    /// that end is the sample nearer the waypoint, else at the sample
    /// before it, put on the waypoint; the flight up to there is the same.
    #[test]
    fn the_other_switch_is_one_sample_later_or_earlier() {
        let v = Vehicle::c_auv4().unwrap();
        let p =
            Profile::<8>::new(&[0.0, 400.0, 700.0, 1500.0], &[300.0, 300.0, 180.0, 200.0]).unwrap();
        let w = Waypoints::<4>::new(&[0.0, 600.0, 1400.0]).unwrap();
        let sc = Scenario::new(&v, &p, &w, Mission::default()).unwrap();
        let start = sc.start_state(220.0);
        let mut seen = [false; 2];
        for k in 0..40 {
            let z = 200.0 + 0.37 * k as f32;
            let mut s = [TrackScore::default()];
            let next = sc.fly(&start, 0, &[z], &mut s).unwrap();
            let mut other = next;
            let mut from = start;
            sc.switch_other_way((&mut from, &mut other), (0, z), &mut s)
                .unwrap();
            let step = next.x.diff(next.x_prev);
            if offset(&next, 600.0) >= 0.0 {
                seen[0] = true;
                assert!((other.x_prev.diff(next.x)).abs() < 1e-4, "{z}");
                assert!((other.x.diff(next.x) - step).abs() < 0.01 * step, "{z}");
            } else {
                seen[1] = true;
                assert_eq!(other.x.value(), 600.0);
                assert!((other.depth.diff(next.depth_prev)).abs() < 1e-4, "{z}");
            }
            // A next track starts from it.
            let mut s2 = [TrackScore::default()];
            assert!(sc.fly(&other, 1, &[150.0], &mut s2).is_ok());
        }
        assert_eq!(seen, [true, true]);
        // On the edge only within EDGE of the waypoint, with a track after.
        let mut s = [TrackScore::default()];
        let next = sc.fly(&start, 0, &[210.0], &mut s).unwrap();
        let near = libm::fabsf(offset(&next, 600.0)) < EDGE;
        assert_eq!(sc.on_edge(0, &next), near);
        assert!(sc.edge_waypoint(1).is_none());
    }
}
