//! The simulation's fast path (see [`super::run`]): steps on one bottom
//! segment inside the active track, with the flight's state and the
//! track's running score in locals the compiler keeps in registers, each
//! new sample scored by one compare in the common case.

use crate::model::Cursor;
use crate::num::{max, min};

use super::lin::Sensitivity;
use super::run::Flight;
use super::score::{At, Geo, piece_within, shortfall, trapezoid};
use super::{Sample, Scenario, SimError, TrackScore, VehicleState};

/// Most steps of one run of the simulation's fast path (see `Scenario::fast_run`).
const FAST_RUN: f32 = 256.0;

/// The fast path's state from step to step (see `Scenario::fast_run`):
/// the flight's, in locals, and the track's running score.
struct FastRun<const N: usize> {
    st: VehicleState<N>,
    pitch: f32,
    rise: f32,
    budget: u32,
    /// The last sample; its `p` is `p0`.
    a0: At,
    /// The last sample's shortfall `p`, m: set where it is computed, and 0
    /// on every sample the common case passes (it is at or above `h_p`).
    p0: f32,
    /// The last sample's `e²`, m².
    e2: f32,
    /// No sample at or above it sets a new minimum or violates, m.
    guard: f32,
    acc: TrackScore,
    /// The run's plain sum of trapezoids (times 4), m³.
    j_run: f32,
}

/// What the fast path's steps share: the reference `r` (m), the active
/// track and its score slot, the bottom segment, where the fast path ends
/// (m), and `h_r`, `h_p` (m).
struct OnSegment {
    r: f32,
    track: usize,
    slot: usize,
    cursor: Cursor,
    fast_limit: f32,
    h_r: f32,
    h_p: f32,
}

