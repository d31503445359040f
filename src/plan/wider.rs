//! A cold horizon whose SQP ended infeasible, or feasible with a track
//! held far above its bottom, started again from a wider beam.
//!
//! The beam scan (`scan.rs`) keeps two paths per track. A vehicle with
//! little pitch authority (3 m/s and 15° on a random canyon line,
//! `check_planner.py --seed 71 --vehicle`) saturates every track's dive or
//! climb, so every depth after the first has exactly zero gradient; from a
//! start infeasible by 279 m summed the SQP restored feasibility with the
//! one depth that moves anything, the first (394 → 133 m; 399.5 m in the
//! f64 best), and the line's `J` was 2.04× the best safe. Where the SQP
//! ends infeasible, the scan runs again with a wider beam and the SQP
//! restarts from its best path, kept if it ends better (feasible, or less
//! infeasible). A feasible end costs nothing, nor does a call whose first
//! track has no safe scanned depth (Monterey 3). Under declared
//! uncertainty only an end infeasible by more than `h_r − h_a` summed
//! restarts: the usual end there misses its certification gaps or the
//! later tracks' margin by less (Monterey 2 certified). Without it, any
//! infeasible end does (it restarted only past the band before): on
//! `check_planner.py --seed 2409 --vehicle
//! tools/reference/vehicles/integ.toml` (`unseen_2409_6`) the cold SQP
//! stopped after one iteration 16.9 m short summed, its depths on a
//! saturated dive's plateau, and the line's `J` was 1.52× the f64
//! search's best safe plan; restarted from the wide beam, 1.0006×. On the
//! 256 random lines of the earlier rounds no plan moves, at 6.1 more
//! evaluations a line (lines with no safe plan restart in vain); the 24
//! shared runs give the same JSON.
//!
//! A feasible end can be as far from the best: on `check_planner.py --seed
//! 2009 --vehicle tools/reference/vehicles/low.toml` (`unseen_2009_2`)
//! the two-path beam started 3.4× above the f64 search's best safe plan,
//! and the SQP ended with track 3 flying 322 m above its bottom at its
//! lowest (`h_r` 40 m), track 4 diving and track 5 climbing at the pitch
//! limit: the line 1.68× the best after the other escapes. So the wide
//! beam also runs where a feasible end (one more plain flight) has a
//! track whose least altitude is above [`HELD`] times `h_r`: held far
//! above its bottom, by the depths around it rather than by its own. It
//! ends at 0.74× there, and `unseen_2005_6` (`--seed 2005`, `rate`
//! vehicle: two tracks at 1.55 `h_r`) goes from 1.26× to 1.0009×. Not
//! under declared uncertainty, where Monterey 1's certified cold call has
//! such a track and the restart, which gained nothing, cost it 163
//! evaluations. On the 256 random lines of the earlier rounds, at twice
//! `h_r` 53 lines run it and 10 move (`unseen_1403_7` 0.78×,
//! `unseen_1201_7` 0.992×, `unseen_1403_2` 0.995×; `unseen_1203_6`
//! 1.017×, still within the checker's bound), 33 more evaluations a line;
//! at 1.5 `h_r` 73 lines run it, 13 move (the same 10, and 3 by less than
//! a millionth), 46 more evaluations a line, and Monterey 3's cold call at
//! track 3 (its plan the same) flies 92 more. (Run after every feasible
//! end, 5 moved, for about 150 evaluations a line, and Monterey 1's cold
//! call doubled for the same plan.) The held track's restart runs after
//! the lift and the held edge, which run again from it where it is kept
//! ([`Planner::cold_escapes`]).
//!
//! The same restart runs where a feasible end's first depth has no
//! gradient at all (a saturated dive or climb through its whole track):
//! the SQP cannot move it, and the plateau escape (`jump/`) moves it
//! with the later depths held. On `check_planner.py --seed 2638 --vehicle
//! tools/reference/vehicles/integ.toml` (`unseen_2638_7`) track 1 kept
//! the scan's 768.7 m through every iteration, where the best safe plan
//! flies it at 697 m (1.9 % higher on its own) so that track 2 can dive
//! 229 m deeper: 1.78× the f64 search's best safe `J`; restarted,
//! 0.996×. On the 267 random lines it runs on 13 more lines and moves
//! none, for 7.4 flights a line (2 % of the horizon mode's); the 18
//! shared runs keep their plans and flights.
//!
//! Where the end is infeasible the beam keeps [`BEAM_WIDE`] paths, where
//! it has a held track or a first depth without gradient [`BEAM_HELD`]. On
//! `check_planner.py --seed 2324 --vehicle
//! tools/reference/vehicles/integ.toml` (`unseen_2324_6`) the cold SQP
//! ended 13.9 m short summed, under the band, with tracks 2 and 3 held
//! 210 m above their bottom by a saturated dive: the held track's
//! four-path beam (the only restart then) started 122 m short and was
//! dropped, and the line's `J` was 3.08× the f64 search's best safe plan
//! (track 1 at 744 m, where the best plan dives to 983 m). Eight paths
//! start feasible (5.045e7 m³), and the line ends at 1.003×.
//!
//! A feasible restart is kept over an infeasible end whatever its `J`,
//! and the end may have been a little short near the best safe plan.
//! After the wide beam, an end that was short by at most the band `h_r −
//! h_a` summed is repaired as a short restart is (`restart.rs`: each
//! short track raised by its shortfall, at most four plain flights) and
//! the SQP restarted from there, careful, kept if it ends better. On
//! `check_planner.py --seed 2910 --vehicle
//! tools/reference/vehicles/twoki.toml` (`unseen_2910_0`) the cold SQP's
//! line search failed at 5.76e6 m³ with track 2 0.78 m short; the wide
//! beam's restart ended feasible at 7.17e6 m³, and the line's `J` was
//! 1.38× the f64 search's best safe plan; repaired, 1.02×. On `--seed
//! 2815 --vehicle tools/reference/vehicles/slow.toml` (`unseen_2815_0`)
//! the cold end was 0.11 m short, the wide beam's restart no better, and
//! the call owed its escapes to the next (1.18×); repaired, the lift runs
//! from a feasible end, 1.0008×. On the 267
//! random lines no plan moves, at 0.4 flights a line; the 18 shared runs
//! keep their plans and flights (Monterey 3's cold end is short by more
//! than the band).

