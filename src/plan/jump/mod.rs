//! The SQP's plateau escape, one coordinate: a depth whose `∂J/∂z_j` is
//! exactly zero (the pitch reference saturated over the whole track) is
//! scanned over its reach, the others held, for a point to restart the
//! SQP from (`solve.rs` restarts from the best over the plateaus).
//!
//! A plateau's edge can hide a narrow feasible window: on a random canyon
//! line (`check_planner.py --seed 5151`, `unseen_5151_1`) track 1's
//! saturated climb is flat for `z_1` up to about 130 m, then its `J` and
//! track 2's fall until a cliff near 200 m where track 1's least
//! altitude drops from 61 m to 27 m. The 9-point scan (every 97 m) read
//! 126.9 m flat and 223.5 m infeasible, and the call committed 30.2 m:
//! the line's `J` 1.074× the best safe plan's (180.8 m). Where the scan
//! passes from a point within the band to one beyond it whose `J` is
//! lower, the pair is bisected [`EDGE`] times (one flight of the tail
//! each) for the feasible point nearest the cliff.
//!
//! The window can lie between the plateau and a scanned point beyond the
//! band whose `J` is higher: on `make_lines.py`'s `unseen_5007_6` (seed
//! 5007, `fast`) track 2's climb is saturated for `z_2` shallower than
//! about 410 m, where the SQP stopped (342.7 m); the scan read 402 m flat
//! and 538 m 141 m short at a higher `J`, past a window near 445 m where
//! both `J` and track 3's are lower and every track clears. The line's
//! `J` was 1.109× the f64 best safe plan's. Where the scan keeps no
//! point, and no step leaves the plateau within the band, its first step
//! off the plateau to beyond the band is bisected [`EDGE`] times for the
//! first point off it within the band (`bisect_steps`): 0.986×. Not in
//! the held edges' pass, after the plateau rounds. On the 304 random
//! lines 5 move (`unseen_5034_0` 0.990×; one higher, by 2e-5), +0.5
//! flights a line; the 18 shared runs keep their plans and flights.
//!
//! The window can lie between the plateau and a scanned point within the
//! band, short of its targets, whose `J` is lower: on `check_planner.py
//! --seed 3113 --vehicle tools/reference/vehicles/twoki.toml`
//! (`unseen_3113_7`) track 1 dived saturated for `z_1` shallower than
//! about 155 m, where the SQP stopped (138.2 m); the scan read 223.4 m
//! 13 m short (the band is 15 m) at a `J` 57 000 m³ lower, priced out by
//! its shortfall, and track 1 is held by no earlier depth, so no held
//! edge was sought (below). Near 190–200 m every track clears and `J` is
//! lower; the line's `J` was 1.049× the f64 best safe plan's. Where the
//! scan keeps no point and no held edge is found, its first such step
//! (`Steps::dip`) is bisected [`EDGE`] times towards the dip for the
//! start of least score (`bisect_dip`): 1.0015×. Not in the held edges'
//! pass. On the 304 random lines one moves (`unseen_5024_1`, 0.13 %
//! lower), 0.2 flights a line more; the 18 shared runs keep their plans,
//! Monterey 1's cold call flies 3 more (a dip whose bisection keeps no
//! point).
//!
//! From an infeasible optimum, the scan weighs the points less infeasible
//! than it by `J` plus their shortfall priced at [`RESTORE_SHARE`] of the
//! merit weight, as it weighs a feasible optimum's. It took the point of
//! least shortfall before: on a random line on the `rate` vehicle
//! (`check_planner.py --seed 1705`, `unseen_1705_2`) the cold SQP ended
//! 59.7 m short, and the scan of track 1's saturated climb kept its
//! shallowest point (655.5 m, 0.58 m short, the line's `J` 9.9e7 m³) over
//! 1 111.9 m (0.69 m short, 3.6e7 m³); on the plateau no gradient moved
//! it back, and the line ended 4.43× the best safe plan: now 1.003×.
//!
//! Where the scan finds no lower point and track `j` is held at its
//! target by the depths before it, the restart starts just off the
//! plateau's edge instead ([`Planner::held_edge`]'s docs). A later track
//! held through the plateau may be freed only a hair just off its edge
//! and by metres further off: on `check_planner.py --seed 1801`
//! (`unseen_1801_2`, default vehicle) track 2's depth sat on a saturated
//! dive's plateau and track 3's least altitude at its target, held by
//! track 1's depth; just off the edge (941.9 m) track 3 was freed by
//! 4.5 cm, under the slack, 20 m further off by 5 m. The best safe plan
//! flies track 1 46 m deeper and track 2 77 m shallower, past a middle
//! where the straight path is infeasible (track 3 down to 42 m): no
//! local step gets there, and the line's `J` was 1.51× the f64 best.
//! The edge now steps further off, by the band and doubling
//! ([`FREE_STEPS`] tail flights at most), until the held track is freed
//! (then on while it is freed more: below): 1.0027×; `unseen_1706_7`
//! (`second`, the same shape) 3.22× → 1.0025×.
//! Where no step frees it, the point just off the edge is still a start
//! if it is as feasible as the plateau: on `check_planner.py --seed 2005
//! --vehicle tools/reference/vehicles/rate.toml` (`unseen_2005_5`) `z_3`
//! shallower off its plateau lowers track 4, held by `z_2`, but there the
//! linearization sees `z_3` take over holding track 4, and `z_2` moves
//! 87 m deeper: 3.40× → 1.0002×. (Off Monterey 1's plateau the point is
//! 5 m short: no restart.)
//!
//! The window off the edge that frees a later track can be narrower than
//! the scan's step, and the track freed most a little further off than
//! its first freed point: on `check_planner.py --seed 3331 --vehicle
//! tools/reference/vehicles/fast.toml` (`unseen_3331_5`) track 1's dive
//! is saturated for `z_1` shallower than about 855 m, where the SQP
//! stopped (712 m), with track 2 held at its minimum altitude; between
//! 855 and 870 m `z_1` lifts track 2's least altitude by up to 0.7 m,
//! and track 2 can fly 1.8 m deeper. The 9-point scan stepped from the
//! plateau (849 m) to a cliff (987 m), so no step off the plateau was
//! within the band and no held edge was sought: the line 1.018× the f64
//! best safe plan. The cliff's bisection's step off the plateau to
//! within the band now serves as the held edge's step, and of the steps
//! further off (the band, doubling) the edge's start is the one that
//! frees the held track most, stepping on while each frees it more than
//! the last: track 2 freed by 0.13 m just off the edge (858 m), by
//! 0.67 m 8 m further; 1.0027×. On the 304 random lines 9 lower
//! (`unseen_5001_7` −4.7 %, `unseen_5004_2` −1.4 %, `unseen_5012_2`
//! −1.1 %, `unseen_5018_6` −0.49 %), 2 higher (by 0.054 % at most),
//! +0.98 % flights (the cliff's step alone: 6 lower, +0.82 %); track by
//! track and the 24 shared runs the same.

