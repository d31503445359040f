//! A cold horizon's first depth moved a stride along `J`'s descent, where
//! the SQP stopped at a corner of a later track's boundary.
//!
//! A track's least altitude is the least over its samples; where the
//! sample that sets it changes, the boundary of the safe set turns a
//! corner. On `check_planner.py --seed 2403 --vehicle
//! tools/reference/vehicles/low.toml` (`unseen_2403_5`, `h_r` 40 m,
//! `h_a` 28 m) the cold SQP ended with track 1 free (its least altitude
//! 40 m, 12 m above its target) and track 2 on its boundary, set by its
//! own depth, 915.1 m. Along that boundary the line's `J` falls as track 1
//! dives (−5.7e4 m³ per metre of `z_1`), but past `z_1` = 704.2 m another
//! sample of track 2 sets its least altitude, and the boundary's `z_2`
//! steps 7 m shallower: `J` along it rises 0.4 % before it falls again, by
//! 26 % to the best safe plan (747.5 m, 871.2 m). The SQP, whose row of
//! track 2 is the first sample's, converged at the corner: the line's `J`
//! was 1.35× the f64 search's best safe plan. Restarts from `z_1` moved
//! 2 and 4 m deeper slid back to the corner; from 8 m, the SQP found the
//! best plan (1.002×).
//!
//! The escape: where the cold call's end is feasible, its first track
//! flies more than [`FREE`] of the band above its target, and `z_1` moved
//! by the band `h_r − h_a` one way or the other (the other depths held,
//! one plain flight each) lowers the horizon's `J` by more than
//! [`PROMISE`] of it, the SQP restarts with `z_1` moved by the band that
//! way (then twice the band, [`STRIDES`] at most), kept if it ends
//! feasible with `J` lower by more than [`GAIN`]. Not under declared
//! uncertainty, as the other escapes.
//!
//! The promise was 10 % until `check_planner.py --seed 3249 --vehicle
//! tools/reference/vehicles/heavy.toml` (`unseen_3249_2`): the cold SQP
//! ended with track 1 at 660.3 m, where track 2's least altitude, set by
//! the arrival, dips 4 cm under its target for the next 19 m of `z_1`
//! and clears it again to 709 m, `J` falling 63e3 m³ a metre deeper; the
//! promise over the band was 9.4 % of the horizon's `J`, and the line
//! 1.301× the f64 search's best safe plan. At 5 % the stride runs; its
//! SQP from 680.3 m found tracks 1 and 2 at the best plan's depths, but
//! its first step had put tracks 3 and 4 on plateaus (dives at the pitch
//! limit the whole track, `∂J/∂z` exactly zero there) 8.6e6 m³ worse,
//! and it went back to its start. Where a stride's restart goes back so,
//! its end with those depths put back at the stride's start is restarted
//! too (`optim/sqp.rs`, `SqpEnd::plateaus`): 1.0014×.
//!
//! Measured on the 256 random lines of the earlier rounds, kept wherever
//! it ended lower: 21 lines moved, at 6.9 more evaluations a line. On 18
//! the restart gained under 0.1 % of the cold horizon's `J` (the same
//! basin converged again) and the line moved by as little; where it
//! gained 0.9 % and 1.2 % the line went −0.8 % (`unseen_5151_4`) and
//! +2.6 % (`unseen_1103_5`, a vehicle whose `J` has teeth: the committed
//! depth moved 1.3 m and the later calls found less); where it gained
//! 4.2 %, −4.0 % (`unseen_1102_1`). A corner's basin gains more than
//! [`GAIN`]; a nearer one is left to the later calls.
//!
//! The promise was `∂J/∂z_1` over the band, more than 5 % of the
//! horizon's `J`, and the gain 2 %, until `check_planner.py --seed 3345`
//! (`unseen_3345_7`, default vehicle): the SQP stopped with track 1
//! 12.9 m above its target, where the line's `J` falls 4.2e3 m³ per
//! metre of `z_1` but has teeth (track 4's `J` moves about 1e3 m³
//! between depths half a metre apart, round 37's teeth): the tangent
//! read −961 m³/m, the line search found no decrease, and the promise
//! was 0.5 %. The f64 search's
//! best safe plan flies track 1 on its boundary, 12.9 m deeper, and
//! track 2 8 m shallower: the line was 1.0178×. On `--seed 3300
//! --vehicle tools/reference/vehicles/slow.toml` (`unseen_3300_0`) the
//! tangent had the wrong sign (+8.8e3 m³/m against a trend of −1.7e3).
//! The promise is now measured (two plain flights, the band each way)
//! and the thresholds 1 %: 1.0027× and 1.068× → 1.051×. On the 304
//! random lines one moves (`unseen_5028_3` −1.5 %), +1.23 % flights;
//! with a gain of 0.5 % `unseen_5036_6` went +0.51 % (its later calls
//! found less), as `unseen_1103_5` above.

