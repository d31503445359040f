//! The objective the optimizer minimizes over a horizon: for the SQP
//! (BFGS), `Σ J` under each segment's least altitude at or above the
//! target altitude; for GD and a single track, `Φ(ζ) = Σ J + μ Σ V`. Both
//! with their exact gradients from the tangent pass.

use core::cell::Cell;

use crate::optim::Objective;
use crate::optim::sqp::{Constrained, Linearized};
use crate::sim::{Scenario, SimError, TrackScore, VehicleState, Watch};

use super::scan::with_depth;

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
    /// The SQP's target altitudes (m): the first track's least altitude at
    /// or above `target.0`, every later one's at or above `target.1`, is
    /// feasible.
    pub target: (f32, f32),
    /// Segments further above the target than this (m) stay out of the
    /// SQP's step.
    pub band: f32,
    /// Raises of each track's target (m, the horizon's tracks in order):
    /// the gap between its nominal and its certified least altitude
    /// (`gaps.rs`). The caller's buffer, one cell per horizon track (none:
    /// no raise), written between the SQP's runs.
    pub gaps: &'a [Cell<f32>],
    /// Whether the constraint rows are secants from plain flights
    /// [`SECANT_STEP`] apart instead of tangents
    /// ([`PlanObjective::secant_rows`]).
    pub secant: bool,
    /// A restart's ceiling, m³: the SQP gives up after its
    /// [`CEILING_PROBE`]-th iteration where its iterate's `J` is not below
    /// it and, at that iteration's pace, would take more than
    /// [`CEILING_PACE`] more to get there (`kink.rs`); none: never.
    pub ceiling: Option<f32>,
}

/// The iteration after which a run with a [`PlanObjective::ceiling`]
/// is judged.
pub(super) const CEILING_PROBE: u32 = 2;

/// Iterations, at the probe's pace, within which a run above its
/// [`PlanObjective::ceiling`] must be able to reach it to go on.
pub(super) const CEILING_PACE: f32 = 10.0;

/// The step of the constraint rows' secants, m: past the teeth of a
/// least altitude where the depth loop integrates (a few centimetres
/// wide), as the single track's second look (`single.rs`).
pub(super) const SECANT_STEP: f32 = 0.5;

/// How far above its target (a share of the band `h_r − h_a`) a later
/// track still counts as held where the depth loop integrates
/// ([`PlanObjective::held_slack_teeth`]). At 0.05, on `check_planner.py
/// --seed 3196 --vehicle tools/reference/vehicles/fast.toml`
/// (`unseen_3196_0`, band 8 m) the cold SQP stopped on a tooth with track
/// 2 0.6 m above its target, `J` still falling 45e3 m³ a metre deeper, so
/// the lift never looked at it; the best safe plan climbs track 1 on its
/// plateau (any depth above 900 m flies the same) so that track 2 flies
/// 24 m deeper: the line 1.113× the f64 search's best safe plan. At 0.1,
/// 1.0015×; on the 304 random lines of BENCHMARKS.md in horizon mode 4
/// lower (to −0.69 %), one higher (+0.022 %), 5.3 flights a line more;
/// track by track and the 18 shared runs unchanged.
pub(super) const TEETH_SLACK: f32 = 0.1;

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
            target: (f32::NEG_INFINITY, f32::NEG_INFINITY),
            band: f32::INFINITY,
            gaps: &[],
            secant: false,
            ceiling: None,
        }
    }
}

