//! A single track's optimum, and a horizon's first depth, where `J` has
//! small jumps.
//!
//! An autopilot whose depth loop integrates conditionally (contract §7,
//! with `ki > 0`) makes `J(z)` a sawtooth: each time the sample at which
//! the depth loop leaves saturation passes a sample, its integrator gains
//! or loses one step's increment and `J` jumps. On a random canyon line
//! (`check_planner.py --seed 51 --vehicle` with `depth_pid.ki = 0.02`) it
//! jumps +181 m³ every 6.5 cm of depth on a trend of +1 800 m³/m; between
//! jumps the exact gradient is the tooth's slope (−970 m³/m), and BFGS
//! ends inside a tooth, its `J` change below the stopping threshold while
//! the trend still falls: 7.5 m and 1.6 % short of the best `J`.
//!
//! The polish reads `J` on a scale the teeth do not matter: from the
//! optimizer's end, a step of [`STEP`] to each side (plain flights); if one
//! is lower by more than the stopping threshold, steps doubling that way
//! while `J` falls, then the vertex of the parabola through the last three
//! points. Where neither side is lower, a wider look at four steps
//! each side ([`LOOKS`]), doubling from there in the same way: on `check_planner.py
//! --seed 2402 --vehicle tools/reference/vehicles/rate.toml`,
//! `unseen_2402_0` track 4, unconstrained, a bump of the teeth 0.3 m wide
//! and 0.3 % high held BFGS and both half-metre sides above its end,
//! 1.75 m short of the basin (1.040× the best `J`, a small `J`); the
//! wider look, 1.001×. Where that too finds nothing, a widest look at
//! sixteen steps: on `check_planner.py --seed 2560 --vehicle
//! tools/reference/vehicles/rate.toml`, `unseen_2560_6` track 5,
//! unconstrained, BFGS ended in a dip of `J`'s wiggles with a bump 2.5 m
//! to its deeper side and the basin 5.4 m away (1.0052× the best `J`);
//! the widest look, 1.0006×. On 267 random lines the widest look costs
//! 4.2 flights a line track by track unconstrained, 1.0 constrained, 1.6
//! in horizon mode, and moves two lines, each lower (an unconstrained
//! line's `J` by 9 %, a horizon line's by 0.12 %). Between the wider and
//! the widest, a look at twice the wider's step: on `check_planner.py
//! --seed 2649 --vehicle tools/reference/vehicles/rate.toml`,
//! `unseen_2649_5` track 2, unconstrained, BFGS ended with a bump 2 m to
//! its deeper side and the basin 4.9 m away, past the 2 m look and short
//! of the 8 m one (1.0059× the best `J`); the 4 m look, 1.0012×. On the
//! 267 random lines that look costs about as much again (measured without
//! it: 4.2 flights a line track by track unconstrained, 1.0 constrained,
//! 1.6 in horizon mode), and moves two lines by 0.1 % of `J` at most (the
//! 18 shared runs keep their plans). A descent from the first look can
//! end in a dip beside the basin: from its end, the look at the wider
//! step and at twice it once more (the first that finds a lower point,
//! descended from as before). On `check_planner.py --seed 2807 --vehicle
//! tools/reference/vehicles/rate.toml`, `unseen_2807_3` track 4,
//! unconstrained, the half-metre look's descent ended at 1 078.67 m with
//! a bump 2.5 m deeper and the basin 5 m deeper (1.0055× the best `J`);
//! looked at again, 1.0036×. On the 267 random lines it moves no plan
//! track by track and two horizon plans (`unseen_3110_0` +0.14 %, the
//! other 1e-4 lower), for 2.7 flights a line track by track
//! unconstrained, 0.4 constrained and 0.3 in horizon mode; the 18 shared
//! runs keep their plans and flights. A descent from a wider look can
//! end at the parabola's vertex a step of the teeth off the basin: from
//! its end, the first look once more. On `check_planner.py --seed 2958
//! --vehicle tools/reference/vehicles/twoki.toml`, `unseen_2958_1`
//! track 1, unconstrained, the 2 m look's descent ended at 891.02 m, with
//! 890.52 m 1.1 % lower (1.0127× the best `J`); looked at closer,
//! 1.0002×. On 304 random lines on the ten vehicles of
//! `tools/reference/vehicles/` and the default it moves 4 lines track by
//! track unconstrained and one in horizon mode, all lower (to 0.997×),
//! for 0.1 flights a line at most; the 18 shared runs keep their plans
//! and flights. Between the first look and the wider, a look at twice
//! the first step: on `check_planner.py --seed 2985 --vehicle
//! tools/reference/vehicles/fast.toml`, `unseen_2985_6` track 3,
//! unconstrained, BFGS stalled in a valley with a bump 0.4 m deeper and
//! the basin 1.2 m deeper, every look at 0.5, 2, 4 and 8 m higher (1.009×
//! the best `J`); the 1 m look, 1.003×. On the 304 random lines it moves
//! 3 lines track by track unconstrained (all lower, to 0.996×), 2
//! constrained (one 4e-5 higher) and one in horizon mode (`unseen_5001_5`
//! 0.21 % higher, 1.0016× the f64 search's best safe plan), for 4.25,
//! 0.86 and 1.7 flights a line; the 18 shared runs keep their plans (2
//! flights more track by track on Monterey 1 and 3). On the 256 random lines of the
//! earlier rounds the first two looks cost 4.2 flights a line track by
//! track unconstrained, 0.9 constrained, 1.0 in horizon mode, and moved
//! four lines, each lower (by 0.07 % at most). Only where the optimizer's
//! end looks like a tooth or a step:
//! its gradient would move `J` over [`STEP`] by more than [`SHARE`] of `J`
//! (at a smooth optimum the gradient vanishes), or `J` still fell by more
//! than that share in the optimizer's last iteration (a staircase, whose
//! flat steps stop BFGS on its gradient rule: `unseen_51_1` track 2, 3.6 m
//! and 1.7 % short), and wherever the vehicle's depth loop integrates:
//! on `check_planner.py --seed 2418 --vehicle
//! tools/reference/vehicles/rate.toml`, `unseen_2418_4` track 3,
//! unconstrained, BFGS stopped 9 m short of a smooth-looking basin (`J`
//! 1.1 % high) on a tooth whose slope and last decrease were both under
//! that share (now 428.7 m, 1.00008× the best from the same start). On
//! the 256 random lines of the earlier rounds that costs 0.65 flights a
//! line track by track (0.25 constrained), and moves 6 lines' tracks
//! (2 constrained); horizon plans and the default vehicle's (`ki` = 0)
//! do not move. A constrained track keeps only depths whose flight
//! clears the certified altitude. It is polished where the scan hands it
//! to the optimizer, and where the optimizer, having left the safe set,
//! ran again to an interior optimum (`candidate.rs`, `inward`): on
//! `check_planner.py --seed 1203 --vehicle
//! tools/reference/vehicles/integ.toml`, `unseen_1203_2` track 3 and
//! `unseen_1203_5` track 4 ended 1.3 and 2.0 m off, 1.021× the best safe
//! `J`; polished, 1.0017× and 1.00002×. Where that second run trips
//! again (a tooth's slope points out of the safe set while the trend
//! falls into it), the search runs from the boundary itself
//! ([`Planner::polish_boundary`]): on `check_planner.py --seed 1902
//! --vehicle tools/reference/vehicles/integ.toml`, `unseen_1902_0`
//! track 1 kept its boundary, 1.0087× the best safe `J`; now 1.0004×.
//! Where the doubling steps themselves leave the safe set while `J`
//! still falls, the boundary between the lowest point and that step is
//! searched ([`boundary_toward`]): on `check_planner.py --seed 2669
//! --vehicle tools/reference/vehicles/integ.toml`, `unseen_2669_0` track
//! 1, constrained, BFGS ended on a tooth at 624.5 m, the doubling reached
//! 626.0 m and its next step (628.0 m) flew below `h_a`: 1.0185× the best
//! safe `J`, whose depth (627.44 m) is on the boundary; now 1.0014×. The
//! horizon's first depth has the same search against its floors. On the
//! 267 random lines 11 horizon plans are lower (by up to 2.3 %), for 0.7
//! more flights a line; track by track, 2 constrained lines move (their
//! polished track lower, the later tracks' own choices from its end
//! 0.07 % and 0.33 % higher on the line); the 18 shared runs keep their
//! plans and flights.
//!
//! A horizon's SQP meets the same teeth ([`Planner::polish_first`]): on
//! `check_planner.py --seed 2002 --vehicle
//! tools/reference/vehicles/integ.toml`, `unseen_2002_7`, the cold call
//! converged with track 1 16 m above its target, its `∂J/∂z_1` a tooth's
//! −8.2e3 m² where the trend is −3.9e4 m², and an active row of track 4
//! whose gradient (a tooth's too) said a deeper track 1 pulled track 4
//! down, while its least altitude stays within centimetres over 45 m of
//! `z_1`. Each call's first depth is polished, the later depths held,
//! where the depth loop integrates: the line went from 1.50× to 1.116×
//! the best safe `J` (track 1 at 564.6 m; the best plan's 568.0 m).
//!
//! The later depths can be stuck the same way: free of their targets,
//! with a gradient that promises much, where the SQP's steps are cut to
//! slivers by the teeth and a row's kink. On `check_planner.py --seed
//! 2993 --vehicle tools/reference/vehicles/twoki.toml`
//! (`unseen_2993_1`) the cold call ended with track 2 at 1 331.8 m, 4.4 m
//! above its target with `∂J/∂z_2` = −1.5e4 m², where it could fly 10 m
//! deeper; the first depth's polish then took track 1 5 m deeper, which
//! that shallow track 2 allowed, and the line was 1.113× the f64 search's
//! best safe plan. So before the first depth, each later depth whose track
//! clears its target by more than 10 % of the band (5 % before round 40; the lift's
//! [`TEETH_SLACK`](super::objective::TEETH_SLACK)), and whose
//! gradient promises more than [`SHARE`] of `J` over [`STEP`], is
//! polished the same way, the other depths held, against the same
//! floors: 1.069× (track 2's descent stops at 1 335.2 m, where track 4's
//! least altitude, at its target, wanders below its floor with the teeth;
//! the best plan flies track 4 3.5 m shallower). On the 304 random lines
//! of BENCHMARKS.md 14 move in horizon mode, 10 lower (by up to 0.17 %)
//! and 4 higher (by up to 0.24 %: `unseen_5034_2`, `integ`, 1.0440× →
//! 1.0466× the f64 best), 2.95 flights a line more; the default vehicle's
//! depth loop does not integrate, and the 18 shared runs keep their plans
//! and flights. A later depth on a staircase has no such gradient: on
//! `check_planner.py --seed 3120 --vehicle
//! tools/reference/vehicles/rate.toml` (`unseen_3120_6`) the cold call
//! converged with tracks 4 and 5 clear of their targets and `∂J/∂z` of
//! 2.4 and 4.5 m² (a step's flat: `J` jumps about 90 m³ every 5 to 8 cm
//! of `z_5` on a trend of 1 800 m³/m), where `z_4` 4.5 m deeper with
//! `z_5` 3.7 m shallower is 3.7 % lower; the line was 1.0159× the f64
//! search's best safe plan. So a later depth is polished also where `J`
//! fell by more than [`SHARE`] of itself in the SQP's last iteration, as
//! a single track is (1.6e-3 there): 1.0015×. On the 304 random lines 4
//! move, all lower (to −0.29 %), for 1.8 flights a line more; the 18
//! shared runs give the same JSON.
//!
//! A look's descent reads the trend and ends anywhere on a tooth, up to
//! a tooth's height above its bottom. Where `J` is small that height is a
//! share of it: on `check_planner.py --seed 2792 --vehicle
//! tools/reference/vehicles/integ.toml`, `unseen_2792_1` track 1 (`J`
//! 1.15e3 m³, teeth 6 cm wide and 9 m³ high), the polish ended just past
//! a jump, 1.011× the best `J`. Where the depth loop integrates, the
//! polish's end then settles to a tooth's bottom: the same search from
//! a first step of 1 cm (`looks.rs`, `TOOTH`; 1.0014×). On 304 random lines it moves 86
//! lines track by track unconstrained (each polished track lower from
//! its own start; the later tracks' own choices make 40 lines lower and
//! 46 higher, by 1.3 % at most), 17 constrained (11 lower, 6 higher by
//! 0.2 % at most) and 6 in horizon mode (4 lower, 2 higher by 0.17 % at
//! most), for 2.6, 0.4 and 0.2 flights a line; the default vehicle's
//! depth loop does not integrate, and the 18 shared runs keep their plans
//! and flights.
//!
//! A tooth's bottom lies at its jump, and a depth there is a knife edge:
//! on `check_planner.py --seed 3145 --vehicle
//! tools/reference/vehicles/rate.toml`, `unseen_3145_2` track 1
//! (constrained track by track), the settling ended at 778.28735 m, `J`
//! 33 533.2 m³, one f32 ulp short of a jump of +43 m³; the f64 flight of
//! the same depth is past it (33 576.3 m³, 1.3e-3 of `J` off the reported
//! value, over the checker's 1e-3). So the bottom is backed off its jump
//! by 2 mm against the settling's descent (`looks.rs`, `BACK`), kept where
//! `J` there is within [`SHARE`] of the bottom's: 778.28534 m, 33 534.2
//! m³, the f64 flight within 1e-6. On the 304 random lines (one flight
//! more where the settling moved) it moves 3 lines in horizon mode (to
//! ±0.01 %, 0.06 flights a line fewer), 7 constrained track by track (3
//! lower, to −0.33 %; 4 higher, to +0.03 %; 0.07 flights a line more) and
//! 45 unconstrained (22 lower, 23 higher, within ±0.5 %; 0.56 flights a
//! line more); the 18 shared runs give the same JSON.
//!
//! A descent from the first look can also end at its parabola's vertex
//! short of the basin, where neither wider look finds a lower point: on
//! `check_planner.py --seed 3162 --vehicle
//! tools/reference/vehicles/rate.toml`, `unseen_3162_7` track 4
//! (constrained track by track, its least altitude 60.14 m whatever the
//! depth near the basin), the vertex through the points 1 and 2 m apart
//! fell at 1 102.39 m, 0.75 m short of the basin on teeth of about 40 m³:
//! 1.0058× the f64 best, over the checker's 1.005. So the first look is
//! taken once more after those two: 1 102.88 m, 1.0015×. On the 304
//! random lines the first track to change, from the same start, is lower
//! on 1 line constrained track by track (none higher), and within ±0.11 %
//! on 36 unconstrained (17 lower, 19 higher: which tooth the settling
//! ends on); the lines' `J` move in horizon mode on 3 lines (2 lower, one
//! 0.045 % higher), constrained track by track on one (0.15 % higher,
//! the later tracks' own choices), unconstrained on 31 (18 lower, to
//! −1.4 %; 13 higher, to +0.8 %), for 0.7, 0.3 and 1.2 flights a line;
//! the 18 shared runs give the same JSON.

