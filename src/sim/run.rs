//! The simulation loop: the vehicle flying its next tracks (model
//! contract §3, §6, §7), scored as it goes (§8).
//!
//! One step, in the contract's order:
//! 1. the active reference `r_k = z_n` for `X_{n-1} <= x_k < X_n`;
//! 2. the autopilot cascade gives `δ_k`, then updates its integrators;
//! 3. `η_{k+1} = Ad η_k + Bd δ_k`;
//! 4. kinematics along the mean pitch `θ̄ = (θ_k + θ_{k+1}) / 2`:
//!    `d += -U0 Ts sin θ̄`, `x += U0 Ts cos θ̄`;
//! 5. `d_{k-1} <- d_k`.
//!
//! A run over tracks `first..first+m` starts from a state on track `first`
//! and ends at the first sample with `x >= X_{first+m}`; that final state is
//! exactly the start state of the next track. Each segment between two
//! samples is scored into the tracks it overlaps as it is flown, so a run
//! costs one pass and no trajectory storage.
//!
//! The loop is written once. A `Sensitivity` hook receives what each step
//! and each scored segment linearize to; the plain simulation passes a
//! no-op that compiles away, the gradient ([`crate::gradient`]) propagates
//! tangents in the same pass.

use crate::model::Cursor;
use crate::num::{DEG, min};

use super::lin::{NoSensitivity, Sensitivity, StepLin};
use super::score::Geo;
use super::{Sample, Scenario, SimError, TrackScore, VehicleState};

/// What a run carries from step to step.
pub(super) struct Flight<const N: usize> {
    pub(super) st: VehicleState<N>,
    /// θ_k: computed once per step, as θ_{k+1} of the step before, deg.
    pub(super) pitch: f32,
    /// `d_k − d_{k−1}`, m.
    pub(super) rise: f32,
    /// Steps left before the run is declared stuck. Every step of the
    /// general path counts, and every steep one (`|θ̄| > 45°`) of the fast
    /// path: a fast step within ±45° moves `x` on by at least `U0 Ts cos
    /// 45°`, and a fast run ends within `fast::FAST_RUN` steps' length, so that
    /// the fast path cannot be stuck.
    pub(super) budget: u32,
    pub(super) cursor: Cursor,
    /// The current sample's geometry.
    pub(super) cur: Geo,
    /// The active track, and `X_{track+1}` where it ends, m.
    pub(super) track: usize,
    pub(super) track_end: f32,
    /// Where the run ends, m.
    pub(super) x_end: f32,
}

/// The end of a run: finite scores and a finite end state, or
/// [`SimError::Diverged`]. Finite inputs of absurd magnitude (a bottom
/// 10¹⁸ m down) can overflow `J` or the violation; an absurd but finite
/// reference (10³⁸ m) can drive an integrator out of range without
/// upsetting the flight, which the clamps keep finite. (Position and depth
/// are finite, or the flight would have failed.)
#[inline(always)]
fn finish<const N: usize>(
    st: VehicleState<N>,
    scores: &[TrackScore],
) -> Result<VehicleState<N>, SimError> {
    if scores
        .iter()
        .any(|s| !(s.min_altitude.is_finite() && s.j().is_finite() && s.violation().is_finite()))
    {
        return Err(SimError::Diverged);
    }
    if !(st.depth_integral.is_finite()
        && st.pitch_integral.is_finite()
        && st.eta.iter().all(|v| v.is_finite()))
    {
        return Err(SimError::Diverged);
    }
    Ok(st)
}

