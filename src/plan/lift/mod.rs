//! A cold horizon whose SQP ends with a later track held at its least
//! altitude's target by the depth of the track before it: the vehicle
//! arrives too deep for the later track to be given a deeper depth.
//! Lifting the earlier depth lets the later one dive, a joint move of two
//! depths that neither makes alone. On a random canyon line
//! (`check_planner.py --seed 60606`, `unseen_60606_0`) the SQP ended with
//! track 1 at 662.6 m (a saturated dive: `∂J/∂z_1` exactly 0, and no
//! single-depth scan gains) and track 2 at its target at 661.1 m; the best
//! safe plan flies track 1 at 587 m so that track 2 can dive to 922 m. The
//! line's `J` was 1.56× the f64 search's best safe plan; after, 1.001×
//! (`unseen_5151_6`: 1.33× → 1.002×).
//!
//! The escape, for each later track `g` at its target: depth `g − 1`
//! lifted by the band `h_r − h_a`, doubling (at most [`LIFTS`] times,
//! within the box). At each lift, track `g`'s least altitude is measured
//! at its own depth (one flight of the two tracks): where it clears the
//! target by the band, depth `g` is deepened by what was freed beyond the
//! band; and where track `g` at its preferred depth clears its target at
//! the same lift (its least altitude set by track `g − 1` alone, a
//! saturated dive's plateau), the least lift that frees that depth is
//! narrowed too, and the start with the lower horizon `J` is taken
//! (`unseen_1302_5`: 1.40× → 1.001×; the freed start there was worse than
//! the SQP's end); where the preferred depth does not clear it, the
//! deepest depth `g` between the two that does is bisected for, a third
//! start (`unseen_1206_6`: 1.40× → 1.0007×). Where no lift frees track
//! `g` by the band, and track `g` is held more than the band
//! above its preferred depth (its bottom's mean less `h_r`), the lift that
//! lets track `g` fly its preferred depth is sought instead: a dive from
//! a shallower start passes a rise of the bottom higher, so a climb on
//! track `g − 1` can buy a deep track `g` (`unseen_90317_0`, where the
//! best plan climbs 209 m on track 3 to fly track 4 250 m deeper). The
//! least such lift found by doubling is narrowed by
//! [`NARROW`](super::raise::NARROW) bisections (one flight each); where
//! the climb saturates before any lift frees it, the least lift that
//! reached the saturation is taken. The same search is made for track
//! `g` at its deepest useful depth (its deepest bottom less `h_r`) where
//! that is below the preferred one, or below track `g`'s own depth where
//! it is not held more than the band above the preferred one, by more
//! than the altitude that counts as a gain (by more than the band before
//! round 36, below): on a track whose bottom falls away, the best plan
//! may dive at the pitch limit the whole track (a saturated plateau) from
//! a start lifted further than the mean needs. On `check_planner.py --seed 2203 --vehicle
//! tools/reference/vehicles/integ.toml` (`unseen_2203_4`) the preferred
//! start (track 1 lifted 20 m, track 2 at 816 m) restarted into the SQP's
//! end again; the deepest (track 1 lifted 90 m, track 2 at 980 m) ends at
//! 1.0006× the f64 best safe plan, where the line was 3.36×. That start
//! is restarted after the best of the others (its `J` does not tell which
//! ends better: ranked with them by `J`, it displaced the freed start of
//! `unseen_2006_5` below, 0.991× → 1.318×), and kept only where it ends
//! lower (`unseen_2004_7`: 1.31× → 1.003×). Each start is
//! flown whole (one flight of the tail) and the SQP restarted from it,
//! kept only if it ends better: a freed start (its infeasibility within
//! the band) where the horizon's `J` is at most [`FREED_SHARE`] above the
//! SQP's, a start at the preferred depth (which may be far from
//! feasible) where it is lower, or where it is feasible within the band,
//! as a freed one (`--seed 2550`, `slow`, `unseen_2550_6`: track 2 lifted
//! 110 m for track 3 to fly its preferred depth, feasible within the band, at
//! 1.04× the SQP's `J`; restarted, the line goes from 1.136× to 1.0009×
//! the f64 best; on 267 random lines one moves, by 1e-4, 1.2 flights a
//! line more); then the next later track, from wherever
//! the workspace stands. A freed start's `J` may be above the SQP's and
//! its restart's end below: on `check_planner.py --seed 2006 --vehicle
//! tools/reference/vehicles/second.toml` (`unseen_2006_5`) the start
//! lifted track 2 by 160 m (5.33e6 m³ against 4.48e6, 1.19×), and the
//! restart ended 101 m above the SQP's track 2 with track 3 81 m deeper:
//! the line's `J` 1.32× → 0.991× the f64 best safe plan's. Measured on
//! 256 random lines: 21 move, `unseen_8080_6` 0.94×, `unseen_1404_5`
//! 1.062×, 6 flights a line more. With no bound, 50 move (`unseen_1205_4`
//! 0.75×, its start 1.42× the SQP's) at 18 flights a line, and Monterey
//! 2's cold call flies a start 1.33× the SQP's for nothing (+12 flights,
//! +122 M instructions on the M4F). The deepest depth's start moves 15 of
//! the 256 lines (`unseen_1401_4` 0.79×, `unseen_1202_1` 0.93×,
//! `unseen_1404_5` 0.94×; `unseen_1203_3` 1.021×, still 0.973× the f64
//! best) at 14 flights a line.
//!
//! A lift that leaves track `g` at its deep depth no higher than the last
//! one ends the search as a saturated climb only where the lifted depth
//! is at or above the state track `g − 1` starts in. Below it, the track
//! still dives, and a dive saturated the whole track flies the same
//! however far its reference is lifted, until the lift brings the
//! reference within the dive's reach: the lifts go on, and where none
//! frees track `g`, the search ends as the first such lift would have
//! ended it. On `check_planner.py --seed 2730
//! --vehicle tools/reference/vehicles/second.toml` (`unseen_2730_4`)
//! lifts of 20 and 40 m left track 4's dive, from 593 m toward 785 m,
//! the same, and the search stopped; the best plan lifts track 4 by 116
//! m, so that track 5 flies 47 m deeper. The line's `J` was 1.23× the
//! f64 search's best safe plan; lifted on past the dive's plateau (80,
//! then 160 m), 1.004×. A lift past the plateau that frees track `g` at
//! its own depth does not displace the first flat lift's start: both are
//! ranked (as `Next::Both`), since a lift that frees the track may be far
//! from the best (`unseen_1801_2`, `--seed 1801`: a freed start 620 m up
//! displaced the plateau's, and the line went from 1.0027× to 1.51×). On
//! the 267 random lines 15 move (`unseen_3125_1` −0.4 %, `unseen_3113_7`
//! −0.3 %; `unseen_3101_0` +0.02 %, and one line with no safe plan
//! +0.3 %), 1.9 flights a line more; the 18 shared runs keep their
//! plans, Medes 2 at 12 flights more.
//!
//! The deepest depth's search doubles the lift until track `g` at that
//! depth clears its target; a lift that frees track `g` at its own depth
//! first no longer ends it. On `check_planner.py --seed 2309 --vehicle
//! tools/reference/vehicles/low.toml` (`unseen_2309_6`) a lift of 24 m
//! freed track 3 at its own depth, so no deepest start was made; the best
//! plan lifts track 2 by 116 m for track 3 to dive 319 m deeper: the line
//! 1.53× the f64 best safe plan, now 1.0014×. (Where the climb then
//! saturates first, the start is kept only if track `g` is within the
//! band of its target there: Monterey 1's deepest depths saturate 87 and
//! 103 m into the bottom, and those starts cost its cold call 7 flights,
//! 21.7 M instructions on the M4F, for nothing.) And the start at the
//! deepest depth, where it leaves track `g + 1` more than the band below
//! its target (a dive carried on from a deeper arrival), has
//! depth `g + 1` raised to the deepest found that clears it (doubling,
//! then [`NARROW`](super::raise::NARROW) bisections), since a later
//! depth on a saturated plateau gives the restart's restoration no gradient: on `--seed 2308`
//! (`low`, `unseen_2308_5`) the start left track 3 165 m into the
//! bottom, and the restart retreated track 2 instead; raised, the line
//! goes from 1.18× to 0.994× the f64 best. (Raised wherever it is below
//! its target at all, `lift_both` went back to 1.31×; the preferred
//! depth's start raised too, `unseen_4242_5` went from 1.04× to 1.11×.)
//! The freed start's deepest depth `g` (the third start above) is raised
//! the same way: on `--seed 3125` (`low`, `unseen_3125_3`) a 24 m lift of
//! track 2 freed track 3 100 m deeper, which left track 4 below its
//! target by more than the band, and the start was not taken; raised, the
//! line goes from 1.101× to 1.0006× the f64 best (on 267 random lines, 2
//! move, both lower: `unseen_3112_3` 1.024× → 0.959×; 0.7 flights a line
//! more).
//!
//! The doublings reach 128 bands (eight lifts; six before round 31, 32
//! bands). On `check_planner.py --seed 2984 --vehicle
//! tools/reference/vehicles/tight.toml` (`unseen_2984_5`, band 4 m)
//! track 3 was held by a ridge 200 m into it. Lifts of track 2 up to
//! 128 m left track 3's least altitude at its preferred depth still
//! rising (−107 m, then −62 m at the last), so the climb was never seen
//! to saturate and the lift before a saturated one was not sought. The
//! best plan lifts track 1 by 52 m and track 2 into its saturated climb
//! so that track 3 flies 148 m deeper, past the ridge: the line's `J` was
//! 1.44× the f64 search's best safe plan. With eight lifts the climb
//! saturates at 256 m and the lift of track 1 before it makes the start:
//! 1.0013×. On the 304 random lines of BENCHMARKS.md one other moves
//! (`unseen_5032_2`, `tight`, 0.70×), for 2.3 flights a line (577 of
//! them on that line); the 18 shared runs keep their plans and flights.
//!
//! A climb that does not saturate can leave track `g` as short as the
//! last lift did too: the vehicle settles on track `g`'s deep depth
//! before its least altitude, whatever the lift, until a lift so far that
//! the dive is still under way there. Where track `g − 1`'s `J` moved
//! between the two lifts (by more than `MOVED` of it, `search.rs`: the climb
//! is not saturated), one far lift is flown, `FAR` bands (the
//! doubling's reach; not above the box); where it frees track `g` at its
//! deep depth, the least lift that does is narrowed as above, and that
//! start is restarted after the best of the others where its horizon `J`
//! is below the SQP's (the plateau's start is still ranked: on a line it
//! alone ends better). On `check_planner.py --seed 2941 --vehicle
//! tools/reference/vehicles/heavy.toml` (`unseen_2941_6`) lifts of 20 and
//! 40 m left track 4 at its preferred depth 53 m short; the best plan
//! climbs 160 m and more on track 3, so that the sluggish dive passes the
//! rise above its target and track 5 flies 250 m deeper. The line's `J`
//! was 1.248× the f64 search's best safe plan; after, 0.996×. On 304
//! random lines on the ten vehicles of `tools/reference/vehicles/` and
//! the default, none moves, 1.7 flights a line more; the 18 shared runs
//! keep their plans, Monterey 1's flights too, and Medes 1 and 2,
//! Aburatsubo and Monterey 2 fly 1 to 3 more times.
//!
//! A lift by the band can free track `g` by less than the band and still
//! pay: where track `g`'s least altitude moves less than a metre per
//! metre of its own depth (its low point passed while the vehicle still
//! dives), the depth freed is more than the altitude. So the lift also
//! walks along track `g`'s target: depth `g − 1` lifted by the band and
//! depth `g` deepened by the secant's reach back to its target (one
//! flight at as much again as was freed: `freed² / fell`, at most
//! `REACH` = 4 times what was freed), at most two steps (`WALKS`), while
//! the start (one flight of the tail) stays feasible within the band and
//! its horizon `J` falls below the SQP's. Its last step is restarted
//! after the best start, where there is no far lift's. On
//! `check_planner.py --seed 2749 --vehicle
//! tools/reference/vehicles/rate.toml` (`unseen_2749_4`) the lift of
//! track 2 by 20 m freed 4.3 m of track 3's least altitude, and the
//! line's `J` rises over the first 5 m of the lift before it falls: the
//! line went from 1.26× the f64 search's best safe plan to 1.124×. (The
//! best plan lifts track 2 by 43 m, where track 3's least altitude moves
//! to another point and it flies 20 m deeper still: a jump the walk's
//! restart does not see.) On 304 random lines 10 move, 7 lower
//! (`unseen_5000_3` 0.943×, `unseen_5036_5` 0.981×) and 3 higher by at
//! most 0.064 %, 6.1 flights a line more; the 18 shared runs keep their
//! plans, Monterey 1's cold call at 1 flight more.
//!
//! Where the walk's first step leaves the tail more than the band from
//! feasible, the band's lift went past a jump of track `g`'s least
//! altitude (its low point moved), and the walk is made again with lifts
//! of a quarter and a half band (`SHORT`). On `check_planner.py --seed
//! 3061 --vehicle tools/reference/vehicles/stiff.toml` (`unseen_3061_0`)
//! track 3's clearing depth rises from 377.3 m to 388.2 m as track 2 is
//! lifted 7 m, with the line's `J` about 10 % lower, then jumps to 448 m,
//! which puts tracks 4 and 5 into the bottom; the lift by the band (20 m) and
//! its walk were past the jump, and the line was 1.126× the f64 search's
//! best safe plan. The quarter band's start (5 m, its `J` 1 % below the
//! SQP's) restarts to 1.0007×. On the 304 random lines one moves (by under
//! 1e-5), 0.25 flights a line more; the 18 shared runs keep their plans
//! and flights.
//!
//! A lift that reaches the box's floor (the surface) with track `g` at
//! its deep depth within the band of its target is a start too, as a
//! saturated climb's: on `check_planner.py --seed 2542 --vehicle
//! tools/reference/vehicles/stiff.toml` (`unseen_2542_5`) the best plan
//! climbs to the surface on track 2 to pass a seamount on track 3, whose
//! least altitude from the surface is 1.07 m short of its target, set by
//! the arrival; the restart's restoration lifts track 1 the metre it
//! needs, and the line goes from 4.60× to 0.999× the f64 best (on 267
//! random lines none moves, 0.03 flights a line more).
//!
//! Where the lift of track `g − 1` saturates (its climb at the pitch
//! limit, track `g` at its deep depth still short of its target) and that
//! start's horizon `J` is below the SQP's, the track before is lifted
//! instead: depth `g − 2` by doubling, as above, with depth `g − 1` lifted
//! twice as far as the saturating lift, so that its climb stays saturated
//! while its start is lifted by up to as much. Its start (the best freed
//! or deep one, feasible within the band and at most [`FREED_SHARE`]
//! above the SQP's `J`) is restarted after the others. On
//! `check_planner.py --seed 2770 --vehicle
//! tools/reference/vehicles/integ.toml` (`unseen_2770_1`) track 2's climb
//! saturated 80 m up with track 3 at its preferred depth 38 m short of its
//! target; the best plan lifts track 1 by 47 m and track 2 past its
//! saturation, for track 3 74 m deeper: the line went from 1.63× to
//! 1.0015× the f64 best. On the 267 random lines one moves (1e-4 lower, at
//! 479 flights fewer), 0.2 flights a line fewer; the 18 shared runs keep
//! their plans, Medes 1 and 2 and Aburatsubo at 14, 6 and 6 flights more.
//! (Without the bound on the saturated start's `J`, Monterey 1's cold call
//! flew 6 more times for nothing: its saturated start is above the SQP's
//! `J`, and a lift of the track before costs track `g − 2` more.)
//!
//! The lift runs from the SQP's end, and the cold call's later escapes
//! may move the plan far from there (`wider.rs`, `cold_escapes`): where
//! they took the horizon's `J` below nine tenths (round 35; four fifths
//! before, `AGAIN`) of where the lift ran,
//! the lift and the held edge run once more. On `check_planner.py --seed
//! 2574 --vehicle tools/reference/vehicles/rate.toml` (`unseen_2574_1`)
//! the lift ran at `J` 5.0e6 m³ (track 1 at 945 m), where no lift freed
//! track 4; the stride and the held edge then took the plan to 1.0e6 m³
//! (track 1 at 1 006 m), with track 4 held by track 3. Lifted there, the
//! line goes from 1.186× to 1.082× the f64 best safe `J`. On 267 random
//! lines 6 move, all lower (`unseen_3111_6` −5.3 %, safe), 5.8 flights a
//! line more; the 18 shared runs keep their plans and flights. (Round 21
//! measured the lift repeated in every round: 14.7 to 49 flights a line.)
//!
//! A kept restart can leave a track before the one lifted for held at
//! its target, where it was not when the lift passed it: after the first
//! kept restart past track 2, the lift starts over from track 2, once. On
//! `check_planner.py --seed 2913 --vehicle
//! tools/reference/vehicles/twoki.toml` (`unseen_2913_6`) the lift of
//! track 3 for track 4 was kept and left track 3 held by track 2's
//! arrival: the line 1.103× the f64 best safe plan; looked at again,
//! 1.025×. On the 267 random lines 11 move, 10 lower (to 0.997×) and one
//! 0.18 % higher, 9.8 flights a line more; the 18 shared runs keep their
//! plans and flights.
//!
//! A later track counts as held at its target within a hundredth of the
//! band, but where the depth loop integrates within [`TEETH_SLACK`](super::objective::TEETH_SLACK) of
//! it: the SQP stops where a tooth's gradient says (`polish.rs`), short
//! of the boundary. On `check_planner.py --seed 2003 --vehicle
//! tools/reference/vehicles/integ.toml` (`unseen_2003_1`) track 2 ended
//! 0.27 m above its target (the hundredth is 0.2 m), held there by track
//! 1; lifting track 1 by 2.9 m lets it fly 23 m deeper: the line went from
//! 1.139× to 1.046× the f64 best. (For every vehicle, the 256 lines moved
//! little, but Monterey 2's cold call flew 122 more times, 207 → 329, for
//! 0.001 % of `J`.)
//!
//! Where the depth loop integrates, a track's least altitude has teeth in
//! the depths before it too, and a tooth's slope can have the sign
//! opposite to the trend's: the restart's linearized rows then take the
//! lift back. On `check_planner.py --seed 2991 --vehicle
//! tools/reference/vehicles/twoki.toml` (`unseen_2991_3`) track 2's least
//! altitude falls 0.35 m per metre track 1 is deepened, but its row said
//! it rises 0.19 m; the lift of track 1 by the band freed track 2 to
//! 1 135.5 m, and the restart went back to track 1 at 1 040.76 m, where
//! it had been. So where a start of the lift of track 1 (the committed
//! depth) is not kept and its horizon `J` (one plain flight) is below the
//! SQP's, the restart is made again with track 1 held at the lift
//! (kept only if it ends better; the polish of the first depth then
//! works on its teeth): the line went from 1.137× the f64 search's best
//! safe plan to 1.0013×. On the 304 random lines of BENCHMARKS.md one
//! other moves (`unseen_5031_5`, `twoki`, 0.696×, from 1.44× to 1.0028×
//! the f64 best), 4.9 flights a line more (3.4 of them on that line); the
//! 18 shared runs keep their plans and flights. (Held at any lifted
//! depth, six more lines moved, `unseen_5031_7` 1.8 % higher: a later
//! depth held at its lift is carried as the next calls' warm start and
//! stays there, and the line went from 1.0059× to 1.024× the f64 best;
//! with a free restart after the held one as well, the same.)
//!
//! The deepest useful depth is sought wherever it is deeper than that by
//! more than the gain's slack, not by the band. On `check_planner.py
//! --seed 2772 --vehicle tools/reference/vehicles/second.toml`
//! (`unseen_2772_1`) track 3, held at its target at 1 126.5 m, has its
//! deepest useful depth at 1 145.7 m, 19.2 m deeper, under the band of 20
//! m, so no such start was made. The best plan lifts track 2 by 93 m for
//! track 3 to fly at 1 169.7 m, past its own deepest useful depth: the
//! vehicle arrives deeper at the short track 4, and tracks 4 and 5 cost
//! 2.9e6 m³ less. The start from that depth ends at 1.0006× the f64
//! search's best safe plan, where the line was 1.112×. On the 304 random
//! lines of BENCHMARKS.md one line moves (by under 1e-5), 1.05 flights a
//! line more; the 18 shared runs keep their plans and flights.
//!
//! The deepest depth's start that leaves track `g + 1` more than the band
//! below its target has that track raised, as above; where that start's
//! horizon `J` is not below the SQP's, depth `g` is retreated instead: the
//! deepest depth `g` at least the band below the SQP's at which track `g +
//! 1`, at its own depth, clears its target (one flight to see that it
//! does there, then [`NARROW`](super::raise::NARROW) bisections), with the
//! least lift of depth `g − 1` that frees track `g` at that depth
//! (`NARROW` more). On `check_planner.py --seed 2724 --vehicle
//! tools/reference/vehicles/low.toml` (`unseen_2724_2`) track 2's deepest
//! useful depth, 130 m below the SQP's, left track 3 14 m below its
//! minimum altitude, and with track 3 raised the start's `J` was 2.8×
//! the SQP's; the best plan flies track 2 at 1 056 m, between, so that
//! the deep track 3 is reached from a deeper arrival. The line was
//! 1.154× the f64 search's best safe plan; retreated (track 2 at 1 069.6
//! m, track 1 lifted 147 m, `J` 0.91× the SQP's), its restart ends at
//! 0.986×. On the 304 random lines 5 move, 3 lower
//! (`unseen_5026_0`, `second`, from 1.115× the f64 best to 0.961×), none
//! higher by 1e-5, 3.8 flights a line more; the 18 shared runs keep their
//! plans, Monterey 1's cold call at 1 flight more.

