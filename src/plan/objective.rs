//! The objective the optimizer minimizes over a horizon,
//! `Φ(ζ) = Σ J + μ Σ V`, with its exact gradient from the tangent pass.

use crate::optim::Objective;
use crate::sim::{Scenario, SimError, TrackScore, VehicleState};

/// Why [`PlanObjective`] did not return a value: the flight failed, the
/// budget is spent, or (a constrained single track) the optimizer has left
/// the safe set and the boundary search takes over. An explicit stop, not an error
/// sentinel: the optimizer treats both as a failed trial.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Stop {
    /// The simulation failed at this point.
    Sim(SimError),
    /// A depth below the certified altitude was evaluated (see
    /// [`PlanObjective::guard`]); every later evaluation stops too.
    LeftSafeSet,
    /// The evaluation budget is spent.
    Budget,
}

/// `Φ(ζ) = Σ J + μ Σ V` over the horizon, with its exact gradient.
pub(super) struct PlanObjective<'a, const N: usize> {
    pub sc: Scenario<'a, N>,
    pub start: &'a VehicleState<N>,
    pub track: usize,
    pub count: usize,
    pub mu: f32,
    pub evaluations: u32,
    /// Most evaluations; the next one after them stops.
    pub budget: u32,
    /// `Σ V` at the last point evaluated: the optimizers' last evaluation
    /// is always the point they return.
    pub last_violation: f32,
    /// Least altitude over the horizon at the last point evaluated, m.
    pub last_min_altitude: f32,
    /// With one track: the last depth evaluated, its score and end state,
    /// which the verification then need not fly again.
    pub last_flight: Option<(f32, TrackScore, VehicleState<N>)>,
    /// With one track, constrained: the certified altitude `h_a + m_s`. The
    /// first depth evaluated below it stops the optimizer (every later
    /// evaluation stops without a flight), so that the boundary search
    /// takes over from the best safe depth it had reached.
    pub guard: Option<f32>,
    /// That first unsafe depth and its minimum altitude (m, m).
    pub tripped: Option<(f32, f32)>,
    /// The safe depth of least `J` evaluated, with `J` and its minimum
    /// altitude (m, m³, m).
    pub best_safe: Option<(f32, f32, f32)>,
}

impl<'a, const N: usize> PlanObjective<'a, N> {
    /// The objective over `count` tracks from `track`, flown from `start`.
    pub fn new(
        sc: Scenario<'a, N>,
        start: &'a VehicleState<N>,
        track: usize,
        count: usize,
        mu: f32,
    ) -> Self {
        Self {
            sc,
            start,
            track,
            count,
            mu,
            evaluations: 0,
            budget: u32::MAX,
            last_violation: 0.0,
            last_min_altitude: f32::INFINITY,
            last_flight: None,
            guard: None,
            tripped: None,
            best_safe: None,
        }
    }
}

impl<const N: usize> PlanObjective<'_, N> {
    /// The scores of a plain flight of the horizon `z` (no tangents; the
    /// entries past `count` default). Counts as an evaluation, within the
    /// budget; leaves the last point's records (`last_*`) alone.
    pub fn flight<const K: usize>(&mut self, z: &[f32; K]) -> Result<[TrackScore; K], Stop> {
        if self.tripped.is_some() {
            return Err(Stop::LeftSafeSet);
        }
        if self.evaluations >= self.budget {
            return Err(Stop::Budget);
        }
        self.evaluations = self.evaluations.saturating_add(1);
        let used = z.get(..self.count).ok_or(Stop::Sim(SimError::TrackRange))?;
        let mut scores = [TrackScore::default(); K];
        let sc = scores
            .get_mut(..self.count)
            .ok_or(Stop::Sim(SimError::TrackRange))?;
        self.sc
            .fly(self.start, self.track, used, sc)
            .map_err(Stop::Sim)?;
        Ok(scores)
    }

    /// `Φ(ζ)` alone, by a plain flight of the horizon (no tangents): what
    /// a scan needs. As [`Self::flight`].
    pub fn flight_value<const K: usize>(&mut self, z: &[f32; K]) -> Result<f32, Stop> {
        let scores = self.flight(z)?;
        let sc = scores.get(..self.count).unwrap_or(&[]);
        let j: f32 = sc.iter().map(TrackScore::j).sum();
        let violation: f32 = sc.iter().map(TrackScore::violation).sum();
        let phi = j + self.mu * violation;
        if phi.is_finite() {
            Ok(phi)
        } else {
            Err(Stop::Sim(SimError::Diverged))
        }
    }
}

impl<const N: usize, const K: usize> Objective<K> for PlanObjective<'_, N> {
    type Error = Stop;

    fn eval(&mut self, z: &[f32; K]) -> Result<(f32, [f32; K]), Stop> {
        if self.tripped.is_some() {
            return Err(Stop::LeftSafeSet);
        }
        if self.evaluations >= self.budget {
            return Err(Stop::Budget);
        }
        self.evaluations = self.evaluations.saturating_add(1);
        let e = self
            .sc
            .evaluate_tracks(self.start, self.track, z, self.count)
            .map_err(Stop::Sim)?;
        if let (Some(h_safe), 1, Some(&z0)) = (self.guard, self.count, z.first()) {
            if e.min_altitude < h_safe {
                self.tripped = Some((z0, e.min_altitude));
                return Err(Stop::LeftSafeSet);
            }
            if self.best_safe.is_none_or(|b| e.j < b.1) {
                self.best_safe = Some((z0, e.j, e.min_altitude));
            }
        }
        let mut g = e.grad_j;
        for (gi, vi) in g.iter_mut().zip(e.grad_violation.iter()) {
            *gi += *vi * self.mu;
        }
        self.last_violation = e.violation;
        self.last_min_altitude = e.min_altitude;
        self.last_flight = match (self.count, e.scores.first(), z.first()) {
            (1, Some(s), Some(&z0)) => Some((z0, *s, e.end)),
            _ => None,
        };
        Ok((e.j + self.mu * e.violation, g))
    }

    /// A horizon's trial values by a plain flight (a single track's
    /// evaluation records its flight and guards the safe set: no cheaper
    /// value there).
    fn value(&mut self, z: &[f32; K]) -> Option<Result<f32, Stop>> {
        (self.count > 1 && self.guard.is_none()).then(|| self.flight_value(z))
    }
}
