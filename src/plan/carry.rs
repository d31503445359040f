//! A track flown at a depth the planner did not choose
//! ([`Planner::carry`]): a climb after a predicted collision, an
//! operator's override. The declared worlds fly through it too, so the
//! next call's certificates start from the worlds' states there, not
//! afresh from the nominal state (model contract §12: the line is
//! certified from its start).

use crate::sim::{Scenario, TrackScore, VehicleState};

use super::commit::{certification_bottom, nominal_only};
use super::planner::{Continuation, Planner};
use super::status::PlanError;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// Flies `track` (0-based) at reference depth `depth` (m), which this
    /// planner did not plan, from `state` (the state in which the vehicle
    /// reaches the track's first waypoint, which may be below the bottom),
    /// and carries each declared world's state through it. Returns the
    /// predicted state at the track's last waypoint: the next call's
    /// start, from which that call's certificates keep the worlds' spread.
    /// The warm start and the continuation are forgotten (they were for
    /// another depth).
    ///
    /// # Errors
    /// [`PlanError::Sim`] for a flight that cannot run (a track outside
    /// the line, a state not finite or not on it, a depth not finite), and
    /// [`PlanError::NoCertificationBottom`] as [`Planner::plan`].
    pub fn carry(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
        depth: f32,
    ) -> Result<VehicleState<N>, PlanError> {
        let bottom = certification_bottom(sc)?;
        let mut score = [TrackScore::default()];
        let next = sc.fly(state, track, &[depth], &mut score)?;
        if !self.tube.prepare_for(sc, state, track) {
            // (As a commit: `J` is weighed from where the worlds start.)
            self.line_j = 0.0;
        }
        let only_nominal = nominal_only(sc, bottom, &self.tube, state);
        let lazy = self.cfg.max_evaluations == u32::MAX;
        let mut flights = 0;
        self.tube.advance(
            (sc, bottom),
            depth,
            &next,
            (only_nominal, lazy, &mut flights),
        );
        self.warm = None;
        self.cont = Continuation::NONE;
        Ok(next)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Mission, Profile, Uncertainty, Vehicle, Waypoints};
    use crate::plan::{Mode, PlannerConfig, certify_line};

    /// A track flown at a depth the planner did not choose, between two
    /// planned ones: the next call's certificate is the whole line's from
    /// the start (the worlds carried through the override), not the one
    /// from the override's predicted end with every world starting there.
    #[test]
    fn the_worlds_fly_through_a_carried_track() {
        let v = Vehicle::c_auv4().unwrap();
        let p =
            Profile::<8>::new(&[0.0, 400.0, 700.0, 2200.0], &[300.0, 300.0, 180.0, 200.0]).unwrap();
        // (Track 2 starts 150 m into the override's climb, the worlds
        // still apart.)
        let w = Waypoints::<4>::new(&[0.0, 600.0, 750.0, 2100.0]).unwrap();
        let u = Uncertainty::new(0.0, 0.0, 0.0, 0.1, 2.0, 0.1).unwrap();
        let sc = Scenario::new(&v, &p, &w, Mission::default().with_uncertainty(u)).unwrap();
        let start = sc.start_state(220.0);
        for mode in [Mode::TrackWise, Mode::Horizon] {
            let cfg = PlannerConfig {
                mode,
                ..PlannerConfig::default()
            };
            let mut planner = Planner::<3>::new(cfg).unwrap();
            let first = planner.plan(&sc, &start, 0).unwrap();
            // An override: well above the planned depth.
            let carried = planner.carry(&sc, &first.next_state, 1, 60.0).unwrap();
            assert!(planner.continuation().is_empty());
            let last = planner.plan(&sc, &carried, 2).unwrap();
            let mut least = [0.0; 3];
            let depths = [first.depth, 60.0, last.depth];
            certify_line(&sc, p.view(), &start, (0, &depths), &mut least).unwrap();
            assert!(
                (last.certified_min_altitude - least[2]).abs() < 1e-3,
                "{mode:?}: {} against the line's {}",
                last.certified_min_altitude,
                least[2]
            );
            // Every world started afresh from the carried state instead
            // (what the call certified before `carry`): higher.
            let mut from_there = [0.0; 1];
            certify_line(&sc, p.view(), &carried, (2, &[last.depth]), &mut from_there).unwrap();
            assert!(
                from_there[0] > least[2] + 0.2,
                "{mode:?}: {from_there:?} {least:?}"
            );
        }
    }
}
