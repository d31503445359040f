//! A later track whose dive is saturated the whole track, flying high
//! above its target, after a track held at its target: its depth does
//! not move `J` (the vehicle dives at the pitch limit and never reaches
//! it), and the held track before it would have the dive begin earlier,
//! but its own target holds it. The best plan can set the held track's
//! reference far deeper, below its own bottom, so that the dive is under
//! way before the later track begins, and climb on the track before so
//! that the early dive passes the held track's bottom. No single depth's
//! move sees that: the held track's row says it cannot go deeper, and
//! the later one's depth has no gradient.
//!
//! On `check_planner.py --seed 2848 --vehicle
//! tools/reference/vehicles/slow.toml` (`unseen_2848_5`) the cold SQP
//! ended with track 3 0.79 m above its target at 690.0 m, `∂J/∂z_3`
//! −9.2e4 m², and track 4 at 1 115.5 m, 72.7 m above the bottom at its
//! least (its target 60 m), `∂J/∂z_4` zero, 5.38e6 of the line's 6.19e6
//! m³: its bottom falls 43° away and the slow vehicle dives too late.
//! The f64 search's best safe plan climbs 333 m on track 2 and sets track
//! 3 at 980 m. The line was 1.425× that plan's `J`.
//!
//! The escape: for each later track `t` (from the third) whose depth's
//! gradient is within [`FLAT`] of the horizon's `J` over the band `h_r −
//! h_a`, more than the band deeper than track `t − 1`, where `∂J/∂z_{t −
//! 1}` is negative (these from the SQP's end, no flight), and, from one
//! flight of the horizon, track `t` [`NEAR`] of the band above its target
//! or more and track `t − 1` within that of its target: the SQP restarted
//! with depth `t − 1` set to depth `t` (kept if it ends better). That
//! start is far from feasible (track 3 89 m into the bottom); the
//! restart's restoration climbs on the tracks before. `unseen_2848_5`
//! ends at 0.928× the f64 search's best safe plan (track 2 at 489 m,
//! track 3 at 1 115.5 m). On `make_lines.py`'s `unseen_5011_5` (the default
//! vehicle) the line was 2.010× the f64 best safe plan and is 1.0010×. On
//! the 304 random lines of BENCHMARKS.md 6 move, 5 lower (also
//! `unseen_5021_1` 0.942×, `unseen_5001_2` 0.997×) and one higher by
//! under 1e-5 (a line with no safe plan), 4.1 flights a line more; the 18
//! shared runs keep their plans, Monterey 2's cold call at 1 flight more
//! (Monterey 1's later tracks climb: no flight). Before the test on the
//! depths without a flight (a later track deeper, the held one's gradient
//! negative), Monterey 1's cold call flew once more for nothing.
//!
//! The restoration need not find the climb. On `check_planner.py --seed
//! 3312 --vehicle tools/reference/vehicles/heavy.toml` (`unseen_3312_5`)
//! track 4 dived at the pitch limit 170 m above its bottom at its least
//! after track 3 held at its target; restarted with track 3 at track 4's
//! depth, the SQP ended worse, and the line was 1.335× the f64 search's
//! best safe plan, which climbs at the pitch limit on track 2 and sets
//! track 1 42 m shallower and track 3 112 m deeper. So the SQP restarts a
//! second time from the same start with the track before the held one at
//! the shallow end of its box (its climb), kept if it ends better:
//! 0.9989×. On the 304 random lines no plan moves, +0.69 % flights (the
//! second restart where the first runs); the 24 shared runs, and Monterey
//! 1–3 under the README's recommended bounds, keep their plans and
//! flights.
//!
//! The dive can need to begin on the first track, where the SQP cannot
//! move it: a first track that dives at the pitch limit the whole track
//! has `∂J/∂z_1` exactly zero, its depth anywhere on that plateau flying
//! the same. On `check_planner.py --seed 3188 --vehicle
//! tools/reference/vehicles/integ.toml` (`unseen_3188_1`) the cold SQP
//! ended with track 1 at 482.7 m on such a plateau (the same flight from
//! 470 m to 600 m), track 2 held at its target at 601.9 m and tracks 3 to
//! 5 diving after it; the best safe plan sets track 1 at 674.7 m, its
//! dive deeper at its own target, where track 2's least altitude is set
//! by the arrival and its depth goes 7.5 m deeper, and tracks 3 to 5 fly
//! 8 m nearer their bottoms: the line was 1.0515× the f64 search's best
//! safe plan. [`Planner::dive_first`] takes the first depth to its own
//! boundary, searched from the deepest depth of the first track's scan
//! at or below it that clears its target toward the next deeper that does
//! not (602 m and 721 m there), the later depths held, and restarts the
//! SQP from there: 1.0004×. On the 304 random lines 6 run it and 2 move,
//! both lower (`unseen_5018_5` −0.33 %, `unseen_5030_5` −0.015 %), 0.7
//! flights a line fewer (the lower restarts end sooner); the 18 shared
//! runs keep their plans and flights.

use crate::optim::constrained::group_bit;
use crate::optim::{Bounds, Outcome};

use super::Planner;
use super::looks::{Clear, boundary_toward};
use super::objective::{PlanObjective, Stop};
use super::scan::{ScanLog, with_depth};

/// A later depth's gradient counts as flat within this share of the
/// horizon's `J` over the band `h_r − h_a`.
const FLAT: f32 = 1e-4;

/// The share of the band by which the later track flies above its target,
/// and within which the track before is at its own.
const NEAR: f32 = 0.1;