impl<const N: usize> PlanObjective<'_, N> {
    /// The scores of a plain flight of the horizon `z` (no tangents; the
    /// entries past `count` default). Counts as an evaluation, within the
    /// budget; leaves the last point's records (`last_*`) alone.
    pub fn flight<const K: usize>(&mut self, z: &[f32; K]) -> Result<[TrackScore; K], Stop> {
        self.count_flight()?;
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

    /// Whether the vehicle's depth loop integrates ([`teeth`]).
    pub(super) fn teeth(&self) -> bool {
        teeth(&self.sc)
    }

    /// Whether the mission declares uncertainty (the call certifies its
    /// plan over the declared worlds).
    pub(super) fn declared(&self) -> bool {
        *self.sc.mission().uncertainty() != crate::model::Uncertainty::NONE
    }

    /// The SQP's target altitude of track `t` of the horizon, m.
    pub(super) fn target_of(&self, t: usize) -> f32 {
        let base = if t == 0 { self.target.0 } else { self.target.1 };
        base + self.gaps.get(t).map_or(0.0, Cell::get)
    }

    /// The ℓ1 infeasibility of `scores` for the SQP: the sum over the
    /// tracks of their least altitude's shortfall below their target, m.
    fn infeasibility(&self, scores: &[TrackScore]) -> f32 {
        scores
            .iter()
            .take(self.count)
            .enumerate()
            .map(|(t, s)| (self.target_of(t) - s.min_altitude()).max(0.0))
            .sum()
    }

    /// Counts one flight within the budget.
    fn count_flight(&mut self) -> Result<(), Stop> {
        if self.tripped.is_some() {
            return Err(Stop::LeftSafeSet);
        }
        if self.evaluations >= self.budget {
            return Err(Stop::Budget);
        }
        self.evaluations = self.evaluations.saturating_add(1);
        Ok(())
    }

    /// The scores of tracks `0..j` of the horizon `z` and the state they
    /// end in (the start's for `j = 0`): one flight, counted as
    /// [`Self::flight`], none for `j = 0`.
    pub fn head<const K: usize>(
        &mut self,
        z: &[f32; K],
        j: usize,
    ) -> Result<([TrackScore; K], VehicleState<N>), Stop> {
        let mut scores = [TrackScore::default(); K];
        if j == 0 {
            return Ok((scores, *self.start));
        }
        self.count_flight()?;
        let used = z
            .get(..j.min(self.count))
            .ok_or(Stop::Sim(SimError::TrackRange))?;
        let sc = scores
            .get_mut(..used.len())
            .ok_or(Stop::Sim(SimError::TrackRange))?;
        let end = self
            .sc
            .fly(self.start, self.track, used, sc)
            .map_err(Stop::Sim)?;
        Ok((scores, end))
    }

    /// `(Σ J, v)` of the horizon `z` whose tracks before `j` flew `head`
    /// and left `at_j` (see [`Self::head`]): the tracks from `j` flown, one
    /// flight, counted.
    pub fn tail_value<const K: usize>(
        &mut self,
        head: &[TrackScore; K],
        (at_j, j): (&VehicleState<N>, usize),
        z: &[f32; K],
    ) -> Result<(f32, f32), Stop> {
        self.count_flight()?;
        let used = z
            .get(j..self.count)
            .ok_or(Stop::Sim(SimError::TrackRange))?;
        let mut scores = *head;
        let tail = scores
            .get_mut(j..self.count)
            .ok_or(Stop::Sim(SimError::TrackRange))?;
        self.sc
            .fly(at_j, self.track.saturating_add(j), used, tail)
            .map_err(Stop::Sim)?;
        self.value_of(&scores)
    }

    /// Track `j` of the horizon alone flown at depth `zj` (m) from `at_j`,
    /// the state it starts in: its least altitude, m. One flight, counted.
    pub fn least_of_track(
        &mut self,
        at_j: &VehicleState<N>,
        j: usize,
        zj: f32,
    ) -> Result<f32, Stop> {
        let [flown] = self.fly_from::<1>((at_j, j), &[zj])?;
        Ok(flown.min_altitude())
    }

    /// Tracks `j..=g` of the horizon flown at `z` from `at_j`, the state
    /// track `j` starts in: track `g`'s least altitude, m. One flight,
    /// counted.
    pub fn least_at<const K: usize>(
        &mut self,
        (at_j, j): (&VehicleState<N>, usize),
        z: &[f32; K],
        g: usize,
    ) -> Result<f32, Stop> {
        let used = z.get(j..=g).ok_or(Stop::Sim(SimError::TrackRange))?;
        let flown = self.fly_from::<K>((at_j, j), used)?;
        let last = flown
            .get(g.saturating_sub(j))
            .ok_or(Stop::Sim(SimError::TrackRange))?;
        Ok(last.min_altitude())
    }

    /// Tracks `j..=g` of the horizon flown at `z` from `at_j`, the state
    /// track `j` starts in: the scores of tracks `j` and `g`. One flight,
    /// counted.
    pub fn ends<const K: usize>(
        &mut self,
        (at_j, j): (&VehicleState<N>, usize),
        z: &[f32; K],
        g: usize,
    ) -> Result<(TrackScore, TrackScore), Stop> {
        let used = z.get(j..=g).ok_or(Stop::Sim(SimError::TrackRange))?;
        let flown = self.fly_from::<K>((at_j, j), used)?;
        match (flown.first(), flown.get(g.saturating_sub(j))) {
            (Some(&a), Some(&b)) => Ok((a, b)),
            _ => Err(Stop::Sim(SimError::TrackRange)),
        }
    }

    /// Tracks `j..` of the horizon flown at `z` from `at_j`, the state
    /// track `j` starts in: the first of them whose least altitude is
    /// within `slack` (m) of its target, with that altitude (m). One
    /// flight, counted.
    pub fn held_from<const K: usize>(
        &mut self,
        (at_j, j): (&VehicleState<N>, usize),
        z: &[f32; K],
        slack: f32,
    ) -> Result<Option<(usize, f32)>, Stop> {
        let used = z
            .get(j..self.count)
            .ok_or(Stop::Sim(SimError::TrackRange))?;
        let flown = self.fly_from::<K>((at_j, j), used)?;
        Ok(flown
            .iter()
            .take(used.len())
            .enumerate()
            .find_map(|(i, s)| {
                let g = j.saturating_add(i);
                (s.min_altitude() <= self.target_of(g) + slack).then_some((g, s.min_altitude()))
            }))
    }

    /// How far above its target (m) a track's least altitude still counts
    /// as held there: a hundredth of the band `h_r − h_a`, or the
    /// feasibility tolerance `tol` (m) if larger.
    pub fn held_slack(&self, tol: f32) -> f32 {
        let m = self.sc.mission();
        tol.max(0.01 * (m.reference_altitude() - m.min_altitude()))
    }

    /// [`Self::held_slack`], but where the depth loop integrates at least
    /// [`TEETH_SLACK`] of the band: the SQP stops where a tooth's gradient
    /// says, short of the boundary (`lift/`, `polish.rs`), m.
    pub(super) fn held_slack_teeth(&self, tol: f32) -> f32 {
        let m = self.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        let teeth = if self.teeth() {
            TEETH_SLACK * band
        } else {
            0.0
        };
        self.held_slack(tol).max(teeth)
    }

    /// Tracks `j..j + used.len()` of the horizon flown at the depths
    /// `used` (m) from `at_j`, the state track `j` starts in: their scores,
    /// the first `used.len()` of the `L`. One flight, counted.
    fn fly_from<const L: usize>(
        &mut self,
        (at_j, j): (&VehicleState<N>, usize),
        used: &[f32],
    ) -> Result<[TrackScore; L], Stop> {
        self.count_flight()?;
        let mut scores = [TrackScore::default(); L];
        let flown = scores
            .get_mut(..used.len())
            .ok_or(Stop::Sim(SimError::TrackRange))?;
        self.sc
            .fly(at_j, self.track.saturating_add(j), used, flown)
            .map_err(Stop::Sim)?;
        Ok(scores)
    }

    /// `(Σ J, v)` of the horizon's `scores` (m³, m): a non-finite `J` is
    /// a diverged flight.
    pub(super) fn value_of(&self, scores: &[TrackScore]) -> Result<(f32, f32), Stop> {
        let sc = scores.get(..self.count).unwrap_or(&[]);
        let total: f32 = sc.iter().map(TrackScore::j).sum();
        if total.is_finite() {
            Ok((total, self.infeasibility(sc)))
        } else {
            Err(Stop::Sim(SimError::Diverged))
        }
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
        self.count_flight()?;
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

impl<const N: usize, const K: usize> Constrained<K> for PlanObjective<'_, N> {
    type Error = Stop;

    /// `Σ J`, its gradient, and one constraint per segment of the horizon
    /// (`watch.rs`): its least altitude above the target, with its
    /// gradient, grouped by track.
    fn linearize(&mut self, z: &[f32; K], gn: bool, out: &mut Linearized<K>) -> Result<(), Stop> {
        self.count_flight()?;
        let wp = self.sc.waypoints().positions();
        let h_r = self.sc.mission().reference_altitude();
        let records = (&mut out.c[..], &mut out.a[..], &mut out.group[..]);
        let (mut watch, rows) = Watch::new(
            (wp, self.track, self.count),
            h_r,
            records,
            gn.then_some(&mut out.gn),
        );
        // (A match, not `map_err` and `?`: those copied the evaluation
        // twice, a few hundred bytes of this frame under every SQP step.)
        let e = match self
            .sc
            .evaluate_watched(self.start, self.track, z, self.count, &mut watch)
        {
            Ok(e) => e,
            Err(err) => return Err(Stop::Sim(err)),
        };
        out.rows = rows;
        out.j = e.j;
        out.grad = e.grad_j;
        if self.secant {
            self.secant_rows(z, &e.scores, out)?;
        }
        // Each segment's least altitude above its track's target.
        for (c, &t) in out.c.iter_mut().zip(out.group.iter()).take(rows) {
            *c -= self.target_of(usize::from(t));
        }
        out.infeasibility = self.infeasibility(&e.scores);
        out.band = self.band;
        self.last_violation = out.infeasibility;
        self.last_min_altitude = e.min_altitude;
        self.last_flight = None;
        Ok(())
    }

    fn value(&mut self, z: &[f32; K]) -> Result<(f32, f32), Stop> {
        let scores = self.flight(z)?;
        self.value_of(&scores)
    }

    /// At the [`PlanObjective::ceiling`]'s probe, an iterate not below it
    /// that its last iteration's decrease (a rise included) would not take
    /// there in [`CEILING_PACE`] more (nor a `J` that is not a number).
    fn abandon(&self, iterations: u32, (before, j): (f32, f32)) -> bool {
        self.ceiling.is_some_and(|c| {
            let on_pace = j < c || j - c <= CEILING_PACE * (before - j);
            iterations == CEILING_PROBE && !on_pace
        })
    }
}

impl<const N: usize> PlanObjective<'_, N> {
    /// Each constraint row of `out` made its track's secant: for every
    /// depth `j` up to the row's track, the least altitude of a plain
    /// flight with `z_j` [`SECANT_STEP`] deeper less `base`'s (the tangent
    /// pass's scores at `z`), over the step (m/m). Where the depth loop
    /// integrates, the least altitude has teeth and its tangent is the
    /// slope between the integrator's switches, not the trend: on
    /// `unseen_2994_3` (`BENCHMARKS.md`, round 34) track 5's row read
    /// (−0.82, −0.006, 0, 0, −0.60) m/m where the f64 secants over
    /// ±0.5 m read (−0.02, −0.96, 0, 0, −0.04). The gradient of `J` is
    /// made the same flights' secant against `out.j` (the tangent pass's
    /// `J` at `z`, the sum of `base`'s): `J` has teeth there too (on
    /// `check_planner.py --seed 3171 --vehicle
    /// tools/reference/vehicles/twoki.toml`, `unseen_3171_3`, the tangent
    /// read `∂J/∂z_2` = +3.7e3 m² where the secant reads −9.9e3 and `J`
    /// falls 7.5e3 m³ a metre over 20 m; with tangent gradient and secant
    /// rows the restart stayed, the line 1.0160× the f64 search's best
    /// safe plan; after, 1.0009×). One plain flight a depth, counted; not
    /// inlined: its frame stays off the tangent pass's stack.
    #[inline(never)]
    fn secant_rows<const K: usize>(
        &mut self,
        z: &[f32; K],
        base: &[TrackScore; K],
        out: &mut Linearized<K>,
    ) -> Result<(), Stop> {
        for (j, &zj) in z.iter().enumerate().take(self.count) {
            let scores = self.flight(&with_depth(z, j, zj + SECANT_STEP))?;
            let jt: f32 = scores.iter().take(self.count).map(TrackScore::j).sum();
            if let Some(g) = out.grad.get_mut(j) {
                *g = (jt - out.j) / SECANT_STEP;
            }
            let rows = out.a.iter_mut().zip(out.group.iter()).take(out.rows);
            for (row, &g) in rows {
                let g = usize::from(g);
                let (Some(hi), Some(lo)) = (scores.get(g), base.get(g)) else {
                    continue;
                };
                if let Some(slot) = row.get_mut(j).filter(|_| g >= j) {
                    *slot = (hi.min_altitude() - lo.min_altitude()) / SECANT_STEP;
                }
            }
        }
        Ok(())
    }
}

/// Whether the vehicle of `sc` has a depth loop that integrates (`ki >
/// 0`): it does so conditionally, and `J` and the least altitude have
/// teeth (`polish.rs`, `fallback.rs`).
pub(super) fn teeth<const N: usize>(sc: &Scenario<'_, N>) -> bool {
    sc.vehicle().autopilot().config().depth_pid.ki > 0.0
}