use crate::num::max;
use crate::optim::Bounds;
use crate::optim::constrained::group_bit;
use crate::sim::{TrackScore, VehicleState};

mod steps;

use steps::{EDGE, Point, Step, Steps, at_depth, bisect_dip, bisect_steps, flat, scan_steps};

use super::Planner;
use super::objective::PlanObjective;
use super::scan::{reach_from, with_depth};
use super::solve::{RESTORE_SHARE, lex_less};

/// Steps further off a plateau's edge (the band `h_r − h_a`, doubling)
/// that [`Planner::held_edge`] tries for a later track held just off it.
const FREE_STEPS: u32 = 3;

/// A merit weight (m³/m) that prices any shortfall out of a scan.
const PRICED_OUT: f32 = 1e30;

/// A restart candidate: its score (shortfall, `J`) and its depths.
type Jump<const K: usize> = ((f32, f32), [f32; K]);

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The best point of a scan of coordinate `j` when `∂J/∂z_j` is
    /// exactly zero (no gradient, of `J` or of the altitudes after it, can
    /// move it), the others held. From an infeasible optimum (shortfall
    /// `v` above `tol`, m), the point of least `v` if it is less; from a
    /// feasible one, the lowest `J` among the points whose `v` is within
    /// the mission's band `h_r − h_a` (m), if it beats the optimum's by
    /// more than the stopping threshold once its shortfall is priced at
    /// [`RESTORE_SHARE`] of the finished run's merit weight `ρ` (m³/m),
    /// the scan's edges bisected as in the module docs. The SQP restarted
    /// from it moves the other depths too (and is kept only if it ends
    /// better): a plateau left by one depth alone may need its neighbours
    /// to follow. Not inlined: the scan's state stays off the stack of
    /// the SQP runs.
    #[inline(never)]
    pub(super) fn sqp_plateau_jump(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        j: usize,
        (tol, rho, later): (f32, f32, bool),
    ) -> Option<Jump<K>> {
        let (&lo, &hi) = bounds.lo.get(j).zip(bounds.hi.get(j))?;
        let out = &self.work;
        if lo >= hi || out.gradient.get(j).is_none_or(|&g| g != 0.0) {
            return None;
        }
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        let v_now = obj.last_violation;
        let restoring = v_now > tol;
        let threshold = out.j - self.cfg.bfgs.tol.j_threshold(out.j);
        // The tracks before `j` fly the same whatever `z_j`: once.
        let (head, at_j) = obj.head(&out.z, j).ok()?;
        // Within the reach from where track `j` starts (beyond, the same
        // plateau).
        let t = obj.track.saturating_add(j);
        let (lo, hi) = reach_from(&obj.sc, t, at_j.depth(), (lo, hi));
        // Scores a point: restoring, the points less infeasible than the
        // optimum by `J` with their shortfall priced as below (the least
        // shortfall alone would take the worst of several feasible depths,
        // or a saturated climb's shallowest point: module docs).
        let price = RESTORE_SHARE * rho;
        let score = |(_, jz, v): Point| -> Option<((f32, f32), (f32, f32))> {
            if restoring {
                let merit = jz + price * max(v - tol, 0.0);
                (v < v_now - tol).then_some(((0.0, merit), (0.0, f32::INFINITY)))
            } else if v <= band && jz + price * v < threshold {
                Some(((0.0, jz), (0.0, threshold)))
            } else {
                None
            }
        };
        let mut best: Option<Jump<K>> = None;
        let mut keep = |p: Point| match score(p) {
            Some((s, bar)) if lex_less(s, best.as_ref().map_or(bar, |b| b.0)) => {
                best = Some((s, with_depth(&out.z, j, p.0)));
                true
            }
            _ => false,
        };
        let (flown, plateau) = ((&head, &at_j, j), (out.j, v_now + tol));
        let reach = (lo, hi, self.cfg.scan_points);
        let sides = (plateau, band, restoring);
        let (steps, kept) = scan_steps(obj, (flown, &out.z), reach, sides, &mut keep);
        // (The cliff and the dip are the plateau rounds': the held edges'
        // pass comes after them.)
        let Steps { held, edge, .. } = steps;
        let cliff = steps.cliff.filter(|_| !kept && !later && held.is_none());
        // (No scanned step off the plateau within the band: the cliff's
        // bisected one, module docs.)
        let held = held.or(bisect_steps(
            obj,
            (flown, &out.z),
            (edge, cliff),
            (band, plateau),
            &mut keep,
        ));
        let at = (out.z, out.j, v_now);
        if best.is_none() && !later {
            self.scanned.note(at, j, held);
        }
        let dip = steps.dip.filter(|_| !kept && !later);
        let found = best.or_else(|| self.held_edge(obj, flown, held?, (&at.0, tol, later)));
        // (A dip's point is a start where the scan would have kept it.)
        let start = |p: Point| {
            score(p)
                .filter(|&(s, bar)| lex_less(s, bar))
                .map(|(s, _)| s)
        };
        found.or_else(|| {
            let (s, p) = bisect_dip(obj, (flown, &at.0), (dip?, plateau), start)?;
            Some((s, with_depth(&at.0, j, p.0)))
        })
    }

    /// [`Planner::held_edge`] for the held edges' pass (`later`) from the
    /// step off the plateau of `z_j` that the plateau rounds' scan found
    /// at the workspace's point ([`Scanned`]), without scanning again.
    /// Not inlined: its flights' state is not on the pass's stack.
    #[inline(never)]
    fn held_edge_seen(
        &self,
        obj: &mut PlanObjective<'_, N>,
        j: usize,
        held: Option<Step>,
        tol: f32,
    ) -> Option<Jump<K>> {
        let z = self.work.z;
        let (head, at_j) = obj.head(&z, j).ok()?;
        self.held_edge(obj, (&head, &at_j, j), held?, (&z, tol, true))
    }

    /// A plateau of `z_j` on which track `j` is held at its target by the
    /// depths before it (its least altitude at the target, none of it
    /// `z_j`'s): the start at the plateau's edge. Nowhere on the plateau
    /// does the linearization see `z_j`, so no step trades it against an
    /// earlier depth; just off the edge it does. On a random canyon line
    /// on the `stiff` vehicle (`check_planner.py --seed 1205`,
    /// `unseen_1205_7`) track 4 dived saturated at 2 200 m, held at its
    /// target by track 3's depth (662 m); the best safe plan flies track 3
    /// at 719 m and track 4 at 861 m, out of the saturation. The step
    /// `(on, off)` of the scan is bisected [`EDGE`] times (one flight of
    /// the tail each), and the point off the plateau (within the band)
    /// returned, with its `J` as its score: the restart is kept only if it
    /// ends lower. A later track held (`later`) must be freed by more
    /// than the slack: the point there and the points further off (the
    /// band, doubling, [`FREE_STEPS`] times at most) are tried outwards
    /// while each frees it more than the last, and the one that frees it
    /// most is the start (module docs); not freed, the point just off the
    /// edge if it is as feasible as the plateau (within the slack). `None`
    /// when track `j` is not held, or the later track is neither freed nor
    /// the edge's point feasible.
    fn held_edge(
        &self,
        obj: &mut PlanObjective<'_, N>,
        flown: (&[TrackScore; K], &VehicleState<N>, usize),
        (mut on, mut off): (Point, Point),
        (z, tol, later): (&[f32; K], f32, bool),
    ) -> Option<Jump<K>> {
        let (_, at_j, j) = flown;
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        let slack = obj.held_slack(tol);
        let (g, least) = obj.held_from((at_j, j), z, slack).ok()??;
        if g != j && !later {
            return None;
        }
        let flat_j = on.1;
        for _ in 0..EDGE {
            let p = at_depth(obj, flown, 0.5 * (on.0 + off.0), z)?;
            if flat(p, (flat_j, on.2 + tol)) {
                on = p;
            } else if p.2 <= band {
                off = p;
            } else {
                break;
            }
        }
        if g == j {
            return Some(((0.0, off.1), with_depth(z, j, off.0)));
        }
        // A later track held must be freed off the plateau: else the
        // linearization there sees no trade either. Just off the edge it
        // may be freed by a hair; further off, by more (module docs).
        let away = if off.0 < on.0 { -band } else { band };
        // The step that frees it most: outwards while each step frees it
        // more than the last (module docs).
        let (mut step, mut most) = (0.0, None::<(f32, [f32; K])>);
        for _ in 0..=FREE_STEPS {
            let start = with_depth(z, j, off.0 + step);
            let freed = obj.least_at((at_j, j), &start, g).ok()?;
            if freed > least + slack && most.is_none_or(|(m, _)| freed > m) {
                most = Some((freed, start));
            } else if most.is_some() {
                break;
            }
            step = if step == 0.0 { away } else { 2.0 * step };
        }
        if let Some((_, start)) = most {
            return Some(((0.0, off.1), start));
        }
        // Not freed, but as feasible as the plateau (within the slack):
        // the linearization there sees `z_j`, which may take over holding
        // track `g` from the depths before it and let them move. Ranked
        // after any freed start (its score's first entry above 0).
        let unfreed = (f32::MIN_POSITIVE, off.1);
        (off.2 <= on.2 + slack).then_some((unfreed, with_depth(z, j, off.0)))
    }

    /// A cold horizon's last escape: [`Planner::held_edge`] for a track
    /// held after the plateau's own (`later`), from the best of every
    /// plateau's scan, the SQP restarted there and kept if it ends lower.
    /// Last, because a kept restart moves the point from which the other
    /// escapes start (`unseen_1404_5`: the lift found a lower `J` from
    /// where the plateau rounds left it, and none from the held edge's).
    /// On `unseen_1106_6` (`low`), track 3's depth on its plateau and
    /// track 4 held by track 2's: 1.24× → 1.0005×.
    ///
    /// The restart is then made again from the same start as a careful
    /// run (the rows beyond the band that its step would cross join the
    /// QP), kept if it ends lower still. On `check_planner.py --seed 2308
    /// --vehicle tools/reference/vehicles/low.toml` (`unseen_2308_0`) the
    /// start just off track 4's plateau left track 4 46 m above its target
    /// and track 3's rows flat in `z_3`: the plain run's first step took
    /// `z_3` 243 m deeper (`∂J/∂z_3` = −2.2e5 m², nothing in the band
    /// against it) into a flight 166 m short, and its end was not kept.
    /// The careful run's first step is 70 m, and it ends with track 3 70 m
    /// deeper and track 4 on its boundary: 1.63× → 1.0009× the f64 best
    /// safe plan. (Careful alone, it also took `unseen_1105_7` (`stiff`)
    /// from 1.0002× to 1.0052×; after the plain run, 3 of the 256 lines
    /// move, all lower, for 3.8 evaluations a line.)
    ///
    /// Where the plateau rounds scanned a plateau at this very point and
    /// kept nothing ([`Scanned`]), their step off it is taken without
    /// scanning again: the same flights would find the same step. On
    /// Monterey 1 the cold call's rounds and this pass both scanned track
    /// 3's plateau from the same point; now once: 164 → 155 flights, the
    /// same plan (246.8 → 227.0 M instructions on the M4F). On the 304
    /// random lines the same plans, 3.2 flights a line fewer.
    ///
    /// Where neither restart from the best start is kept, the next
    /// plateau's start is tried, best first, until one is. On
    /// `check_planner.py --seed 2578 --vehicle
    /// tools/reference/vehicles/slow.toml` (`unseen_2578_0`) tracks 4 and 5
    /// both dived on plateaus, track 5 held; the best start (track 5's
    /// edge) ended no lower, and the start off track 4's plateau was never
    /// tried: from it, track 4 flies 125 m shallower and track 3 54 m
    /// deeper, 2.17× → 1.0013× the f64 best safe plan. On 267 random lines
    /// 4 move, none higher, 1.7 flights a line more; the shared runs keep
    /// their plans and flights. Returns the iterations so far.
    #[inline(never)]
    pub(super) fn held_last(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        iterations: u32,
    ) -> u32 {
        if !self.feasible_with_room(obj, tol, iterations) {
            return iterations;
        }
        let mut starts: [Option<Jump<K>>; K] = [None; K];
        let at = (self.work.z, self.work.j, obj.last_violation);
        for (j, slot) in starts.iter_mut().enumerate().take(h) {
            // (Shortfall priced out: the rounds took the plateaus' lower
            // points already; this pass is for the held edges. Where the
            // rounds scanned this plateau at this point and kept nothing,
            // the scan would find what they found: not flown again.)
            *slot = match self.scanned.held_at(at, j) {
                Some(held) => self.held_edge_seen(obj, j, held, tol),
                None => self.sqp_plateau_jump(obj, bounds, j, (tol, PRICED_OUT, true)),
            };
        }
        // Best first (none last); the next only where no restart from one
        // was kept.
        let score = |s: &Option<Jump<K>>| s.map_or((f32::INFINITY, f32::INFINITY), |c| c.0);
        starts.sort_unstable_by(|a, b| {
            let (a, b) = (score(a), score(b));
            lex_less(b, a).cmp(&lex_less(a, b))
        });
        let mut iterations = iterations;
        for (_, z) in starts.iter().flatten() {
            let mut kept = false;
            for careful in [false, true] {
                if iterations >= self.cfg.bfgs.max_iterations {
                    return iterations;
                }
                if let Some(total) =
                    self.sqp_restart(obj, z, (h, bounds), (tol, 0.0, careful), iterations)
                {
                    (iterations, kept) = (total, true);
                }
            }
            if kept {
                break;
            }
        }
        iterations
    }
}