use crate::num::min;
use crate::optim::{Bounds, First};
use crate::sim::TrackScore;

use super::Planner;
use super::looks::{Clear, boundary_toward, descend, flown_at, lower_side, settle};
use super::objective::PlanObjective;

/// The polish's first step, m: many teeth wide, short against a track's
/// basin (the scan's grid is tens of metres).
const STEP: f32 = 0.5;

/// The share of `J` that the gradient must predict over [`STEP`] for the
/// polish to run.
const SHARE: f32 = 1e-4;

/// The looks' steps, m, each side of the optimizer's end, in order: the
/// first ([`STEP`]), then doubling to the widest, sixteen first steps
/// (the wider look is the third, four first steps; module docs).
const LOOKS: [f32; 5] = [STEP, 2.0 * STEP, 4.0 * STEP, 8.0 * STEP, 16.0 * STEP];

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The polish of the module docs on the workspace's single track, in
    /// `bounds`, every depth's least altitude at or above `h_safe` (m)
    /// when given. Plain flights, counted in `obj`'s evaluations. Not
    /// inlined: its state stays off the optimizer's stack.
    #[inline(never)]
    pub(super) fn polish_single(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        h_safe: Option<f32>,
    ) {
        let w = &self.work;
        let Some(First {
            z: z0,
            g: g0,
            lo,
            hi,
        }) = w.first_in(bounds)
        else {
            return;
        };
        let j0 = w.j;
        let share = SHARE * libm::fabsf(j0);
        let fell = w.last_fall();
        if !(libm::fabsf(g0) * STEP > share || fell > share || obj.teeth()) {
            return;
        }
        self.polish_from(obj, (0, lo, hi), Clear::First(h_safe), (z0, j0));
    }

    /// The horizon's committed (first) depth polished as a single track's
    /// (module docs), the later depths held, where the vehicle's depth
    /// loop integrates (its `J` has teeth) and the SQP's end `self.work`
    /// is feasible (infeasibility at most `tol`, m): every point kept has
    /// each track's least altitude at most `tol` below the lower of its
    /// target and its altitude at the end. Between teeth the exact
    /// gradient is the tooth's slope, and an active row's gradient a
    /// tooth's too, so the SQP can converge where the trend of `J` still
    /// falls steeply into the safe set (and the later tracks' least
    /// altitudes wander by millimetres with the teeth). Before it, each
    /// later depth stuck above its target ([`Planner::stuck_later`]) is
    /// polished the same way. One flight to check the end, two or more
    /// for each polish. Not under declared uncertainty.
    #[inline(never)]
    pub(super) fn polish_first(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
    ) {
        let Some(First { z: z0, lo, hi, .. }) = self.work.first_in(bounds) else {
            return;
        };
        // (Not under declared uncertainty: as the other escapes.)
        if h < 2 || !obj.teeth() || obj.declared() {
            return;
        }
        let Ok(end) = obj.flight(&self.work.z) else {
            return;
        };
        let Ok((j0, v0)) = obj.value_of(&end) else {
            return;
        };
        if v0 > tol {
            return;
        }
        let mut floors = [f32::NEG_INFINITY; K];
        for (t, (floor, s)) in floors.iter_mut().zip(&end).enumerate().take(obj.count) {
            *floor = min(s.min_altitude(), obj.target_of(t)) - tol;
        }
        let clear = Clear::Floors(floors);
        let fell = self.work.last_fall();
        let mut j0 = j0;
        for i in 1..h.min(obj.count) {
            if self.stuck_later(obj, (i, bounds), (&end, fell), tol)
                && let (Some(&zi), Some(&lo), Some(&hi)) =
                    (self.work.z.get(i), bounds.lo.get(i), bounds.hi.get(i))
                && self.polish_from(obj, (i, lo, hi), clear, (zi, j0))
            {
                j0 = self.work.j;
            }
        }
        self.polish_from(obj, (0, lo, hi), clear, (z0, j0));
    }

    /// Whether later depth `i` of the SQP's end (its flight `end`) is
    /// stuck (module docs): its track clears its target by more than
    /// [`PlanObjective::held_slack_teeth`] (m), and its gradient
    /// predicts more than [`SHARE`] of `J` over [`STEP`] or `J` fell by
    /// more than that share in the SQP's last iteration (`fell`, m³: a
    /// staircase).
    fn stuck_later(
        &self,
        obj: &PlanObjective<'_, N>,
        (i, bounds): (usize, &Bounds<K>),
        (end, fell): (&[TrackScore; K], f32),
        tol: f32,
    ) -> bool {
        let slack = obj.held_slack_teeth(tol);
        let w = &self.work;
        let (Some(s), Some(&g), Some(&lo), Some(&hi)) = (
            end.get(i),
            w.gradient.get(i),
            bounds.lo.get(i),
            bounds.hi.get(i),
        ) else {
            return false;
        };
        let share = SHARE * libm::fabsf(w.j);
        lo < hi
            && s.min_altitude() > obj.target_of(i) + slack
            && (libm::fabsf(g) * STEP > share || fell > share)
    }

    /// The polish's search from a constrained track's boundary `(z, J)`
    /// (m, m³), in `bounds`, every point's least altitude at or above the
    /// objective's guard (its trip cleared): the workspace put at the
    /// boundary, then moved to the lower `J` if one is found (whether it
    /// was).
    pub(super) fn polish_boundary(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        (z, j): (f32, f32),
    ) -> bool {
        if let Some(first) = self.work.z.first_mut() {
            *first = z;
        }
        self.work.j = j;
        let (Some(&lo), Some(&hi)) = (bounds.lo.first(), bounds.hi.first()) else {
            return false;
        };
        obj.tripped = None;
        let guard = obj.guard;
        self.polish_from(obj, (0, lo, hi), Clear::First(guard), (z, j))
    }

    /// The polish's search of depth `i` from `(z0, J0)` (m, m³), the
    /// workspace's depth `i` at `z0`, in `[lo, hi]` (m), the other depths
    /// held, its points clearing `clear`: whatever the gradient says.
    /// Moves the workspace to the lowest point found below the stopping
    /// threshold; whether it moved. Out of line: one copy for every
    /// caller.
    #[inline(never)]
    pub(super) fn polish_from(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (i, lo, hi): (usize, f32, f32),
        clear: Clear<K>,
        (z0, j0): (f32, f32),
    ) -> bool {
        let tol = self.cfg.bfgs.tol;
        let bar = j0 - tol.j_threshold(j0);
        let base = self.work.z;
        let teeth = obj.teeth();
        let inside = |z: f32| crate::num::max(crate::num::min(z, hi), lo);
        let mut at = |z: f32| {
            let z = inside(z);
            (z.to_bits() != z0.to_bits())
                .then(|| flown_at(obj, (&base, i, z), clear))
                .flatten()
        };
        // Each side at the first step, then, where neither is lower, at
        // each wider look in turn (a bump of the teeth, or of `J`'s
        // wiggles, can hide the basin).
        let Some((first, step)) = LOOKS
            .into_iter()
            .find_map(|s| lower_side(&mut at, (z0, s), bar).map(|p| (p, s)))
        else {
            return false;
        };
        let (mut best, mut out) = descend(&mut at, inside, (z0, j0), (first, step));
        // A descent from the first look may end in a dip beside the basin:
        // the wider look once more from its end, and where neither finds a
        // lower point, the first look (its vertex may fall short); a
        // descent from a wider look, at a vertex a step of the teeth off
        // the basin: the first look once more (module docs).
        if out.is_none() {
            let bar = best.1 - tol.j_threshold(best.1);
            let [.., wider, twice, _] = LOOKS;
            let again: &[f32] = if step <= STEP {
                &[wider, twice, STEP]
            } else {
                &[STEP]
            };
            let again = again
                .iter()
                .find_map(|&s| lower_side(&mut at, (best.0, s), bar).map(|p| (p, s)));
            if let Some(again) = again {
                (best, out) = descend(&mut at, inside, best, again);
            }
        }
        // The look's end lies anywhere on a tooth: settled to a tooth's
        // bottom where the depth loop integrates, and backed off its jump
        // (module docs).
        if teeth {
            let bar = best.1 - tol.j_threshold(best.1);
            best = settle(&mut at, inside, best, (bar, SHARE * libm::fabsf(best.1)));
        }
        // `J` still fell where the next step left the safe set: the
        // boundary between them.
        if let Some(z) = out
            && let Some(p) =
                boundary_toward(obj, (&base, i, best.0, z), clear, self.cfg.bisection_steps)
            && p.1 < best.1
        {
            best = p;
        }
        let w = &mut self.work;
        if let Some(z) = w.z.get_mut(i) {
            *z = best.0;
        }
        w.j = best.1;
        // (The polished value ends the history; full, it keeps its last.)
        let _ = w.history.push(best.1);
        true
    }
}