use crate::optim::Bounds;
use crate::sim::{TrackScore, VehicleState};

use super::Planner;
use super::objective::{PlanObjective, Stop};
use super::scan::with_depth;
use super::solve::horizon_flight;

mod search;

use super::bottom::preferred;
use search::{Lift, Next, Starts};

/// A freed start is tried where its horizon `J` is at most this share
/// above the SQP's (module docs).
pub(super) const FREED_SHARE: f32 = 0.25;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The escape of the module docs over a horizon of `h` tracks in
    /// `bounds`, feasible within `tol` (m), after `iterations`. Returns the
    /// iterations so far. Not inlined: its state stays off the SQP runs'
    /// stack.
    #[inline(never)]
    pub(super) fn lift_earlier(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        mut iterations: u32,
    ) -> u32 {
        if !self.feasible_with_room(obj, tol, iterations) {
            return iterations;
        }
        // (A kept restart may leave an earlier track held where it was
        // not: the tracks before it are looked at again, once.)
        let (mut g, mut again) = (1, true);
        while g < h {
            let mut kept = false;
            if let Ok(starts) = self.lift_start(obj, bounds, g, tol) {
                for z in starts.iter().flatten() {
                    let restarted =
                        self.sqp_restart(obj, z, (h, bounds), (tol, 0.0, false), iterations);
                    let restarted = restarted.or_else(|| {
                        let held = self.lifts_held(obj, z, (g, bounds))?;
                        self.sqp_restart(obj, z, (h, &held), (tol, 0.0, false), iterations)
                    });
                    if let Some(total) = restarted {
                        (iterations, kept) = (total, true);
                    }
                    if iterations >= self.cfg.bfgs.max_iterations {
                        return iterations;
                    }
                }
            }
            g = if kept && again && g > 1 {
                again = false;
                1
            } else {
                g.saturating_add(1)
            };
        }
        iterations
    }

    /// For the lift of the committed depth (`g` is 1), where the depth
    /// loop integrates and the start `z`'s horizon `J` is below the SQP's
    /// (one plain flight): `bounds` with the depths before track `g` (the
    /// first) held at `z`'s, for a restart that cannot take the lift back
    /// (module docs).
    #[inline(never)]
    fn lifts_held(
        &self,
        obj: &mut PlanObjective<'_, N>,
        z: &[f32; K],
        (g, bounds): (usize, &Bounds<K>),
    ) -> Option<Bounds<K>> {
        if g != 1 || !obj.teeth() {
            return None;
        }
        // (One plain flight; a `J` that is not finite is not below.)
        let (j, _, _) = horizon_flight(obj, z).ok()?;
        (j < self.work.j).then_some(())?;
        let mut held = *bounds;
        let (lo, hi, &v) = (held.lo.first_mut()?, held.hi.first_mut()?, z.first()?);
        let v = v.max(*lo).min(*hi);
        (*lo, *hi) = (v, v);
        Some(held)
    }

    /// The restart points for later track `g`, none unless `g` is at its
    /// target (within the band's hundredth, or `tol`, m): the best start a
    /// lift of track `g − 1` finds where the horizon's `J` is lower, then
    /// the far lift's start (or the walk's along track `g`'s target),
    /// then the start at track `g`'s deepest depth, then the lift before a
    /// saturated one ([`Planner::lift_before`]; module docs). (Not inlined:
    /// its flights' state is not on the stack of the restarts that
    /// follow.)
    #[inline(never)]
    fn lift_start(
        &self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        g: usize,
        tol: f32,
    ) -> Result<Starts<K>, Stop> {
        let h_r = obj.sc.mission().reference_altitude();
        let band = h_r - obj.sc.mission().min_altitude();
        let slack = obj.held_slack_teeth(tol);
        let j = g.saturating_sub(1);
        let z = self.work.z;
        let (head, at_j) = obj.head(&z, j)?;
        let target = obj.target_of(g);
        if obj.least_at((&at_j, j), &z, g)? > target + slack {
            return Ok([None; 4]);
        }
        let (Some(&zj), Some(&zg), Some(&lo), Some(&hi)) =
            (z.get(j), z.get(g), bounds.lo.get(j), bounds.hi.get(g))
        else {
            return Ok([None; 4]);
        };
        let l = Lift {
            at_j,
            j,
            g,
            zj,
            zg,
            lo,
            target,
            band,
            slack,
            // Track `g`'s preferred depth, where it is held more than the
            // band above it.
            deep: preferred(&obj.sc, obj.track.saturating_add(g), h_r)
                .map(|p| p.min(hi))
                .filter(|&p| p > zg + band),
        };
        // (A freed start is kept within the band of feasible, as the SQP
        // left it; a start at the preferred depth may be far from it, the
        // climb saturated, and the restart's first steps close that.)
        let mut first = f32::NAN;
        let found = l.search(obj, z, false, &mut first)?;
        let (saturated, [freed, deeper, far, deep]) = l.starts(obj, z, found)?;
        // The deepest depth's start, and the freed start's deepest depth
        // `g`, with the track after `g` raised where it leaves it more than
        // the band below its target (module docs); the first also as it is
        // where it does (`short`).
        let next_lo = bounds.lo.get(g.saturating_add(1)).copied();
        let deeper = l.repaired(obj, deeper, next_lo)?;
        let [short, raised] = l.floor_start(obj, z, (h_r, hi), next_lo)?;
        // The start whose horizon `J` is lowest: a freed one (feasible
        // within the band) up to a share above the SQP's, a deep one below.
        let (sqp, loose) = (self.work.j, (1.0 + FREED_SHARE) * self.work.j);
        let starts = [
            (freed, band, loose),
            (deeper, band, loose),
            (deep, f32::INFINITY, sqp),
        ];
        let (best, deep_j) = ranked(obj, (&head, (&at_j, j)), starts, (band, loose))?;
        let walked = l.walk(obj, (z, first), (&head, sqp))?;
        let below = |obj: &mut PlanObjective<'_, N>, start: Option<[f32; K]>| match start {
            Some(start) if obj.tail_value(&head, (&at_j, j), &start)?.0 < sqp => Ok(Some(start)),
            _ => Ok(None),
        };
        let far = below(obj, far)?.or(walked);
        // The deepest depth's start with the next track raised, else with
        // depth `g` retreated (module docs).
        let mut lowest = below(obj, raised)?;
        if lowest.is_none() {
            let retreated = l.retreated(obj, short)?;
            lowest = below(obj, retreated)?;
        }
        let before = match saturated {
            Some(lift) if j > 0 && deep_j < sqp => self.lift_before(obj, bounds, &l, (z, lift))?,
            _ => None,
        };
        Ok([best, far, lowest, before])
    }

    /// The lift before a saturated one (module docs): where the lift of
    /// track `j` (`l`) saturated at `lift` (m), depth `j` of `z` lifted
    /// twice as far and track `j − 1` lifted by doubling, for track `g` at
    /// its deep depth; the start whose horizon `J` is lowest, if one is
    /// feasible within the band and at most [`FREED_SHARE`] above the
    /// SQP's. (Not inlined: its flights' state is not on the stack of the
    /// restarts that follow.)
    #[inline(never)]
    fn lift_before(
        &self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        l: &Lift<N>,
        (z, lift): ([f32; K], f32),
    ) -> Result<Option<[f32; K]>, Stop> {
        let i = l.j.saturating_sub(1);
        let (Some(&zi), Some(&lo)) = (z.get(i), bounds.lo.get(i)) else {
            return Ok(None);
        };
        let z = with_depth(&z, l.j, crate::num::max(l.zj - 2.0 * lift, l.lo));
        let (head, at_i) = obj.head(&z, i)?;
        let before = Lift {
            at_j: at_i,
            j: i,
            zj: zi,
            lo,
            ..*l
        };
        let mut first = f32::NAN;
        let (a, b) = match before.search(obj, z, false, &mut first)? {
            Next::Freed(start, deeper) => (Some(start), deeper),
            Next::Deep(lifts) | Next::Both(_, lifts) | Next::Far(lifts, _) => {
                (Some(before.narrowed(obj, z, lifts)?), None)
            }
            Next::Nothing => (None, None),
        };
        let (band, loose) = (l.band, (1.0 + FREED_SHARE) * self.work.j);
        let starts = [(a, band, loose), (b, band, loose), (None, band, loose)];
        Ok(ranked(obj, (&head, (&at_i, i)), starts, (band, loose))?.0)
    }
}

