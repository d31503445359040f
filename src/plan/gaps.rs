//! The certified target in the optimizer (model contract §12): under
//! declared uncertainty the SQP's horizon is raised track by track by the
//! *certification gap*, the difference between a track's least altitude
//! in the nominal flight over the map and its least altitude over the
//! worlds that sink the vehicle most, flown over the certification bottom
//! (less the vehicle margin). With the gap in its targets, the optimizer's
//! candidate is certifiable as it stands: the commit's certificate holds
//! at the first try instead of a search from an anchor, and a later call,
//! starting where this one predicted with the same gaps, finds the same
//! continuation and keeps it with its known certificate (`commit.rs`).
//!
//! A round: the candidate continuation flown in the screening worlds
//! ([`Tube::sinking`]: the sinking corners and every world that has set a
//! certificate's least altitude), the horizon flown nominally; every track
//! whose screened altitude is below the certified altitude gets its gap,
//! and the SQP re-solves from where it stopped. At most [`GAP_ROUNDS`].
//! The gaps are kept for the next calls (by track).
//!
//! What is committed is still certified in every world by the commit: the
//! gaps only aim the optimizer; where the screening misses a world, the
//! commit's certificate catches it and the search of `commit.rs` takes
//! over.

use crate::optim::Bounds;
use crate::sim::Scenario;

use super::certify::{MAX_TRACKS, Worlds};
use super::commit::{certification_bottom, nominal_only};
use super::objective::PlanObjective;
use super::{PlanError, Planner};

/// Most rounds of raising the targets in one call.
const GAP_ROUNDS: u32 = 3;

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The tube ready for screening: its screening worlds' states at the
    /// call's track (module docs); `None` when the nominal flight over
    /// the map is the certificate. Counts the flights into `obj`. Not
    /// inlined: the declared worlds' list stays off the solve's stack.
    #[inline(never)]
    fn screening(
        &mut self,
        sc: &Scenario<'_, N>,
        obj: &mut PlanObjective<'_, N>,
    ) -> Result<Option<Worlds>, PlanError> {
        let (state, track) = (*obj.start, obj.track);
        let bottom = certification_bottom(sc)?;
        self.tube.prepare_for(sc, &state, track);
        if nominal_only(sc, bottom, &self.tube, &state) {
            return Ok(None);
        }
        let mask = self.tube.sinking();
        let mut flights = 0_u32;
        self.tube
            .materialize((sc, bottom), (&state, track), (mask, &mut flights));
        obj.evaluations = obj.evaluations.saturating_add(flights);
        Ok(Some(mask))
    }

    /// Each horizon track's nominal least altitude over the map and its
    /// least altitude in the screening worlds `mask` over the
    /// certification bottom, less the margin (m, m), for the horizon `z`
    /// with the continuation beyond it; `None` when a flight fails. Not
    /// inlined: the continuation and the worlds' minima stay off the
    /// stack of the solve that follows.
    #[inline(never)]
    fn screen_gaps(
        &self,
        sc: &Scenario<'_, N>,
        obj: &mut PlanObjective<'_, N>,
        (z, h, mask): (&[f32; K], usize, Worlds),
    ) -> Result<Option<[(f32, f32); K]>, PlanError> {
        let track = obj.track;
        let bottom = certification_bottom(sc)?;
        let len = sc
            .waypoints()
            .tracks()
            .saturating_sub(track)
            .min(MAX_TRACKS);
        let shallow = sc.mission().depth_limits()[0];
        let depth = z.first().copied().unwrap_or(shallow);
        let c = self.candidate_continuation((track, len), (depth, (z, h)), shallow);
        let mut certified = [f32::INFINITY; MAX_TRACKS];
        let mut flights = 0_u32;
        let d = c.get(..len).unwrap_or(&[]);
        self.tube
            .screen(sc, bottom, d, mask, (&mut flights, &mut certified));
        obj.evaluations = obj.evaluations.saturating_add(flights);
        let Ok(nominal) = obj.flight(z) else {
            return Ok(None);
        };
        let mut out = [(f32::INFINITY, f32::INFINITY); K];
        for (o, (n, &m)) in out
            .iter_mut()
            .zip(nominal.iter().zip(certified.iter()))
            .take(h)
        {
            *o = (n.min_altitude(), m);
        }
        Ok(Some(out))
    }

    /// The first gaps of a horizon with none known yet (a cold call), from
    /// its starting point `z0`: the first solve then aims at them.
    pub(super) fn seed_gaps(
        &mut self,
        sc: &Scenario<'_, N>,
        obj: &mut PlanObjective<'_, N>,
        (z0, h): (&[f32; K], usize),
        tol: f32,
    ) -> Result<(), PlanError> {
        if obj.gaps.iter().take(h).any(|g| g.get() != 0.0) {
            return Ok(());
        }
        let Some(mask) = self.screening(sc, obj)? else {
            return Ok(());
        };
        if let Some(pairs) = self.screen_gaps(sc, obj, (z0, h, mask))? {
            for (slot, (n, m)) in obj.gaps.iter().zip(pairs.iter()).take(h) {
                let gap = n - m;
                if gap.is_finite() && gap > 0.0 {
                    slot.set(gap + tol);
                }
            }
        }
        Ok(())
    }

    /// The SQP's targets raised by the certification gaps of the horizon
    /// (module docs), re-solving from the workspace's point; `tol` is the
    /// boundary tolerance (m), `h_safe` the certified altitude (m), after
    /// the call's `iterations` so far (the workspace's count is only its
    /// last run's, where the escapes restarted). Returns the call's
    /// iterations so far. Nothing when the nominal flight over the map is
    /// the certificate.
    pub(super) fn close_gaps(
        &mut self,
        sc: &Scenario<'_, N>,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        (tol, h_safe, mut iterations): (f32, f32, u32),
    ) -> Result<u32, PlanError> {
        // (A re-solve below chains its count onto the workspace's.)
        self.work.iterations = iterations;
        let Some(mask) = self.screening(sc, obj)? else {
            return Ok(iterations);
        };
        let track = obj.track;
        for round in 0..=GAP_ROUNDS {
            let z = self.work.z;
            let Some(pairs) = self.screen_gaps(sc, obj, (&z, h, mask))? else {
                break;
            };
            let mut raised = false;
            for (t, &(n, m)) in pairs.iter().enumerate().take(h) {
                let gap = n - m;
                let Some(slot) = obj.gaps.get(t) else {
                    continue;
                };
                if m < h_safe + 0.5 * tol && gap > slot.get() {
                    slot.set(gap + tol);
                    raised = true;
                }
                if let Some(keep) = self.gaps.get_mut(track.saturating_add(t)) {
                    *keep = gap.max(0.0);
                }
            }
            if !raised || round == GAP_ROUNDS {
                break;
            }
            // Within the call's iteration cap: the re-solve gets what its
            // start (counted as one) leaves, and none runs where nothing
            // is left (the raised targets then go to the certificate as
            // they are).
            let cap = self.cfg.bfgs.max_iterations;
            let left = cap.saturating_sub(iterations).saturating_sub(1);
            if left == 0 {
                break;
            }
            self.cfg.bfgs.max_iterations = left;
            let every = u64::MAX;
            let solved = self.solve_sqp(obj, &z, (h, bounds), tol, (every, false));
            self.cfg.bfgs.max_iterations = cap;
            iterations = solved?.0;
        }
        self.horizon_len = h;
        Ok(iterations)
    }
}
