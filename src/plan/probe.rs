//! A later track held at its target where its dive ends: its least
//! altitude falls where the vehicle is still diving onto its depth, so
//! both its own depth (the longer the dive, the lower that point) and the
//! arrival (an earlier depth) move it. A few metres deeper its dive is
//! saturated over that point and the arrival alone sets it, a metre a
//! metre; the SQP's linearization at its end sees the track's own depth
//! moving it most, so it does not trade a sliver of the earlier depth for
//! a deeper later one. On `check_planner.py --seed 2782 --vehicle
//! tools/reference/vehicles/integ.toml` (`unseen_2782_5`) the cold SQP
//! ended with track 2 at its target at 678.3 m, its row moved −0.57 m/m
//! by its own depth and −0.46 m/m by track 1's; 5 m deeper it is 0.17 m
//! short, set by track 1 alone, and the best safe plan lifts track 1 by
//! 0.12 m so that track 2 flies 21 m deeper. The line's `J` was 1.16×
//! the f64 search's best safe plan.
//!
//! The escape: where the workspace's last kept SQP run ended with such a
//! row (`Linearized::blended`: active, moved at least a tenth of a metre
//! a metre by its own depth and by an earlier one), the track is probed
//! [`PROBE`] of the band `h_r − h_a` deeper (one flight) and, where the
//! probe's `J` is lower and its shortfall summed at most [`SHORT`] of the
//! band, the SQP is restarted from it (kept if it ends better): its first
//! step restores the shortfall with the earlier depth. `unseen_2782_5`
//! goes to 1.065× (the next call stops short of the best plan's track 2,
//! held by track 4). It runs in the cold call's escapes after the sink
//! (`wider.rs`). On the 267 random lines 30 move, 23 lower (to 0.94×,
//! `unseen_3103_6`) and 7 higher by at most 0.14 % (`unseen_3129_0`),
//! 9.6 flights a line more (2.5 %); the 18 shared runs keep their plans
//! and flights but Medes 1 (+6 flights in the cold call) and Medes 2 (+4,
//! its `J` 4e-5 lower). Tried and not kept: the probe the band deeper
//! (1.2 m short there, where track 4 falls short too, and the restart's
//! line search fails); every held track probed, whatever its row (the
//! rows of Monterey 1's held tracks are a dive's plateau or settled, and
//! their two probes cost its cold call 3 flights, 9.3 M instructions on
//! the M4F, past 250 M); the probe after every call's SQP, warm ones too
//! (+21 flights a line, two lines 1.0 % and 1.6 % higher).

use crate::optim::Bounds;
use crate::optim::constrained::group_bit;

use super::Planner;
use super::objective::{PlanObjective, Stop};
use super::scan::with_depth;

/// How far deeper a held track is probed, a share of the band.
const PROBE: f32 = 0.25;

/// A probe is restarted from where its shortfall summed is at most this
/// share of the band `h_r − h_a`.
const SHORT: f32 = 0.25;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The escape of the module docs for the later tracks whose least
    /// altitude's row was in transition where the last kept SQP run ended
    /// (`Linearized::blended`), over a horizon of `h` tracks in `bounds`,
    /// feasible within `tol` (m), after `iterations`. Returns the
    /// iterations so far.
    pub(super) fn probe_deeper(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        mut iterations: u32,
    ) -> u32 {
        for g in 1..h {
            if group_bit(g).is_none_or(|b| self.blended & b == 0) {
                continue;
            }
            if !self.feasible_with_room(obj, tol, iterations) {
                break;
            }
            let z = match self.probe_start(obj, bounds, g) {
                Ok(Some(z)) => z,
                Ok(None) => continue,
                Err(_) => break,
            };
            iterations = self
                .sqp_restart(obj, &z, (h, bounds), (tol, 0.0, false), iterations)
                .unwrap_or(iterations);
        }
        iterations
    }

    /// The workspace with later track `g` [`PROBE`] of the band deeper, in
    /// `bounds`, where its flight's `J` is lower and its shortfall summed
    /// at most [`SHORT`] of the band (one flight). (Not inlined: its
    /// flight's scores are not on the stack of the restart that follows.)
    #[inline(never)]
    fn probe_start(
        &self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        g: usize,
    ) -> Result<Option<[f32; K]>, Stop> {
        let m = obj.sc.mission();
        let band = m.reference_altitude() - m.min_altitude();
        let (Some(&zg), Some(&hi)) = (self.work.z.get(g), bounds.hi.get(g)) else {
            return Ok(None);
        };
        if zg + PROBE * band > hi {
            return Ok(None);
        }
        let probe = with_depth(&self.work.z, g, zg + PROBE * band);
        let flown = obj.flight(&probe)?;
        let (j, v) = obj.value_of(&flown)?;
        Ok((v <= SHORT * band && j < self.work.j).then_some(probe))
    }
}