use crate::num::{max, min};
use crate::optim::{Bounds, First};

use super::Planner;
use super::objective::PlanObjective;
use super::scan::with_depth;
use super::solve::horizon_flight;

/// The share of the band `h_r − h_a` by which the first track must fly
/// above its target.
const FREE: f32 = 0.1;

/// The share of the horizon's `J` by which a plain flight with `z_1`
/// moved by the band must be lower to promise a stride (module docs).
const PROMISE: f32 = 0.01;

/// Strides tried: the band, then twice it.
const STRIDES: u32 = 2;

/// The share of the horizon's `J` a restart must gain to be kept (module
/// docs).
const GAIN: f32 = 0.01;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The escape of the module docs from the SQP's end in `self.work`, a
    /// cold call's horizon of `h` tracks in `bounds`, feasible within
    /// `tol` (m), after `iterations` so far; returns the iterations so far
    /// (a kept restart's). One plain flight to check the first track,
    /// two for the promise, then at most [`STRIDES`] SQP restarts (each
    /// with a second from its end off the plateaus, where it went back:
    /// module docs): the first that ends lower ends the search, kept only
    /// if it gains more than [`GAIN`] (a nearer basin found by the band's
    /// stride is not looked past). Not inlined: its state stays off the
    /// SQP runs' stack.
    #[inline(never)]
    pub(super) fn stride_first(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        iterations: u32,
    ) -> u32 {
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        let w = &self.work;
        let Some(First { z: z1, lo, hi, .. }) = w.first_in(bounds) else {
            return iterations;
        };
        if h < 2 || obj.declared() || obj.last_violation > tol {
            return iterations;
        }
        let free = obj.flight(&w.z).is_ok_and(|s| {
            s.first()
                .is_some_and(|t| t.min_altitude() > obj.target_of(0) + FREE * band)
        });
        if !free {
            return iterations;
        }
        let Some(dir) = self.promise(obj, (z1, lo, hi), band) else {
            return iterations;
        };
        let mut stride = band;
        for _ in 0..STRIDES {
            let z = first_moved(&self.work.z, (z1, lo, hi), dir * stride);
            let (kept, kept_v) = (self.work.mark(), obj.last_violation);
            let start = (tol, 0.0, false);
            self.restart_plateaus = None;
            let mut run = self.sqp_restart(obj, &z, (h, bounds), start, iterations);
            if let Some(flat) = self
                .restart_plateaus
                .take()
                .map(|end| off_plateaus(&z, end))
            {
                let so_far = run.unwrap_or(iterations);
                let again = self.sqp_restart(obj, &flat, (h, bounds), start, so_far);
                run = again.or(run);
            }
            if let Some(it) = run {
                if self.work.j < (1.0 - GAIN) * kept.j {
                    return it;
                }
                obj.last_violation = kept_v;
                self.work.restore(&kept);
                return iterations;
            }
            stride *= 2.0;
        }
        iterations
    }

    /// The stride's direction (+1 deeper, −1 shallower): the side of the
    /// SQP's end, `z_1` moved by the band within `[lo, hi]` (m) and the
    /// other depths held, whose horizon `J` is the lower, where it is
    /// below the end's by more than [`PROMISE`] of it (two plain flights;
    /// module docs).
    fn promise(
        &self,
        obj: &mut PlanObjective<'_, N>,
        (z1, lo, hi): (f32, f32, f32),
        band: f32,
    ) -> Option<f32> {
        let mut side = |d: f32| {
            let z = first_moved(&self.work.z, (z1, lo, hi), d * band);
            horizon_flight(obj, &z).map_or(f32::INFINITY, |(j, _, _)| j)
        };
        let (deeper, shallower) = (side(1.0), side(-1.0));
        let (dir, j) = if deeper <= shallower {
            (1.0, deeper)
        } else {
            (-1.0, shallower)
        };
        (j < (1.0 - PROMISE) * self.work.j).then_some(dir)
    }
}

/// `z` with its first depth `z1` moved `by` (m) within `[lo, hi]`: a
/// stride's start, or the promise's side.
fn first_moved<const K: usize>(z: &[f32; K], (z1, lo, hi): (f32, f32, f32), by: f32) -> [f32; K] {
    with_depth(z, 0, max(min(z1 + by, hi), lo))
}

/// A restart's end `left` with the depths in `bits` (its plateaus) put
/// back at its start `z`.
fn off_plateaus<const K: usize>(z: &[f32; K], (left, bits): ([f32; K], u32)) -> [f32; K] {
    let mut out = left;
    for (j, (o, &s)) in out.iter_mut().zip(z).enumerate() {
        let bit = u32::try_from(j).ok().and_then(|j| 1_u32.checked_shl(j));
        if bit.is_some_and(|b| bits & b != 0) {
            *o = s;
        }
    }
    out
}