impl<const N: usize> Scenario<'_, N> {
    /// Flies tracks `first_track..first_track + depths.len()` with one
    /// reference depth per track (m) from `start`, scoring each track into
    /// `scores` and handing every sample to `observe`. Returns the state at
    /// the first sample past the last of those tracks.
    ///
    /// # Errors
    /// [`SimError`] for bad arguments or a flight that diverges.
    pub fn simulate<F: FnMut(&Sample)>(
        &self,
        start: &VehicleState<N>,
        first_track: usize,
        depths: &[f32],
        scores: &mut [TrackScore],
        observe: F,
    ) -> Result<VehicleState<N>, SimError> {
        self.run::<_, _, true>(
            start,
            first_track,
            depths,
            scores,
            &mut NoSensitivity,
            observe,
        )
    }

    /// [`Scenario::simulate`] with no observer: the one out-of-line copy
    /// of the loop that every plain flight of the planner shares (each
    /// caller's own `|_| {}` would otherwise be a copy of its own, about
    /// 5 KB of flash each on a Cortex-M4F).
    ///
    /// # Errors
    /// As [`Scenario::simulate`].
    #[inline(always)]
    pub(crate) fn fly(
        &self,
        start: &VehicleState<N>,
        first_track: usize,
        depths: &[f32],
        scores: &mut [TrackScore],
    ) -> Result<VehicleState<N>, SimError> {
        self.fly_to(start, (first_track, depths), scores, None)
    }

    /// [`Scenario::fly`], the run ending at the first sample at or past
    /// `stop` (m) instead of the last track's waypoint where it is given
    /// (`switch.rs`: a switch one sample the other way): the one
    /// out-of-line copy of the loop with no observer.
    ///
    /// # Errors
    /// As [`Scenario::simulate`].
    #[inline(never)]
    pub(crate) fn fly_to(
        &self,
        start: &VehicleState<N>,
        (first_track, depths): (usize, &[f32]),
        scores: &mut [TrackScore],
        stop: Option<f32>,
    ) -> Result<VehicleState<N>, SimError> {
        let none = &mut NoSensitivity;
        self.run_to::<_, _, true>(start, (first_track, depths), scores, (none, |_| {}), stop)
    }

    /// The one simulation loop; see the module docs. `FAST` selects the
    /// in-segment fast path (always, but for the test that compares the
    /// two paths).
    #[inline(always)]
    pub(crate) fn run<Sn: Sensitivity<N>, F: FnMut(&Sample), const FAST: bool>(
        &self,
        start: &VehicleState<N>,
        first: usize,
        depths: &[f32],
        scores: &mut [TrackScore],
        sens: &mut Sn,
        observe: F,
    ) -> Result<VehicleState<N>, SimError> {
        self.run_to::<_, _, FAST>(start, (first, depths), scores, (sens, observe), None)
    }

    /// [`Scenario::run`], ending at the first sample at or past `stop` (m)
    /// where it is given.
    #[inline(always)]
    fn run_to<Sn: Sensitivity<N>, F: FnMut(&Sample), const FAST: bool>(
        &self,
        start: &VehicleState<N>,
        (first, depths): (usize, &[f32]),
        scores: &mut [TrackScore],
        (sens, mut observe): (&mut Sn, F),
        stop: Option<f32>,
    ) -> Result<VehicleState<N>, SimError> {
        let (last, scores) = self.prepare(start, first, depths, scores)?;
        let mut fl = self.begin(start, (first, last), scores, sens, stop)?;
        loop {
            // A sample whose step needs the general treatment: the end of
            // the run, a waypoint switch, a new bottom segment, a sample
            // not scored.
            if fl.cur.past >= 0.0 {
                let plant = self.vehicle.plant();
                observe(&Sample {
                    x: fl.st.x(),
                    depth: fl.st.depth(),
                    pitch: fl.pitch,
                    pitch_rate: plant.pitch_rate_v(&fl.st.eta),
                    reference: None,
                    command: None,
                });
                break;
            }
            let wp = self.waypoints.positions();
            while fl.track.saturating_add(1) < last && fl.st.x.minus(fl.track_end) >= 0.0 {
                fl.track = fl.track.saturating_add(1);
                fl.track_end = *wp
                    .get(fl.track.saturating_add(1))
                    .ok_or(SimError::TrackRange)?;
            }
            let slot = fl.track.saturating_sub(first);
            let r = *depths.get(slot).ok_or(SimError::TrackRange)?;
            match fl.cur.at {
                Some(a0) if FAST && fl.st.x.minus(fl.track_end) < 0.0 => {
                    let score = scores.get_mut(slot).ok_or(SimError::ScoreBuffer)?;
                    self.fast_run(&mut fl, a0, r, slot, score, sens, &mut observe)?;
                }
                _ => {
                    fl.budget = fl.budget.checked_sub(1).ok_or(SimError::StepLimit)?;
                    let at = (&mut fl.st, &mut fl.pitch, &mut fl.rise);
                    self.advance(at, (r, fl.track, slot), sens, &mut observe)?;
                }
            }
            // The step just taken, the general way.
            let prev = fl.cur;
            fl.cur = self.geo(&mut fl.cursor, fl.st.x, fl.st.depth, fl.x_end)?;
            self.score(&prev, &fl.cur, fl.track, first, last, scores, sens)?;
        }
        finish(fl.st, scores)
    }

    /// Checks a run's arguments and resets its scores; returns the index
    /// of the waypoint it ends at and the scores it fills.
    #[inline(always)]
    fn prepare<'s>(
        &self,
        start: &VehicleState<N>,
        first: usize,
        depths: &[f32],
        scores: &'s mut [TrackScore],
    ) -> Result<(usize, &'s mut [TrackScore]), SimError> {
        let wp = self.waypoints.positions();
        let last = first
            .checked_add(depths.len())
            .filter(|&l| l > first && l < wp.len())
            .ok_or(SimError::TrackRange)?;
        let scores = scores
            .get_mut(..depths.len())
            .ok_or(SimError::ScoreBuffer)?;
        for (i, s) in scores.iter_mut().enumerate() {
            let t = first.saturating_add(i);
            let a = wp.get(t).copied().unwrap_or(0.0);
            let b = wp.get(t.saturating_add(1)).copied().unwrap_or(0.0);
            *s = TrackScore::new(a, b);
        }
        if let Some(index) = depths.iter().position(|z| !z.is_finite()) {
            return Err(SimError::NonFiniteDepth { index });
        }
        self.check_start(start, first)?;
        Ok((last, scores))
    }

    /// The run's state at its start sample, with the piece of the first
    /// track flown before it scored.
    #[inline(always)]
    fn begin<Sn: Sensitivity<N>>(
        &self,
        start: &VehicleState<N>,
        (first, last): (usize, usize),
        scores: &mut [TrackScore],
        sens: &mut Sn,
        stop: Option<f32>,
    ) -> Result<Flight<N>, SimError> {
        let wp = self.waypoints.positions();
        let x_begin = *wp.get(first).ok_or(SimError::TrackRange)?;
        let mut x_end = *wp.get(last).ok_or(SimError::TrackRange)?;
        let mut track_end = *wp
            .get(first.saturating_add(1))
            .ok_or(SimError::TrackRange)?;
        if let Some(stop) = stop {
            // (One track: where it ends is where the run does.)
            x_end = stop;
            if last == first.saturating_add(1) {
                track_end = stop;
            }
        }
        let plant = self.vehicle.plant();
        // Even flying at 75° on average the line would be done by then.
        let max_steps = 4.0 * (x_end - start.x()) / self.kin.step + 100.0;
        let st = *start;
        let mut cursor = Cursor::default();
        let cur = self.geo(&mut cursor, st.x, st.depth, x_end)?;
        if st.x_prev.diff(st.x) < 0.0 {
            let mut c0 = Cursor::default();
            let prev = if st.x_prev.minus(x_begin) >= 0.0 {
                self.geo(&mut c0, st.x_prev, st.depth_prev, x_end)?
            } else {
                Geo {
                    x: st.x_prev,
                    d: st.depth_prev,
                    at: None,
                    past: st.x_prev.minus(x_end),
                }
            };
            self.score(&prev, &cur, first, first, last, scores, sens)?;
        } else if let (Some(a), Some(s)) = (cur.at, scores.first_mut()) {
            s.min_altitude = min(s.min_altitude, a.h);
        }
        Ok(Flight {
            st,
            pitch: plant.pitch_v(&st.eta),
            rise: st.depth.diff(st.depth_prev),
            budget: if max_steps.is_finite() {
                max_steps as u32
            } else {
                u32::MAX
            },
            cursor,
            cur,
            track: first,
            track_end,
            x_end,
        })
    }

    /// Whether `start` can start a run on track `first`: finite, and at
    /// `X_first <= x < X_first+1`.
    ///
    /// # Errors
    /// [`SimError::TrackRange`], [`SimError::NonFiniteState`] or
    /// [`SimError::StateOffTrack`].
    pub(crate) fn check_start(
        &self,
        start: &VehicleState<N>,
        first: usize,
    ) -> Result<(), SimError> {
        let wp = self.waypoints.positions();
        let x_begin = *wp.get(first).ok_or(SimError::TrackRange)?;
        let x_next = *wp
            .get(first.saturating_add(1))
            .ok_or(SimError::TrackRange)?;
        if !start.is_finite() {
            return Err(SimError::NonFiniteState);
        }
        if !(start.x.minus(x_begin) >= 0.0 && start.x.minus(x_next) < 0.0) {
            return Err(SimError::StateOffTrack);
        }
        Ok(())
    }

    /// One step of the loop (contract §7, steps 2–5) from the flight's
    /// state, on reference `r` of its active track: the cascade, the plant,
    /// the kinematics. Moves the state, pitch and rise to sample `k + 1`,
    /// hands sample `k` to `observe` and the linearization to `sens`;
    /// returns the increments `(Δx, Δd)`, m.
    #[inline(always)]
    fn advance<Sn: Sensitivity<N>, F: FnMut(&Sample)>(
        &self,
        at: (&mut VehicleState<N>, &mut f32, &mut f32),
        ref_track_slot: (f32, usize, usize),
        sens: &mut Sn,
        observe: &mut F,
    ) -> Result<(f32, f32), SimError> {
        let (dx, dd, lin) = self.step_alone(at, ref_track_slot, None, observe)?;
        sens.step(self.vehicle, &lin);
        Ok((dx, dd))
    }

    /// [`Scenario::advance`] without handing the linearization on: it is
    /// returned with the increments, for the fast path to hand on with
    /// the step's piece. A steep step (`|θ̄| > 45°`) takes one off
    /// `steep_budget` where there is one (the fast path's: see
    /// `Flight::budget`), or fails with [`SimError::StepLimit`] where it is
    /// spent.
    #[inline(always)]
    pub(super) fn step_alone<F: FnMut(&Sample)>(
        &self,
        (st, pitch, rise): (&mut VehicleState<N>, &mut f32, &mut f32),
        (r, track, slot): (f32, usize, usize),
        steep_budget: Option<&mut u32>,
        observe: &mut F,
    ) -> Result<(f32, f32, StepLin), SimError> {
        let plant = self.vehicle.plant();
        // (The autopilot's `Ts`, the vehicle's as the plant's is, which the
        // integrators use too: one value in one register.)
        let ts = self.vehicle.autopilot().sample_time();
        let pitch_rate = plant.pitch_rate_v(&st.eta);
        let e_d = -st.depth.minus(r);
        // `d_k − d_{k−1}` is the last step's `Δd`: `depth` was `depth_prev`
        // plus it, exactly to the rounding of the compensation term.
        let depth_rate = *rise / ts;
        let command = self.vehicle.autopilot().cascade(
            &mut st.depth_integral,
            &mut st.pitch_integral,
            e_d,
            depth_rate,
            *pitch,
            pitch_rate,
        );
        observe(&Sample {
            x: st.x(),
            depth: st.depth(),
            pitch: *pitch,
            pitch_rate,
            reference: Some((track, r)),
            command: Some(command),
        });
        let eta = plant.step_v(&st.eta, command.elevator);
        let pitch_next = plant.pitch_v(&eta);
        let mean = (*pitch + pitch_next) * (0.5 * DEG) - self.kin.offset;
        // A cruising vehicle's mean pitch is within ±45°: the short
        // polynomials, whose results are finite with `cos > 0`. Beyond (or
        // NaN, from a diverging loop), the checked general case.
        // (`mean²`, which the polynomials need anyway, decides it: see
        // `SHORT_SQ`.)
        let (sin, cos) = if mean * mean <= crate::num::SHORT_SQ {
            crate::num::sin_cos_short(mean)
        } else {
            let abs = libm::fabsf(mean);
            if let Some(b) = steep_budget {
                *b = b.checked_sub(1).ok_or(SimError::StepLimit)?;
            }
            // Inline, not a call: a call in the loop would cost register
            // spills on every step.
            let (sin, cos) = crate::num::sin_cos_long(mean);
            // Beyond ±90° (or NaN) the vehicle flies backwards: the loop
            // has diverged. (NaN fails the compare too.)
            if !(abs <= core::f32::consts::FRAC_PI_2 && cos > 0.0) {
                return Err(SimError::Diverged);
            }
            (sin, cos)
        };
        // With `r`, `d` and `Δd` finite, `e_d` and so `I_d` are. In a world
        // the path is `θ̄ − α` and the water moves `w Ts` (nominal: 0, 0).
        let k = &self.kin;
        let dx = k.step * cos;
        let dd = -k.step * sin + k.sink;
        st.eta = eta;
        *pitch = pitch_next;
        st.depth_prev = st.depth;
        st.x_prev = st.x;
        st.depth = st.depth.add(dd);
        st.x = st.x.add(dx);
        *rise = dd;
        let lin = StepLin {
            slot,
            command,
            sin,
            cos,
            step: k.step,
        };
        Ok((dx, dd, lin))
    }
}

