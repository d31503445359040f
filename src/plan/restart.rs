//! The SQP restarted from another start ([`Planner::sqp_restart`]), kept
//! only where it ends better; a restart gone back to its start runs once
//! more from the edge between them (`edge.rs`), and one that ends a
//! little short of its targets once more from its end repaired
//! ([`repaired`], or across the tracks: [`repaired_short`]).

use crate::optim::sqp::{SqpEnd, sqp_into};
use crate::optim::{BfgsConfig, Bounds};
use crate::sim::TrackScore;

use super::Planner;
use super::objective::PlanObjective;
use super::scan::with_depth;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// Whether an escape that restarts from a feasible SQP end may run:
    /// the last point evaluated feasible within `tol` (m) and an iteration
    /// of the cap left after `iterations`.
    pub(super) fn feasible_with_room(
        &self,
        obj: &PlanObjective<'_, N>,
        tol: f32,
        iterations: u32,
    ) -> bool {
        obj.last_violation <= tol && iterations < self.cfg.bfgs.max_iterations
    }

    /// The SQP restarted from `z` with the merit weight `rho` (m³/m; 0:
    /// learnt afresh), `careful` of the rows beyond the band or not
    /// (`optim/sqp.rs`), kept if it ends better than the workspace's:
    /// feasible and lower, or, from an infeasible optimum, less
    /// infeasible. A restart gone back to its start from a lower `J` runs
    /// once more, careful, from the edge between them (`edge.rs`), kept
    /// on the same terms. A restart that ends lower than a feasible kept
    /// end but short of its targets runs once more too, from its end with
    /// each short track raised by its shortfall ([`repaired`]): on
    /// `check_planner.py --seed 2701 --vehicle
    /// tools/reference/vehicles/rate.toml` (`unseen_2701_2`) the held
    /// track's restart (`wider.rs`) ended at half the kept end's `J`,
    /// 0.19 m short summed, and was dropped: the line 2.07× the f64
    /// search's best safe plan; repaired, 1.005×. On 267 random lines one
    /// more plan moves (0.27 % lower), for 0.24 flights a line; the 18
    /// shared runs keep their plans and flights. Returns the iterations so
    /// far when kept.
    pub(super) fn sqp_restart(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        z: &[f32; K],
        (h, bounds): (usize, &Bounds<K>),
        (tol, rho, careful): (f32, f32, bool),
        iterations: u32,
    ) -> Option<u32> {
        let (mut from, mut careful, mut total) = (*z, careful, None::<u32>);
        for round in 0..2 {
            let kept = self.work.mark();
            let kept_v = obj.last_violation;
            let so_far = total.unwrap_or(iterations);
            // (The restart's start counts as an iteration of the cap: with
            // none left after it, no restart.)
            let max_iterations = self
                .cfg
                .bfgs
                .max_iterations
                .saturating_sub(so_far)
                .saturating_sub(1);
            if max_iterations == 0 {
                break;
            }
            let left = BfgsConfig {
                max_iterations,
                ..self.cfg.bfgs
            };
            // (A fresh metric, `sqp_into`'s Gauss–Newton one.)
            let restart = sqp_into(
                obj,
                (&from, rho, careful),
                (bounds, h),
                &left,
                tol,
                &mut self.work,
            );
            if round == 0 {
                self.restart_plateaus = restart.as_ref().ok().and_then(on_plateaus);
            }
            let acc = &mut self.work;
            let v = obj.last_violation;
            let lower = acc.j.partial_cmp(&kept.j) == Some(core::cmp::Ordering::Less);
            let better = restart.is_ok()
                && if kept_v > tol {
                    v < kept_v
                } else {
                    v <= tol && lower
                };
            // A restart that ends lower than a feasible kept end but short
            // of its targets: once more from its end repaired.
            let short = restart.is_ok() && kept_v <= tol && v > tol && lower && round == 0;
            // The next round's start: the edge from where the run went
            // back (before any restore), else the short end repaired.
            let next = restart
                .ok()
                .and_then(|end| end.left.filter(|_| end.lower))
                .filter(|_| round == 0)
                .and_then(|l| self.edge_toward(obj, &l, tol))
                .or_else(|| {
                    short
                        .then(|| repaired_short(obj, &self.work.z, bounds, tol))
                        .flatten()
                });
            if better {
                self.blended = restart.as_ref().map_or(0, |end| end.blended);
                total = Some(
                    so_far
                        .saturating_add(self.work.iterations)
                        .saturating_add(1),
                );
            } else {
                obj.last_violation = kept_v;
                self.work.restore(&kept);
            }
            let Some(start) = next else { break };
            (from, careful) = (start, true);
        }
        total
    }

    /// Where the depth loop integrates: the SQP once more from the best
    /// end so far, its constraint rows and its gradient of `J` secants
    /// ([`PlanObjective::secant_rows`]), kept if it ends better
    /// ([`Planner::sqp_restart`]). The tangent rows steer the SQP along
    /// the slopes between the integrator's switches; the secants see the
    /// trend across them. On the 112 random lines of the four vehicles
    /// whose depth loop integrates (`make_lines.py`), 31 lines end lower
    /// (to 0.878×), 11 higher by 0.11 % at most, for 25 flights a line
    /// (4 %); the other 192 lines and the 18 shared runs keep their plans.
    /// With the secant gradient of `J` too (round 40), against the
    /// tangent gradient: 28 lines lower (to −1.32 %), 23 higher (to
    /// +0.32 %: later calls from another committed depth), 1.7 flights a
    /// line more. Returns the iterations so far.
    pub(super) fn secant_restart(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        iterations: u32,
    ) -> u32 {
        if !obj.teeth() {
            return iterations;
        }
        let z = self.work.z;
        obj.secant = true;
        let kept = self.sqp_restart(obj, &z, (h, bounds), (tol, 0.0, false), iterations);
        obj.secant = false;
        kept.unwrap_or(iterations)
    }
}

