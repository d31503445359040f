//! A single track's plateau (model contract §10): where the pitch reference
//! stays saturated over the whole track, the track's depth moves nothing,
//! `J` is flat and its gradient exactly zero, and the optimizer stops
//! there although a better depth may lie past the plateau's edge (a
//! vehicle climbing at full pitch to a rising bottom: every shallower
//! depth flies the same). The edge is found by stepping out of the
//! plateau (steps doubling from 1/64 of the box) and a few halvings; the
//! optimizer restarts from the first depth past it, on each side (past a
//! ridge, where `J` first rises off the plateau, from a point further out
//! below the plateau if [`RIDGE_STEPS`] steps find one; past an edge
//! where `J` falls by no more than the optimizer's stopping threshold,
//! from a point further out where it has fallen by more, if as many
//! steps find one: on `check_planner.py --seed 2544`, `unseen_2544_2`
//! track 4, unconstrained, the restart from the edge (11 m³ below the
//! plateau, the threshold 93 m³) stopped at once, 1.007× the f64 best
//! `J`, now 1.000×; on 267 random lines track by track, 37 lines move
//! unconstrained and 9 constrained, the first track moved never more
//! than 4e-5 higher, none in horizon mode), and its
//! answer is kept if it ends lower; a constrained track's, ended past the
//! safe set, keeps the boundary between the edge and its end if that is
//! lower ([`Planner::boundary_off_plateau`]). (A horizon scans its flat
//! coordinates instead, `solve.rs`.)

use crate::num::{max, min};
use crate::optim::{Bounds, First};

use super::fallback::boundary;
use super::flights::Flights;
use super::objective::PlanObjective;
use super::scan::ScanLog;
use super::solve::Merge;
use super::{Method, PlanError, Planner};

/// The outward search's first step, of the box.
const FIRST_STEP_SHARE: f32 = 1.0 / 64.0;

/// Steps past an edge where `J` rises (a ridge), the first of
/// [`FIRST_STEP_SHARE`] of the box, doubling. On a random line on the
/// `second` vehicle (`check_planner.py --seed 2006`, `unseen_2006_6`)
/// track 1's dive is flat deeper than about 1 210 m, `J` rises off the
/// plateau's edge to a ridge and falls past it to the optimum, 1 140 m:
/// the restart from the edge slid back onto the plateau, 1.11× the best
/// `J`. The third step found the basin (1.0000×); measured on 256 random
/// lines, the probes cost 3 flights a line track by track, 0.5 in
/// horizon mode.
const RIDGE_STEPS: u32 = 3;