#[cfg(test)]
mod tests {
    //! The fast in-segment path against the general path, on random
    //! flights: the same flight bit for bit (the fast path only scores
    //! differently), the same minimum altitude, and `J` and the violation
    //! equal to their summation's rounding.
    use super::*;
    use crate::model::{Mission, Profile, TransferFunction, Vehicle, VehicleConfig, Waypoints};
    use crate::sim::rng::Lcg;

    /// The stuck-run budget (`Flight::budget`) counts the fast path's steep
    /// steps: a dive held at 80° to a reference far below, over a flat
    /// bottom (one segment: the fast path all the way), moves on 2.6 cm a
    /// step and runs out of its 4 steps per step-length of track; held at
    /// 40° it arrives.
    #[test]
    fn a_steep_dive_spends_the_budget_and_a_shallow_one_does_not() {
        let fly = |pitch_limit: f32| {
            let mut cfg = VehicleConfig::default();
            cfg.autopilot.pitch_limit = pitch_limit;
            let vehicle = Vehicle::new(&cfg, TransferFunction::C_AUV4).unwrap();
            let bottom = Profile::<2>::new(&[0.0, 400.0], &[9000.0, 9000.0]).unwrap();
            let wps = Waypoints::<2>::new(&[0.0, 200.0]).unwrap();
            let sc = Scenario::new(&vehicle, &bottom, &wps, Mission::default()).unwrap();
            let start = sc.start_state(50.0);
            let mut scores = [TrackScore::default(); 1];
            sc.simulate(&start, 0, &[8000.0], &mut scores, |_| {})
        };
        assert_eq!(fly(80.0).err(), Some(SimError::StepLimit));
        assert!(fly(40.0).is_ok());
    }