/// Most flights of the first track's boundary search in
/// [`Planner::dive_first`].
const FIRST_STEPS: u32 = 6;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The escape of the module docs over a horizon of `h` tracks in
    /// `bounds`, feasible within `tol` (m), after `iterations`. Returns the
    /// iterations so far.
    pub(super) fn dive_earlier(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        mut iterations: u32,
    ) -> u32 {
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        // The later tracks that dive, from the SQP's end (no flight).
        let dives = (2..h)
            .filter(|&t| diving(&self.work, t, band))
            .fold(0, |set, t| set | group_bit(t).unwrap_or(0));
        if dives == 0 || !self.feasible_with_room(obj, tol, iterations) {
            return iterations;
        }
        let z = self.work.z;
        let Ok(tracks) = self.dive_tracks(obj, (dives, h), (band, tol)) else {
            return iterations;
        };
        for t in (2..h).filter(|&t| group_bit(t).is_some_and(|b| tracks & b != 0)) {
            let g = t.saturating_sub(1);
            let (Some(&zt), Some(&hi)) = (z.get(t), bounds.hi.get(g)) else {
                continue;
            };
            let mut start = with_depth(&z, g, crate::num::min(zt, hi));
            iterations = self
                .sqp_restart(obj, &start, (h, bounds), (tol, 0.0, false), iterations)
                .unwrap_or(iterations);
            // The track before the held one started on its climb too
            // (module docs): the restoration may not find it.
            let Some(b) = g.checked_sub(1) else {
                continue;
            };
            let (Some(&lo), Some(slot)) = (bounds.lo.get(b), start.get_mut(b)) else {
                continue;
            };
            *slot = lo;
            iterations = self
                .sqp_restart(obj, &start, (h, bounds), (tol, 0.0, false), iterations)
                .unwrap_or(iterations);
        }
        iterations
    }

    /// The first track's dive taken to its own boundary (module docs):
    /// where the SQP's feasible end (within `tol`, m) has a first depth
    /// whose gradient is exactly zero and the scan of the first track
    /// (`scan`) found a depth at or below it that clears the first track's
    /// target and a deeper one that does not, the boundary between them
    /// is searched ([`FIRST_STEPS`] plain flights at most, the later
    /// depths held), and the SQP restarted from it, kept if it ends
    /// better. Returns the iterations so far.
    pub(super) fn dive_first(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        scan: &ScanLog,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        iterations: u32,
    ) -> u32 {
        let z = self.work.z;
        let flat = self.work.gradient.first() == Some(&0.0);
        if h < 2 || !flat || !self.feasible_with_room(obj, tol, iterations) {
            return iterations;
        }
        let (Some(&z1), target) = (z.first(), obj.target_of(0)) else {
            return iterations;
        };
        let Some((safe, out)) = bracket(scan, z1, target) else {
            return iterations;
        };
        let clear = Clear::First(Some(target));
        let Some((zb, _)) = boundary_toward(obj, (&z, 0, safe, out), clear, FIRST_STEPS) else {
            return iterations;
        };
        let start = with_depth(&z, 0, zb);
        self.sqp_restart(obj, &start, (h, bounds), (tol, 0.0, false), iterations)
            .unwrap_or(iterations)
    }

    /// The tracks of `dives` (bit `t` set for later track `t`, of the `h`)
    /// that fly high after a held track (module docs), from one flight of
    /// the workspace. (Not inlined: the flight's scores stay off the
    /// restarts' stack.)
    #[inline(never)]
    fn dive_tracks(
        &self,
        obj: &mut PlanObjective<'_, N>,
        (dives, h): (u32, usize),
        (band, tol): (f32, f32),
    ) -> Result<u32, Stop> {
        let scores = obj.flight(&self.work.z)?;
        let near = NEAR * band + obj.held_slack_teeth(tol);
        let mut tracks = 0;
        for t in 2..h {
            let (g, bit) = (t.saturating_sub(1), group_bit(t).unwrap_or(0));
            let (Some(st), Some(sg)) = (scores.get(t), scores.get(g)) else {
                continue;
            };
            let high = st.min_altitude() >= obj.target_of(t) + NEAR * band;
            let held = sg.min_altitude() <= obj.target_of(g) + near;
            if dives & bit != 0 && high && held {
                tracks |= bit;
            }
        }
        Ok(tracks)
    }
}

/// Whether later track `t` of the SQP's end `w` dives from the track
/// before (module docs): its depth's gradient flat, its depth more than
/// the `band` (m) below the one before, whose gradient is negative.
fn diving<const K: usize>(w: &Outcome<K>, t: usize, band: f32) -> bool {
    let g = t.saturating_sub(1);
    let flat = w
        .gradient
        .get(t)
        .is_some_and(|d| d.abs() * band <= FLAT * w.j);
    let deeper =
        w.z.get(t)
            .zip(w.z.get(g))
            .is_some_and(|(zt, zg)| *zt > *zg + band);
    flat && deeper && w.gradient.get(g).is_some_and(|d| *d < 0.0)
}

/// The deepest depth of the first track's scan at or below `z1` (m) whose
/// least altitude clears `target` (m), and the shallowest deeper one that
/// does not: the bracket of [`Planner::dive_first`]'s boundary search.
fn bracket(scan: &ScanLog, z1: f32, target: f32) -> Option<(f32, f32)> {
    let safe = scan
        .iter()
        .filter(|&(z, least)| z >= z1 && least >= target)
        .map(|(z, _)| z)
        .reduce(f32::max)?;
    let out = scan
        .iter()
        .filter(|&(z, least)| z > safe && least < target)
        .map(|(z, _)| z)
        .reduce(f32::min)?;
    Some((safe, out))
}