/// Halvings of the bracket around the edge (the restart needs a depth
/// past the edge, not the edge itself).
const HALVINGS: u32 = 4;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The single track's plateau escape (module docs), after the
    /// optimizer: from a plateau (gradient exactly zero), a restart from
    /// each of its edges within the box. Returns the iterations so far (a
    /// restart counts one more). Not inlined: its state stays off the
    /// horizon path's stack.
    #[inline(never)]
    pub(super) fn escape_plateau_single(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        first_step: f32,
        mut iterations: u32,
    ) -> Result<u32, PlanError> {
        let w = &self.work;
        let Some(First { z, g, lo, hi }) = w.first_in(bounds) else {
            return Ok(iterations);
        };
        if g != 0.0 || lo >= hi {
            return Ok(iterations);
        }
        let (flat, mut start) = (w.j, w.z);
        let (cap, thr) = (
            self.cfg.bfgs.max_iterations,
            self.cfg.bfgs.tol.j_threshold(flat),
        );
        for dir in [1.0_f32, -1.0] {
            let Some(edge) = plateau_edge(obj, (lo, hi), (z, flat, thr), dir, &mut start) else {
                continue;
            };
            let budget = cap.saturating_sub(iterations).saturating_sub(1);
            if budget == 0 {
                break;
            }
            if let Some(s) = start.first_mut() {
                *s = edge;
            }
            if let Some(taken) =
                self.restart_off_plateau(obj, &start, bounds, (first_step, budget))?
            {
                iterations = iterations.saturating_add(taken).saturating_add(1);
            }
        }
        Ok(iterations)
    }

    /// A single track's restart from its best scanned depth, where the
    /// optimizer ended above it by more than the stopping threshold (a
    /// guarded run: the best scanned depth that flies safe); under BFGS
    /// (the paper's gradient descent keeps its start). The scan
    /// starts the optimizer from its parabola's vertex, which can lie on
    /// a plateau next to a narrow basin: on `check_planner.py --seed 2402
    /// --vehicle tools/reference/vehicles/rate.toml`, `unseen_2402_1`
    /// track 4 (unconstrained), the scan's best, 1 256.6 m, sat in a
    /// basin 30 m wide, 0.7 % below a plateau; the vertex, 1 227 m, on
    /// the plateau, where `J`'s gradient (−0.11 m², not exactly zero)
    /// stopped BFGS at once. Returns the iterations so far (a restart
    /// counts one more). Not inlined: its state stays off the horizon
    /// path's stack.
    #[inline(never)]
    pub(super) fn restart_from_scanned(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        (scan, first_step): (&ScanLog, f32),
        iterations: u32,
    ) -> Result<u32, PlanError> {
        let j = self.work.j;
        let bar = j - self.cfg.bfgs.tol.j_threshold(j);
        let guard = obj.guard;
        let best = scan
            .entries()
            .filter(|e| e.1 < bar && guard.is_none_or(|h| e.2 >= h))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let budget = self
            .cfg
            .bfgs
            .max_iterations
            .saturating_sub(iterations)
            .saturating_sub(1);
        let bfgs = self.cfg.method == Method::Bfgs;
        let Some((z, _, _)) = best.filter(|_| h == 1 && bfgs && budget > 0) else {
            return Ok(iterations);
        };
        let mut start = self.work.z;
        if let Some(s) = start.first_mut() {
            *s = z;
        }
        let taken = self.restart_off_plateau(obj, &start, bounds, (first_step, budget))?;
        Ok(taken.map_or(iterations, |t| {
            iterations.saturating_add(t).saturating_add(1)
        }))
    }

    /// The optimizer restarted from `start`, kept if it ends lower. A
    /// guarded run (the constrained single track, whose objective is `J`
    /// alone) restarts unguarded, so that a trial step past the safe set
    /// does not end it (its first run's boundary search would take such a
    /// step for an optimum beyond the boundary), and keeps its end only if
    /// that is safe. Returns the iterations when kept.
    fn restart_off_plateau(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        start: &[f32; K],
        bounds: &Bounds<K>,
        run: (f32, u32),
    ) -> Result<Option<u32>, PlanError> {
        let (kept, flat) = (self.work.mark(), self.work.j);
        let guard = obj.guard.take();
        let zero = [0.0; K];
        let taken = self.optimize_onto(obj, start, bounds, run, &zero, Merge::IfBetter);
        obj.guard = guard;
        let Some(taken) = taken? else {
            return Ok(None);
        };
        let Some(h_safe) = guard else {
            return Ok(Some(taken));
        };
        let end = self.work.z;
        let safe = obj
            .flight(&end)
            .ok()
            .and_then(|s| s.first().map(|s| s.min_altitude() >= h_safe));
        let edge = start.first().copied().unwrap_or(0.0);
        let past = end.first().copied().unwrap_or(edge);
        if safe == Some(true)
            || self.boundary_off_plateau(obj, bounds, (edge, past), (flat, h_safe))
        {
            return Ok(Some(taken));
        }
        self.work.restore(&kept);
        Ok(None)
    }

    /// A guarded restart from the plateau's edge `edge` that ended past
    /// the safe set at `past` (m): the safe-set boundary between them,
    /// kept where its `J` is below the plateau's `flat` (m³), then the
    /// polish's search from it (`polish.rs`; the run may have overshot an
    /// interior optimum, as on a sawtooth). On `check_planner.py --seed
    /// 2002 --vehicle tools/reference/vehicles/integ.toml`,
    /// `unseen_2002_7` track 3, constrained, the restart ended 12 m past
    /// the boundary in a tooth and the track stayed on its climb's
    /// plateau: 1.020× the best safe `J`. Whether it found one (the
    /// workspace then there). Not inlined: its flights stay off the
    /// restart's frame.
    #[inline(never)]
    fn boundary_off_plateau(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        (edge, past): (f32, f32),
        (flat, h_safe): (f32, f32),
    ) -> bool {
        let mut fl = Flights {
            sc: obj.sc,
            state: obj.start,
            track: obj.track,
            count: 0,
            limit: obj.budget.saturating_sub(obj.evaluations),
        };
        let steps = self.cfg.bisection_steps;
        let b = boundary(&mut fl, (edge, None), (past, None), h_safe, steps);
        obj.evaluations = obj.evaluations.saturating_add(fl.count);
        let Some(at) = b.ok().map(|b| b.at) else {
            return false;
        };
        let j = at.score.j();
        if !(j < flat && at.score.min_altitude() >= h_safe) {
            return false;
        }
        if !self.polish_boundary(obj, bounds, (at.depth, j)) {
            // (At the boundary: its value ends the history.)
            let _ = self.work.history.push(j);
        }
        true
    }
}