/// The plateau scans of the SQP's rounds that kept no point (module
/// docs of `solve`), for the held edges' pass ([`Planner::held_last`]):
/// the point they were made at (its depths, `J` and shortfall, bitwise),
/// the plateaus scanned there (bits) and each one's step off the plateau
/// within the band, if any. The pass's scan of such a plateau at the same
/// point flies the same depths, keeps no point either (it keeps fewer:
/// only feasible ones), and finds the same step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Scanned<const K: usize> {
    at: ([f32; K], f32, f32),
    bits: u32,
    held: [Option<Step>; K],
}

impl<const K: usize> Scanned<K> {
    /// Nothing scanned.
    pub(super) const NONE: Self = Self {
        at: ([0.0; K], f32::NAN, f32::NAN),
        bits: 0,
        held: [None; K],
    };

    /// Nothing scanned (the slots are kept; none is read before it is
    /// written again).
    pub(super) fn clear(&mut self) {
        self.bits = 0;
    }

    /// Plateau `j` scanned at `at` (depths, `J` m³, shortfall m), keeping
    /// no point, its step off the plateau `held`.
    fn note(&mut self, at: ([f32; K], f32, f32), j: usize, held: Option<Step>) {
        if !same(&self.at, &at) {
            self.bits = 0;
            self.at = at;
        }
        if let (Some(bit), Some(slot)) = (group_bit(j), self.held.get_mut(j)) {
            self.bits |= bit;
            *slot = held;
        }
    }

