//! The continuation search: the last certified point on the straight
//! path from a certified anchor towards the candidate continuation, then
//! on the second leg that moves the committed depth alone towards the
//! candidate's ([`super::commit`] calls it when the candidate does not
//! certify).

use crate::model::ProfileView;
use crate::optim::root::{self, RootTol};
use crate::sim::{Scenario, VehicleState};

use super::candidate::Candidate;
use super::certify::Certificate;
use super::chosen::Chosen;
use super::fallback::{Flown, fly_committed};
use super::planner::MAX_TRACKS;
use super::{PlanError, Planner};

/// The certified-altitude tolerance of the continuation search, m (as the
/// single track's boundary search: 0.2 % of `h_r − h_a`, 1 mm to 2 cm).
const SEARCH_SHARE: f32 = 0.002;

/// The search stops when the step along the path is this short (of 1).
const SEARCH_WIDTH: f32 = 1e-3;

/// Most rounds of the continuation search (a round: a root search in the
/// critical worlds, then the point found certified in every world).
const SEARCH_ROUNDS: u32 = 4;

/// The search path's ends: the certified anchor and the candidate, each
/// with its certificate.
type Ends<'c, const N: usize> = (
    (&'c [f32; MAX_TRACKS], Certificate),
    (&'c [f32; MAX_TRACKS], Certificate),
);

/// A search bracket: the safe end and the unsafe one, each a point on the
/// path (of 1) with its certified margin over `h_safe`, m.
type Bracket = ((f32, f32), (f32, f32));

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The last certified point on the path `a + t (c − a)`, `t ∈ [0, 1]`,
    /// from the certified anchor `a` towards the candidate `c`.
    ///
    /// The root search flies only the *critical* worlds (those that have
    /// set a certificate's least altitude, [`Tube::critical`]): their
    /// least altitude bounds the certificate from above, so a point they
    /// reject is rejected. The point found is then certified in every
    /// world; if another world rejects it, that world becomes critical, the
    /// point becomes the bracket's unsafe end and the search goes on (at
    /// most [`SEARCH_ROUNDS`] rounds, then the last certified point).
    pub(super) fn search(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        ((a, cert_a), (c, cert_c)): Ends<'_, N>,
        len: usize,
        h_safe: f32,
        flights: &mut u32,
    ) -> Chosen<N> {
        // (Continuations in place: each is a quarter of a kilobyte of stack.)
        let at = |t: f32, out: &mut [f32; MAX_TRACKS]| crate::num::between_into(a, c, t, out);
        let mut d = [0.0; MAX_TRACKS];
        let m = sc.mission();
        let rule = RootTol {
            tol: (SEARCH_SHARE * (m.reference_altitude() - m.min_altitude())).clamp(1e-3, 0.02),
            width: SEARCH_WIDTH,
            steps: self.cfg.bisection_steps,
        };
        let mut good = (0.0, cert_a);
        let mut bad = (1.0, cert_c.all - h_safe);
        for _ in 0..SEARCH_ROUNDS {
            let ends = ((good.0, good.1.all - h_safe), bad);
            let ends = (ends, h_safe);
            let Some((t, screened)) =
                self.screened_root(sc, bottom, (&at, len), ends, rule, flights)
            else {
                break;
            };
            // (Every world flown already when all are critical.)
            let cert = if screened.partial {
                if !self.budget.afford(*flights) {
                    break;
                }
                at(t, &mut d);
                let d = d.get(..len).unwrap_or(&[]);
                self.tube.certify(sc, bottom, d, (h_safe, &mut *flights))
            } else {
                screened
            };
            if cert.all >= h_safe {
                good = (t, cert);
                break;
            }
            bad = (t, cert.all - h_safe);
        }
        if good.0 > 0.0 {
            at(good.0, &mut d);
        } else {
            d = *a;
        }
        Chosen {
            searched: true,
            ..Chosen::new(d, len, good.1)
        }
    }

    /// A second leg after [`Planner::search`] stopped short of the
    /// candidate: from the point found, the committed depth alone
    /// towards the candidate's, the later depths held (the straight path
    /// moves them all, and a later depth is often what stopped it, while
    /// the next call re-plans the later tracks anyway). Monterey 1 with a
    /// two-track horizon: `J` 3.04e7 by the straight path alone, 1.46e7.
    pub(super) fn search_committed(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        found: Chosen<N>,
        cand: &Candidate<N>,
        flights: &mut u32,
    ) -> Chosen<N> {
        let (to, len) = (cand.flown.depth, found.len);
        // With a horizon of one track the candidate's depth is myopic (it
        // never saw the next track): only the straight path then.
        let reached = found
            .depths
            .first()
            .is_none_or(|z| z.to_bits() == to.to_bits());
        if reached || len < 2 || self.horizon_len < 2 {
            return found;
        }
        let mut target = found.depths;
        if let Some(z) = target.first_mut() {
            *z = to;
        }
        let d = target.get(..len).unwrap_or(&[]);
        let cert_t = self.certify_within(sc, bottom, d, (cand.h_safe, &mut *flights), 0);
        if cert_t.all >= cand.h_safe {
            return Chosen {
                depths: target,
                cert: cert_t,
                ..found
            };
        }
        let ends = ((&found.depths, found.cert), (&target, cert_t));
        self.search(sc, bottom, ends, len, cand.h_safe, flights)
    }

    /// The previous call's continuation in place of a searched one
    /// (`chosen`) whose horizon `J` (Σ of the horizon's tracks, one
    /// nominal flight each) is above the continuation's, where that
    /// continuation certifies (every world flown, the candidate's
    /// `h_safe`), with its committed depth's nominal flight (`flown`).
    /// The search takes the last certified point on its path, which can
    /// lie far from any good one: towards the climb, the later tracks near
    /// the surface (`unseen_3030_2`, BENCHMARKS.md, round 35). Unbudgeted
    /// calls only (a budgeted one keeps its flights for its fallback). Not
    /// inlined: its frame stays off the search's stack.
    #[inline(never)]
    pub(super) fn anchor_if_cheaper(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        (state, track): (&VehicleState<N>, usize),
        (cand, chosen, flown): (&Candidate<N>, &mut Chosen<N>, &mut Flown<N>),
        flights: &mut u32,
    ) -> Result<(), PlanError> {
        let (len, h_safe) = (chosen.len, cand.h_safe);
        let shallow = sc.mission().depth_limits()[0];
        let a = match self.previous_continuation(track, len, shallow) {
            Some(a) if chosen.searched && self.budget.limit == u32::MAX => a,
            _ => return Ok(()),
        };
        let mut same = a.iter().zip(&chosen.depths).take(len);
        if same.all(|(x, y)| x.to_bits() == y.to_bits()) {
            return Ok(());
        }
        let at = (state, track);
        let j_a = self.horizon_j(sc, at, (&a, len), flights);
        let j_c = self.horizon_j(sc, at, (&chosen.depths, len), flights);
        let (Some(j_a), Some(j_c)) = (j_a, j_c) else {
            return Ok(());
        };
        if j_a >= j_c {
            return Ok(());
        }
        let d = a.get(..len).unwrap_or(&[]);
        let cert = self.tube.certify(sc, bottom, d, (h_safe, flights));
        if cert.all < h_safe || cert.partial {
            return Ok(());
        }
        *chosen = Chosen {
            searched: true,
            ..Chosen::new(a, len, cert)
        };
        *flown = fly_committed(sc, (state, track), a[0], cand.flown, flights)?;
        Ok(())
    }

    /// One round of [`Planner::search`]: the boundary of the critical
    /// worlds' certificate between `good` and `bad` (`t` with its margin
    /// over `h_safe`, m) with that certificate, or `None` where it did not
    /// move off `good`.
    fn screened_root<F: Fn(f32, &mut [f32; MAX_TRACKS])>(
        &self,
        sc: &Scenario<'_, N>,
        bottom: ProfileView<'_>,
        (at, len): (&F, usize),
        ((good, bad), h_safe): (Bracket, f32),
        rule: RootTol,
        flights: &mut u32,
    ) -> Option<(f32, Certificate)> {
        let budget = self.budget;
        let mask = self.tube.critical();
        let mut d = [0.0; MAX_TRACKS];
        let r = root::safe_boundary((good.0, Some(good.1)), (bad.0, Some(bad.1)), rule, |t| {
            if !budget.afford(*flights) {
                return Err(());
            }
            at(t, &mut d);
            let d = d.get(..len).unwrap_or(&[]);
            let cert = self.tube.certify_only(sc, bottom, d, mask, flights);
            Ok::<_, ()>((cert.all - h_safe, cert))
        });
        let root = r.ok()?;
        root.at.filter(|_| root.z > good.0).map(|c| (root.z, c))
    }
}