use crate::optim::Bounds;

use super::Planner;
use super::flights::Flights;
use super::objective::PlanObjective;
use super::restart::{repaired, repaired_across};
use super::scan::{BEAM_HELD, BEAM_WIDE, ScanLog, ScanSpec, scan_start};

/// A track of a feasible SQP end whose least altitude is above this many
/// times `h_r` is held (module docs).
const HELD: f32 = 1.5;

/// The share of the horizon's `J` where the lift first ran below which
/// the escapes' end has the lift and the held edge run again. At 0.8, on
/// `make_lines.py`'s `unseen_5012_2` (`integ`, seed 5012) the held edge
/// took `J` from 1.90e6 to 1.58e6 m³ (0.83×) with track 2 now held by
/// track 1, which the lift had not seen held (10 m above its target when
/// it ran): the line 1.2165× the f64 best safe plan; at 0.9 the lift runs
/// again, lifts track 1 56 m, and the line is 1.0125×. On the 304 lines
/// that one moves, ten run the lift again (+2.8 flights a line), and the
/// 18 shared runs keep their plans and flights.
const AGAIN: f32 = 0.9;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// A cold call's escapes after its SQP, in order: the wide beam where
    /// the SQP ended infeasible by more than the band; then, without
    /// declared uncertainty, the short end repaired (module docs), the
    /// lift (`lift/`) and the held edge (`jump/`, `held_last`); then the
    /// sink (`sink.rs`); then the probe of a held track whose dive ends
    /// (`probe.rs`); then the dive begun earlier and the first track's
    /// dive taken to its boundary (`dive.rs`); then the wide beam where a
    /// track of that end is held far above its bottom or its first depth
    /// has no gradient, and where
    /// that restart is kept, the lift and the held edge again from it;
    /// then the first depth's stride (`stride.rs`); then, where the depth
    /// loop integrates, the SQP on secant rows (`restart.rs`,
    /// `secant_restart`); last, where those took the horizon's `J` below
    /// [`AGAIN`] of where the lift first ran, the lift and the held edge
    /// once more (`lift/`' module docs), and where those moved the end,
    /// the secant rows once more from it: on `check_planner.py --seed 3175
    /// --vehicle tools/reference/vehicles/rate.toml` (`unseen_3175_6`) the
    /// last lift's restart on tangent rows ended with a track held by the
    /// depth before it, whose least altitude falls across the
    /// integrator's switches as that depth deepens and rises between
    /// them: the line 1.0176× the f64 search's best safe plan; after,
    /// 1.0039×. On the 304 random lines two run it (+0.2 flights a line),
    /// one moves (+0.008 %); the 18 shared runs keep their plans. (The held track's restart
    /// first ran before the lift, kept where it beat the SQP's end: on
    /// `check_planner.py --seed 2002 --vehicle
    /// tools/reference/vehicles/integ.toml`, `unseen_2002_0`, it took
    /// track 1 from 453 m to 152 m for 5 % of the horizon's `J`, where
    /// the lift from the SQP's end finds 42 % less: the line went from
    /// 1.0009× to 1.63× the f64 search's best safe `J`.) Arguments as
    /// [`Planner::wider_start`]'s; returns the iterations so far.
    ///
    /// A cold call that ends infeasible (beyond `tol`) runs only the first
    /// of them (the others start from a feasible end), and owes them to
    /// the next call, which runs them from its own end (`Warm::escapes`),
    /// and so on until a call ends feasible. On `check_planner.py --seed
    /// 2534 --vehicle tools/reference/vehicles/second.toml`
    /// (`unseen_2534_4`) the cold call ended infeasible within the band
    /// and the warm calls kept its continuation: 1.20× the f64 best safe
    /// `J`; the second call's held edge takes it to 1.0003×. On 267 random
    /// lines 17 move, none higher (13 of them lines with no safe plan
    /// found either way), 11.6 flights a line more; the 18 shared runs
    /// the same plans and flights (their cold calls end feasible). None
    /// where they are not `due` (a warm call owed nothing).
    pub(super) fn cold_escapes(
        &mut self,
        (obj, fl, scan): (&mut PlanObjective<'_, N>, &mut Flights<'_, '_, N>, &ScanLog),
        (h, bounds, mu): (usize, &Bounds<K>, f32),
        (tol, h_safe, iterations): (f32, f32, u32),
        due: bool,
    ) -> u32 {
        if !due {
            return iterations;
        }
        let at = (tol, h_safe, iterations);
        // The SQP's end where it is short of its targets (module docs).
        let v = obj.last_violation;
        let short = (v > tol).then_some((self.work.z, v));
        let mut iterations = self
            .wider_start((obj, fl, scan), (h, bounds, mu), at, false)
            .unwrap_or(iterations);
        // (Not under declared uncertainty: there every later track's
        // target is `h_a + m_s`, most of them are at it, and the
        // escape's restarts cost Monterey 1's certified cold call
        // +27 %, the line over its 800 M instructions: BENCHMARKS.md.)
        if obj.declared() {
            return iterations;
        }
        if let Some(end) = short {
            iterations = self.repair_short(obj, end, (h, bounds), tol, iterations);
        }
        let lifted_at = self.work.j;
        iterations = self.lift_then_held(obj, (h, bounds), tol, iterations);
        iterations = self.sink_earlier(obj, (h, bounds), tol, iterations);
        iterations = self.probe_deeper(obj, (h, bounds), tol, iterations);
        iterations = self.dive_earlier(obj, (h, bounds), tol, iterations);
        iterations = self.dive_first(obj, scan, (h, bounds), tol, iterations);
        let at = (tol, h_safe, iterations);
        let iterations = match self.wider_start((obj, fl, scan), (h, bounds, mu), at, true) {
            Some(it) => self.lift_then_held(obj, (h, bounds), tol, it),
            None => iterations,
        };
        let iterations = self.stride_first(obj, (h, bounds), tol, iterations);
        let iterations = self.secant_restart(obj, (h, bounds), tol, iterations);
        // The lift and the held edge once more where the escapes took `J`
        // well below where they ran (module docs of `lift/`).
        if self.work.j < AGAIN * lifted_at {
            let before = self.work.j;
            let iterations = self.lift_then_held(obj, (h, bounds), tol, iterations);
            // Where that moved the end, the secant restart once more from
            // it (where the depth loop integrates: the module docs).
            if self.work.j < before {
                return self.secant_restart(obj, (h, bounds), tol, iterations);
            }
            return iterations;
        }
        iterations
    }

    /// The SQP's `end` that fell short of its targets by `v` (m, summed),
    /// each short track raised by its shortfall (`restart.rs`,
    /// `repaired`), and the SQP restarted from there, careful, kept if it
    /// ends better (module docs): where `v` is within the band `h_r −
    /// h_a`. Returns the iterations so far.
    fn repair_short(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (end, v): ([f32; K], f32),
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        iterations: u32,
    ) -> u32 {
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        if v > band || iterations >= self.cfg.bfgs.max_iterations {
            return iterations;
        }
        // (Where the depth loop integrates, by an earlier depth too.)
        let mut z = repaired(obj, &end, bounds, tol);
        if z.is_none() && obj.teeth() {
            z = repaired_across(obj, &end, bounds, tol);
        }
        let Some(z) = z else {
            return iterations;
        };
        let again = self.sqp_restart(obj, &z, (h, bounds), (tol, 0.0, true), iterations);
        again.unwrap_or(iterations)
    }

    /// The lift (`lift/`), then the held edge (`jump/`, `held_last`),
    /// after `iterations` so far; returns the iterations so far.
    fn lift_then_held(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        iterations: u32,
    ) -> u32 {
        let iterations = self.lift_earlier(obj, (h, bounds), tol, iterations);
        self.held_last(obj, (h, bounds), tol, iterations)
    }

    /// The second start of the module docs for a cold call's horizon of
    /// `h` tracks in `bounds` (penalty weight `mu` for the scan), feasible
    /// within `tol` (m), `scan` the first track's scanned depths and
    /// `h_safe` the certified altitude (m), after `iterations` so far:
    /// where the end is infeasible, or (`held`) has a held track or a
    /// first depth without gradient. Returns
    /// the iterations so far where the restart is kept. Not inlined: the
    /// scan's state stays off the SQP's stack.
    #[inline(never)]
    pub(super) fn wider_start(
        &mut self,
        (obj, fl, scan): (&mut PlanObjective<'_, N>, &mut Flights<'_, '_, N>, &ScanLog),
        (h, bounds, mu): (usize, &Bounds<K>, f32),
        (tol, h_safe, iterations): (f32, f32, u32),
        held: bool,
    ) -> Option<u32> {
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        // (No scanned depth of the first track safe: no start makes the
        // call feasible; Monterey 3.)
        let first_safe = scan.iter().any(|(_, least)| least >= h_safe);
        if !first_safe || iterations >= self.cfg.bfgs.max_iterations {
            return None;
        }
        // (An infeasible end is the first restart's, a feasible one the
        // held track's: never the same beam twice.)
        let (start, width) = if held {
            let v = obj.last_violation;
            let flat = self.work.gradient.first() == Some(&0.0);
            (v <= tol && (flat || self.held_high(obj, h)), BEAM_HELD)
        } else {
            let over = if obj.declared() { band } else { tol };
            (obj.last_violation > over, BEAM_WIDE)
        };
        if !start {
            return None;
        }
        let spec = ScanSpec {
            bounds,
            from: 0,
            h,
            points: self.cfg.scan_points,
            mu,
            beam: true,
            width,
        };
        let z = wide_scan(fl, &spec)?;
        self.sqp_restart(obj, &z, (h, bounds), (tol, 0.0, false), iterations)
    }
}

impl<const K: usize, const N: usize> Planner<K, N> {
    /// Whether a track of the SQP's end (one plain flight of its `h`
    /// tracks) flies, at its lowest, more than [`HELD`] times `h_r` above
    /// the bottom (module docs). (Only asked without declared
    /// uncertainty: `cold_escapes` returns before it.)
    fn held_high(&self, obj: &mut PlanObjective<'_, N>, h: usize) -> bool {
        let high = HELD * obj.sc.mission().reference_altitude();
        obj.flight(&self.work.z)
            .is_ok_and(|s| s.iter().take(h).any(|t| t.min_altitude() > high))
    }
}

/// The wide beam's start, if the scan flies. Not inlined: its log stays
/// off the stack of the SQP that follows.
#[inline(never)]
fn wide_scan<const K: usize, const N: usize>(
    fl: &mut Flights<'_, '_, N>,
    spec: &ScanSpec<'_, K>,
) -> Option<[f32; K]> {
    let (mut z, mut curvature) = (spec.bounds.lo, [0.0; K]);
    let mut log = ScanLog::default();
    scan_start(fl, spec, &mut z, &mut curvature, &mut log).ok()?;
    Some(z)
}