/// The first depth found past the edge of the plateau at `z` (its value
/// `flat`) in direction `dir` (±1) within `[lo, hi]`, or `None` if the
/// plateau reaches the box's end (or a flight fails). Where `J` falls off
/// the edge by no more than the optimizer's stopping threshold `thr`
/// (m³), a point further out where it has (module docs). `probe` is the
/// point flown (its first entry is set).
fn plateau_edge<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    (lo, hi): (f32, f32),
    (z, flat, thr): (f32, f32, f32),
    dir: f32,
    probe: &mut [f32; K],
) -> Option<f32> {
    let mut value_at = |t: f32| {
        if let Some(s) = probe.first_mut() {
            *s = t;
        }
        obj.flight_value(probe).ok()
    };
    let is_flat = |v: f32| libm::fabsf(v - flat) <= 1e-6 * libm::fabsf(flat);
    let (mut inside, mut step) = (z, FIRST_STEP_SHARE * (hi - lo));
    let (mut out, mut above, mut v_out) = loop {
        // (Not `f32::clamp`, which asserts its bounds' order.)
        let t = min(max(inside + dir * step, lo), hi);
        if t.to_bits() == inside.to_bits() {
            return None;
        }
        let v = value_at(t)?;
        if is_flat(v) {
            inside = t;
            step *= 2.0;
        } else {
            break (t, v > flat, v);
        }
    };
    for _ in 0..HALVINGS {
        let mid = 0.5 * (inside + out);
        let v = value_at(mid)?;
        if is_flat(v) {
            inside = mid;
        } else {
            (out, above, v_out) = (mid, v > flat, v);
        }
    }
    // Past an edge where `J` rises first (a ridge), a few steps further
    // out for a point below the plateau: the restart from the ridge would
    // slide back onto the plateau. Past one where it falls by no more than
    // the threshold, for a point below by more: the restart from there
    // would stop at once.
    let gentle = !above && flat - v_out <= thr;
    let below = |v: f32| if above { v < flat } else { v < flat - thr };
    let mut step = FIRST_STEP_SHARE * (hi - lo);
    for _ in 0..RIDGE_STEPS {
        if !(above || gentle) {
            break;
        }
        let t = min(max(out + dir * step, lo), hi);
        // (A failed probe keeps the edge found.)
        match value_at(t) {
            Some(v) if below(v) => return Some(t),
            Some(_) => step *= 2.0,
            None => break,
        }
    }
    Some(out)
}
