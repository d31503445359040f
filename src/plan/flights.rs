//! [`Flights`]: every plain flight of one planner call, from its start
//! state, counted (the plan's `evaluations`).

use crate::sim::{Scenario, SimError, TrackScore, VehicleState};

/// Flies one track at a time from a call's start state, counting flights.
pub(super) struct Flights<'s, 'a, const N: usize> {
    pub sc: Scenario<'a, N>,
    pub state: &'s VehicleState<N>,
    pub track: usize,
    /// Flights so far.
    pub count: u32,
    /// Most flights (`u32::MAX`: no budget); a flight past it is refused
    /// with [`SimError::FlightBudget`].
    pub limit: u32,
}

impl<const N: usize> Flights<'_, '_, N> {
    /// Flies the call's track at depth `z` from the call's state.
    pub fn fly(&mut self, z: f32) -> Result<(TrackScore, VehicleState<N>), SimError> {
        let st = *self.state;
        self.fly_from(&st, 0, z)
    }

    /// Flies track `track + j` at depth `z` from `st`.
    pub fn fly_from(
        &mut self,
        st: &VehicleState<N>,
        j: usize,
        z: f32,
    ) -> Result<(TrackScore, VehicleState<N>), SimError> {
        if self.count >= self.limit {
            return Err(SimError::FlightBudget);
        }
        self.count = self.count.saturating_add(1);
        let mut score = [TrackScore::default()];
        let next = self
            .sc
            .fly(st, self.track.saturating_add(j), &[z], &mut score)?;
        Ok((score[0], next))
    }
}