/// The start whose horizon `J` (tracks before `j` from `head`, the rest
/// flown from `at_j`) is lowest among `starts`, each with the most
/// violation it may have (m) and the `J` it must be below (m³), a start
/// within the `band` (m) of feasible below `loose` (m³) whatever its own
/// (module docs); and the last one's `J` (the deep start's; infinite
/// where there is none), m³.
fn ranked<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    (head, (at_j, j)): (&[TrackScore; K], (&VehicleState<N>, usize)),
    starts: [(Option<[f32; K]>, f32, f32); 3],
    (band, loose): (f32, f32),
) -> Result<(Option<[f32; K]>, f32), Stop> {
    let (mut best, mut last): (Option<([f32; K], f32)>, _) = (None, f32::INFINITY);
    let n = starts.len();
    for (k, (start, most, bar)) in starts.into_iter().enumerate() {
        let Some(start) = start else { continue };
        let (jz, v) = obj.tail_value(head, (at_j, j), &start)?;
        if k.saturating_add(1) == n {
            last = jz;
        }
        let bar = if v <= band { loose } else { bar };
        if v <= most && jz < best.map_or(bar, |(_, b)| b.min(bar)) {
            best = Some((start, jz));
        }
    }
    Ok((best.map(|(start, _)| start), last))
}