/// Most flights of [`repaired`].
const REPAIRS: u32 = 4;

/// `z` with each track that falls short of its target raised by its
/// shortfall and `tol` (m), not above its box's `lo` (a track's least
/// altitude rises about a metre per metre it is raised, where its own
/// reference holds it), until the horizon's ℓ1 infeasibility is within
/// `tol`: the repaired depths, if found within [`REPAIRS`] plain flights
/// ([`Planner::sqp_restart`]). Not inlined: its flight's scores stay off
/// the restart's frame, which the SQP's sits on.
#[inline(never)]
pub(super) fn repaired<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    z: &[f32; K],
    bounds: &Bounds<K>,
    tol: f32,
) -> Option<[f32; K]> {
    let mut z = *z;
    for _ in 0..REPAIRS {
        let scores = obj.flight(&z).ok()?;
        let (_, v) = obj.value_of(&scores).ok()?;
        if v <= tol {
            return Some(z);
        }
        let tracks = z.iter_mut().zip(&bounds.lo).zip(&scores).take(obj.count);
        for (t, ((zt, lo), s)) in tracks.enumerate() {
            let short = obj.target_of(t) - s.min_altitude();
            if short > 0.0 {
                *zt = crate::num::max(*zt - short - tol, *lo);
            }
        }
    }
    None
}

/// The depth raised per look of [`repaired_across`], m: wider than the
/// teeth (a few centimetres) of a least altitude where the depth loop
/// integrates.
const ACROSS_STEP: f32 = 0.5;

/// The least rise of the short track's least altitude per metre an
/// earlier depth is raised (m/m) for [`repaired_across`] to move it.
const ACROSS_RATE: f32 = 0.5;

/// Where the depth loop integrates and [`repaired`] fails: the last
/// short track of `z` is held by an earlier depth, not its own. Its
/// tangent rows miss that: they are the slopes between the integrator's
/// switches, and the trend moves with the switches (`check_planner.py
/// --seed 2994 --vehicle tools/reference/vehicles/integ.toml`,
/// `unseen_2994_3`: the cold SQP ended 1.16 m short on track 5, whose
/// row read `∂h_5/∂z = (−0.82, −0.006, 0, 0, −0.60)`, where the f64
/// flights' secants over ±0.5 m read `(−0.02, −0.96, 0, 0, −0.04)`: track
/// 2's depth sets it). Each depth up to that track raised by
/// [`ACROSS_STEP`] (one plain flight each), the one whose raise lifts
/// the track's least altitude most, at [`ACROSS_RATE`] or more, is
/// raised by the shortfall and `tol` (m) over that rate, not above its
/// box's `lo`; then [`repaired`] from there. Not inlined, as
/// [`repaired`].
#[inline(never)]
pub(super) fn repaired_across<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    z: &[f32; K],
    bounds: &Bounds<K>,
    tol: f32,
) -> Option<[f32; K]> {
    let scores = obj.flight(z).ok()?;
    let short = short_track(obj, &scores, true)?;
    let lifted = lifted_across(obj, z, bounds, short, tol)?;
    repaired(obj, &lifted, bounds, tol)
}