    #[test]
    fn fast_path_equals_general_path_on_random_flights() {
        let vehicle = Vehicle::c_auv4().unwrap();
        let mut rng = Lcg(20261201);
        let mut flown = 0;
        for case in 0..200 {
            let n = 8 + (rng.next() * 40.0) as usize;
            let mut x = [0.0_f32; 48];
            let mut b = [0.0_f32; 48];
            let mut depth = 200.0 + 800.0 * rng.next();
            for i in 0..n {
                x[i] = if i == 0 {
                    0.0
                } else {
                    x[i - 1] + 5.0 + 120.0 * rng.next()
                };
                depth += (rng.next() - 0.5) * 60.0;
                b[i] = depth.max(30.0);
            }
            let bottom = Profile::<48>::new(&x[..n], &b[..n]).unwrap();
            let len = x[n - 1];
            let m = 2 + (rng.next() * 3.0) as usize;
            let wx: [f32; 5] =
                core::array::from_fn(|i| 0.98 * len * (i.min(m) as f32) / (m as f32));
            let wps = Waypoints::<5>::new(&wx[..=m]).unwrap();
            let h_a = 5.0 + 40.0 * rng.next();
            let mission = Mission::new(h_a + 30.0 * rng.next(), h_a, [0.0, 6000.0]).unwrap();
            let sc = Scenario::new(&vehicle, &bottom, &wps, mission).unwrap();
            let start = sc.start_state(sc.default_initial_depth());
            let z: [f32; 4] =
                core::array::from_fn(|i| b[(i * n / 4).min(n - 1)] - 100.0 * rng.next());
            let (mut fast, mut general) = ([TrackScore::default(); 4], [TrackScore::default(); 4]);
            let zs = &z[..m];
            let a = sc.run::<_, _, true>(&start, 0, zs, &mut fast, &mut NoSensitivity, |_| {});
            let g = sc.run::<_, _, false>(&start, 0, zs, &mut general, &mut NoSensitivity, |_| {});
            let (a, g) = match (a, g) {
                (Ok(a), Ok(g)) => (a, g),
                (a, g) => {
                    assert_eq!(a.err(), g.err(), "case {case}");
                    continue;
                }
            };
            assert_eq!(a, g, "case {case}: end states differ");
            flown += 1;
            for (f, s) in fast.iter().zip(&general).take(m) {
                assert_eq!(f.min_altitude(), s.min_altitude(), "case {case}");
                let tol = |v: f32| 1e-5 * v.abs() + 1e-6;
                assert!(
                    (f.j() - s.j()).abs() <= tol(s.j()),
                    "case {case}: J {} vs {}",
                    f.j(),
                    s.j()
                );
                assert!(
                    (f.violation() - s.violation()).abs() <= tol(s.violation()),
                    "case {case}: violation {} vs {}",
                    f.violation(),
                    s.violation()
                );
            }
        }
        // Most random flights complete (a few dive into the rock and stop
        // with the same error both ways).
        assert!(flown >= 150, "{flown} flights completed");
    }
}
