//! A cold horizon whose SQP ended infeasible, started again from a wider
//! beam.
//!
//! The beam scan (`scan.rs`) keeps two paths per track. A vehicle with
//! little pitch authority (3 m/s and 15° on a random canyon line,
//! `check_planner.py --seed 71 --vehicle`) saturates every track's dive or
//! climb, so every depth after the first has exactly zero gradient; from a
//! start infeasible by 279 m summed the SQP restored feasibility with the
//! one depth that moves anything, the first (394 → 133 m; 399.5 m in the
//! f64 best), and the line's `J` was 2.04× the best safe. Where the SQP
//! ends infeasible by more than `h_r − h_a` summed, the scan runs again
//! with [`BEAM_WIDE`] paths and the SQP restarts from its best path, kept
//! if it ends better (feasible, or less infeasible). A feasible end costs
//! nothing, nor does the usual infeasible end, a plan that misses its
//! certification gaps or the later tracks' margin by less (Monterey 2
//! certified), or a call whose first track has no safe scanned depth
//! (Monterey 3).

use crate::optim::Bounds;

use super::Planner;
use super::flights::Flights;
use super::objective::PlanObjective;
use super::scan::{BEAM_WIDE, ScanLog, ScanSpec, scan_start};

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The second start of the module docs for a cold call's horizon of
    /// `h` tracks in `bounds` (penalty weight `mu` for the scan), feasible
    /// within `tol` (m), `scan` the first track's scanned depths and
    /// `h_safe` the certified altitude (m), after `iterations` so far.
    /// Returns the iterations so far. Not inlined: the scan's state stays
    /// off the SQP's stack.
    #[inline(never)]
    pub(super) fn wider_start(
        &mut self,
        (obj, fl, scan): (&mut PlanObjective<'_, N>, &mut Flights<'_, '_, N>, &ScanLog),
        (h, bounds, mu): (usize, &Bounds<K>, f32),
        (tol, h_safe, iterations): (f32, f32, u32),
    ) -> u32 {
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        // (No scanned depth of the first track safe: no start makes the
        // call feasible; Monterey 3.)
        let first_safe = scan.iter().any(|(_, least)| least >= h_safe);
        if obj.last_violation <= band || !first_safe || iterations >= self.cfg.bfgs.max_iterations {
            return iterations;
        }
        let spec = ScanSpec {
            bounds,
            from: 0,
            h,
            points: self.cfg.scan_points,
            mu,
            beam: true,
            width: BEAM_WIDE,
        };
        let Some(z) = wide_scan(fl, &spec) else {
            return iterations;
        };
        self.sqp_restart(obj, &z, (h, bounds), (tol, 0.0, false), iterations)
            .unwrap_or(iterations)
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