/// A restart's end a little short of its targets, repaired
/// ([`Planner::sqp_restart`]): by [`repaired`], else, where the depth
/// loop integrates, track by track from the first short one, each raised
/// across ([`lifted_across`]) by the depth that lifts it most, for as
/// many rounds as the horizon has tracks (one plain flight a round and
/// one a depth looked at). On `check_planner.py --seed 3098 --vehicle
/// tools/reference/vehicles/twoki.toml` (`unseen_3098_7`) a lift's
/// restart ended at 7.906e6 m³, 4 cm short on tracks 4 and 5, against
/// the SQP's 8.27e6: track 4 was held by depth 3 and track 5 by depth 4,
/// so raising each short track's own depth ([`repaired`]) lifted
/// nothing, and the lift's end was dropped; the line ended 1.042× the
/// f64 best safe plan. Raised across, depth 3 by 5 cm and then depth 4 by
/// 11 cm, the end is feasible, and the restart from there ends at
/// 1.0025×.
#[inline(never)]
fn repaired_short<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    z: &[f32; K],
    bounds: &Bounds<K>,
    tol: f32,
) -> Option<[f32; K]> {
    if let Some(r) = repaired(obj, z, bounds, tol) {
        return Some(r);
    }
    if !obj.teeth() {
        return None;
    }
    let (mut z, rounds) = (*z, obj.count.min(K));
    for round in 0..=rounds {
        let scores = obj.flight(&z).ok()?;
        let (_, v) = obj.value_of(&scores).ok()?;
        if v <= tol {
            return Some(z);
        }
        if round == rounds {
            break;
        }
        let short = short_track(obj, &scores, false)?;
        z = lifted_across(obj, &z, bounds, short, tol)?;
    }
    None
}

/// The first track of the horizon flown with `scores` that falls short of
/// its target (`last`: the last), with its least altitude and shortfall
/// (m).
fn short_track<const N: usize, const K: usize>(
    obj: &PlanObjective<'_, N>,
    scores: &[TrackScore; K],
    last: bool,
) -> Option<(usize, f32, f32)> {
    let short_of = |t: usize| {
        let h = scores.get(t)?.min_altitude();
        let short = obj.target_of(t) - h;
        (short > 0.0).then_some((t, h, short))
    };
    let count = obj.count.min(K);
    if last {
        (0..count).rev().find_map(short_of)
    } else {
        (0..count).find_map(short_of)
    }
}

/// `z` with track `t`'s shortfall `short` (m; its least altitude `h`, m)
/// made up across: each depth up to `t` raised by [`ACROSS_STEP`] (one
/// plain flight each), the one whose raise lifts the track's least
/// altitude most, at [`ACROSS_RATE`] or more, raised by the shortfall and
/// `tol` (m) over that rate, not above its box's `lo`.
fn lifted_across<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    z: &[f32; K],
    bounds: &Bounds<K>,
    (t, h, short): (usize, f32, f32),
    tol: f32,
) -> Option<[f32; K]> {
    let mut best: Option<(usize, f32)> = None;
    for j in 0..=t {
        let up = *z.get(j)? - ACROSS_STEP;
        if up < *bounds.lo.get(j)? {
            continue;
        }
        let s = obj.flight(&with_depth(z, j, up)).ok()?;
        let rate = (s.get(t)?.min_altitude() - h) / ACROSS_STEP;
        if best.is_none_or(|(_, r)| rate > r) {
            best = Some((j, rate));
        }
    }
    let (j, rate) = best.filter(|&(_, r)| r >= ACROSS_RATE)?;
    let raised = crate::num::max(*z.get(j)? - (short + tol) / rate, *bounds.lo.get(j)?);
    Some(with_depth(z, j, raised))
}

/// Where an SQP run ended before it went back, with the depths it left
/// on plateaus there (bits), if it left any (`SqpEnd::plateaus`).
fn on_plateaus<const K: usize>(end: &SqpEnd<K>) -> Option<([f32; K], u32)> {
    end.left
        .filter(|_| end.plateaus != 0)
        .map(|l| (l, end.plateaus))
}