    /// Plateau `j`'s step where it was scanned at `at` keeping no point.
    fn held_at(&self, at: ([f32; K], f32, f32), j: usize) -> Option<Option<Step>> {
        let seen = group_bit(j).is_some_and(|bit| self.bits & bit != 0);
        (seen && same(&self.at, &at)).then(|| self.held.get(j).copied().flatten())
    }
}

/// Whether two points (depths, `J`, shortfall) are the same, bitwise.
fn same<const K: usize>(a: &([f32; K], f32, f32), b: &([f32; K], f32, f32)) -> bool {
    let bits = |p: &([f32; K], f32, f32)| (p.1.to_bits(), p.2.to_bits());
    bits(a) == bits(b)
        && a.0
            .iter()
            .zip(&b.0)
            .all(|(x, y)| x.to_bits() == y.to_bits())
}

#[cfg(test)]
mod tests {
    use super::*;

    const AT: ([f32; 2], f32, f32) = ([10.0, 20.0], 5.0e6, 0.0);
    const STEP: Step = ((10.0, 5.0e6, 0.0), (30.0, 4.9e6, 2.0));

    #[test]
    fn a_plateau_scanned_at_the_point_is_seen_there_only() {
        let mut s = Scanned::<2>::NONE;
        assert_eq!(s.held_at(AT, 1), None);
        s.note(AT, 1, Some(STEP));
        s.note(AT, 0, None);
        assert_eq!(s.held_at(AT, 1), Some(Some(STEP)));
        assert_eq!(s.held_at(AT, 0), Some(None));
        // Another point (a depth, J or shortfall a bit apart): not seen.
        let mut moved = AT;
        moved.0[0] = f32::from_bits(moved.0[0].to_bits() + 1);
        assert_eq!(s.held_at(moved, 1), None);
        assert_eq!(s.held_at((AT.0, AT.1, 1e-7), 1), None);
        // A scan at another point forgets the first point's.
        s.note(moved, 0, None);
        assert_eq!(s.held_at(AT, 1), None);
        assert_eq!(s.held_at(moved, 0), Some(None));
        s.clear();
        assert_eq!(s.held_at(moved, 0), None);
    }
}