impl<const N: usize> Scenario<'_, N> {
    /// The fast path: from a scored sample `a0` inside the track, as long
    /// as each new sample lands short of `fast_limit` it lies on the active
    /// track, before the line's end and on the bottom segment the cursor
    /// holds, and the segment it ends is scored wholly into this track,
    /// with its running score kept in registers. The limit is a few ulps
    /// and a millimetre short of the next event, so that its plain f32
    /// compare never decides a case the exact (compensated) tests would
    /// decide otherwise. Leaves `fl.cur` at the sample before the one that
    /// left the fast path, for the general path to score that step.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn fast_run<Sn: Sensitivity<N>, F: FnMut(&Sample)>(
        &self,
        fl: &mut Flight<N>,
        a0: At,
        r: f32,
        slot: usize,
        score: &mut TrackScore,
        sens: &mut Sn,
        observe: &mut F,
    ) -> Result<(), SimError> {
        let h_p = self.penalty_altitude;
        // A run is also cut after about `FAST_RUN` steps, so that its plain
        // partial sum of `J` (added to the track's compensated sum when the
        // run ends) adds up at most that many terms: relative error below
        // `FAST_RUN` ε/2.
        let horizon = fl.st.x.value() + FAST_RUN * self.kin.step;
        let event = min(min(fl.track_end, fl.cursor.end()), horizon);
        let on = OnSegment {
            r,
            track: fl.track,
            slot,
            cursor: fl.cursor,
            fast_limit: event - (1e-3 + 4.0 * f32::EPSILON * libm::fabsf(event)),
            h_r: self.mission.reference_altitude(),
            h_p,
        };
        // The flight's state in locals, for registers in the loop.
        let mut run = FastRun {
            st: fl.st,
            pitch: fl.pitch,
            rise: fl.rise,
            budget: fl.budget,
            a0,
            p0: a0.p,
            e2: a0.e * a0.e,
            guard: if a0.p > 0.0 {
                f32::INFINITY
            } else {
                max(score.min_altitude, h_p)
            },
            acc: *score,
            j_run: 0.0,
        };
        loop {
            if !self.fast_step(&mut run, &on, score, sens, observe)? {
                break;
            }
            // The plain flight takes two steps a pass: the state's old and
            // new values swap registers from one step to the next, instead
            // of being copied back (about 10 instructions a step on a
            // Cortex-M4F).
            if Sn::TWO_STEPS && !self.fast_step(&mut run, &on, score, sens, observe)? {
                break;
            }
        }
        run.acc.j.add(0.25 * run.j_run);
        *score = run.acc;
        (fl.st, fl.pitch, fl.rise, fl.budget) = (run.st, run.pitch, run.rise, run.budget);
        // The sample before the one that left the fast path (where that
        // was the first step, the sample `fl.cur` already held).
        fl.cur = Geo {
            x: fl.st.x_prev,
            d: fl.st.depth_prev,
            at: Some(At {
                p: run.p0,
                ..run.a0
            }),
            past: -1.0,
        };
        Ok(())
    }

    /// One step of the fast path (see [`Scenario::fast_run`]): `Ok(true)`
    /// where the new sample stays on it, scored; `Ok(false)` where it
    /// leaves it, for the general path to score.
    #[inline(always)]
    fn fast_step<Sn: Sensitivity<N>, F: FnMut(&Sample)>(
        &self,
        run: &mut FastRun<N>,
        on: &OnSegment,
        score: &mut TrackScore,
        sens: &mut Sn,
        observe: &mut F,
    ) -> Result<bool, SimError> {
        let at = (&mut run.st, &mut run.pitch, &mut run.rise);
        let steep = Some(&mut run.budget);
        let (dx, dd, lin) = match self.step_alone(at, (on.r, on.track, on.slot), steep, observe) {
            Ok(v) => v,
            Err(e) => {
                // The run is lost, but its score so far is kept.
                run.acc.j.add(0.25 * run.j_run);
                *score = run.acc;
                return Err(e);
            }
        };
        let st = &run.st;
        // (NaN leaves the fast path too.)
        if st.x.value().partial_cmp(&on.fast_limit) != Some(core::cmp::Ordering::Less) {
            // The general path scores this step.
            sens.step(self.vehicle, &lin);
            return Ok(false);
        }
        // Δx and Δd are the step's exact increments; the new sample is on
        // the cursor's segment: no lookup.
        let p1 = on.cursor.point(st.x);
        // `p` is computed only where the sample can matter (below): the
        // last sample's is `run.p0` (`run.a0.p` is not kept up).
        let mut a1 = At::clear(p1.altitude(st.depth), p1.slope, on.h_r);
        let e2_next = a1.e * a1.e;
        // (The trapezoid's ¼ is applied to the run's sum: a power of two,
        // so exactly the same.)
        run.j_run += trapezoid(dx, run.e2, e2_next);
        let p0 = run.p0;
        // One compare in the common case: a sample at or above `guard` sets
        // no new minimum and does not violate (its `p` is 0), and `guard`
        // is +inf after a violating sample, so that the violation's next
        // trapezoid is taken here too.
        if a1
            .h
            .partial_cmp(&run.guard)
            .is_none_or(|o| o == core::cmp::Ordering::Less)
        {
            a1.p = shortfall(a1.h, on.h_p);
            let acc = &mut run.acc;
            if p0 > 0.0 || a1.p > 0.0 {
                acc.violation
                    .add(0.25 * trapezoid(dx, p0 * p0, a1.p * a1.p));
            }
            // The segment's first sample was counted as the last one's end.
            acc.min_altitude = min(acc.min_altitude, a1.h);
            run.guard = if a1.p > 0.0 {
                f32::INFINITY
            } else {
                max(acc.min_altitude, on.h_p)
            };
            run.p0 = a1.p;
        }
        let a0 = At { p: p0, ..run.a0 };
        let ends = ((&a0, st.x_prev.value()), (&a1, st.x.value()));
        sens.step_piece(
            self.vehicle,
            &lin,
            on.slot,
            piece_within(dx, dd, ends.0, ends.1),
        );
        run.e2 = e2_next;
        run.a0 = a1;
        Ok(true)
    }
}
