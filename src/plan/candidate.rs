//! The candidate of one call: the track's depth as the optimizer (or the
//! scan, or the boundary search) finds it for the horizon, in steps that
//! each live in their own function: set-up (horizon, penalty, box), the
//! starting point (warm start and scan), the single-track decision, the
//! penalized solve with its plateau escape, verification and fallback.
//! What is committed, and how safe it is, is `commit.rs`'s.

use core::cell::Cell;

use crate::optim::Bounds;
use crate::sim::{Scenario, TrackScore, VehicleState};

use super::certify::Certificate;
use super::fallback::{Flown, closest_safe};
use super::flights::Flights;
use super::objective::PlanObjective;
use super::planner::Warm;
use super::scan::{BEAM, ScanLog, ScanSpec, scan_start, search_box};
use super::single::{self, Decision};
use super::solve::{Merge, ScannedAt, later_margin};
use super::status::{Found, OptimizerStop};
use super::{Method, Mode, PlanError, Planner};

/// First step of a warm-started solve, relative to `first_step`.
const WARM_FIRST_STEP: f32 = 0.1;

/// The SQP's segments further above the target than `h_r − h_a` or this,
/// whichever is more (m), stay out of its step.
const SQP_BAND: f32 = 4.0;

/// The tolerance of a boundary (m): 0.2 % of `h_r − h_a` (m), 1 mm to 2 cm.
pub(super) fn boundary_tolerance(span: f32) -> f32 {
    (0.002 * span).clamp(1e-3, 0.02)
}

/// What one call works with, fixed at its start.
pub(super) struct Setup<const K: usize> {
    /// Tracks optimized jointly.
    pub h: usize,
    warm: Option<Warm<K>>,
    /// Penalty weight of the first stage (0: unconstrained).
    mu: f32,
    pub bounds: Bounds<K>,
    /// Certified altitude `h_a + m_s`, m.
    pub h_safe: f32,
}

/// The call's candidate for its track.
#[derive(Clone, Copy, Debug)]
pub(super) struct Candidate<const N: usize> {
    /// The track's depth with its nominal flight.
    pub flown: Flown<N>,
    /// How it was found.
    pub found: Found,
    pub iterations: u32,
    /// Flights so far.
    pub evaluations: u32,
    /// `h_a + m_s`, m.
    pub h_safe: f32,
    /// The continuation's certificate when already known (a budgeted
    /// call's fallback, `budget.rs`).
    pub cert: Option<Certificate>,
    /// `Σ J` over the horizon of the previous call's continuation, when
    /// the optimizer started from it (m³).
    pub previous_j: Option<f32>,
}

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The call's candidate for `track` from `state`: the optimized (or
    /// scanned, or boundary) depth of the track with its nominal flight,
    /// moved off its waypoint's knife edge (`knife.rs`), the rest of the
    /// horizon in the workspace, and the warm start kept.
    pub(super) fn candidate(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
    ) -> Result<Candidate<N>, PlanError> {
        let mut c = self.candidate_aimed(sc, state, track)?;
        // (What the commit certifies against: the certified altitude, or
        // a single track's floor set by its arrival, `single.rs`.)
        c.h_safe = c.h_safe.min(self.cfg.certified_altitude(sc.mission()));
        self.off_the_edge(sc, state, track, &mut c);
        self.off_the_edge_ahead(sc, state, track, &mut c);
        Ok(c)
    }

    /// [`Planner::candidate`], a single track aimed above the certified
    /// altitude by its certification gap (`gaps.rs`) when the call is
    /// unbudgeted: the boundary it finds is then the certified one.
    fn candidate_aimed(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
    ) -> Result<Candidate<N>, PlanError> {
        let mut s = self.setup(sc, state, track)?;
        if s.h == 1 && self.cfg.constrained && self.budget.limit == u32::MAX {
            s.h_safe += self.gaps.get(track).copied().unwrap_or(0.0);
        }
        let penalized = self.penalized(sc, s.h);
        let mut fl = Flights {
            sc: penalized,
            state,
            track,
            count: 0,
            limit: self.budget.candidate,
        };
        let mut scan = ScanLog::default();
        let (mut z0, mut curvature, from) = self.start_point(&s, &mut fl, &mut scan)?;
        // One track, constrained, scanned: the scan may decide it (module
        // docs of `single`); it is then optimized without the penalty.
        let single = s.h == 1 && self.cfg.constrained && from == 0 && !scan.is_empty();
        if single
            && let Some(done) =
                self.single_decision(&mut fl, &scan, &s, (&mut z0, &mut curvature))?
        {
            return Ok(done);
        }
        if self.cfg.method == Method::Bfgs && s.h >= 2 {
            return self.sqp_candidate(sc, &s, (&mut fl, &mut scan), (penalized, &z0));
        }
        let mu = if single { 0.0 } else { s.mu };
        let mut obj = PlanObjective::new(penalized, state, track, s.h, mu);
        obj.guard = single.then_some(s.h_safe);
        obj.budget = self.budget.optimizer(fl.count)?;
        let first_step = if s.warm.is_some() {
            self.cfg.bfgs.first_step * WARM_FIRST_STEP
        } else {
            self.cfg.bfgs.first_step
        };
        let cap = self.cfg.bfgs.max_iterations;
        let first = self.optimize_onto(
            &mut obj,
            &z0,
            &s.bounds,
            (first_step, cap),
            &curvature,
            Merge::First,
        );
        if let Some(t) = obj.tripped {
            fl.count = fl.count.saturating_add(obj.evaluations);
            return self.after_trip(&mut fl, (&s, &mut obj, &mut scan), t);
        }
        first?;
        let iterations = self.penalty_stages(&mut obj, (s.h, &s.bounds), first_step)?;
        let iterations =
            self.escape_plateaus(&mut obj, (s.h, &s.bounds), first_step, iterations)?;
        let iterations =
            self.restart_from_scanned(&mut obj, (s.h, &s.bounds), (&scan, first_step), iterations)?;
        if s.h == 1 && self.cfg.method == Method::Bfgs && (single || !self.cfg.constrained) {
            let guard = obj.guard;
            self.polish_single(&mut obj, &s.bounds, guard);
        }
        self.committed_to_boundary(&mut obj, (s.h, &s.bounds));
        let last = obj.last_flight;
        let (answer, warm) = ((iterations, None), (obj.mu, 0, false));
        self.finish((&mut fl, &s, &mut scan), (&obj, last), answer, warm)
    }

    /// The candidate of an optimizer's answer: `obj`'s flights counted, its
    /// depth verified (`last`: the optimizer's last one-track flight, if
    /// that depth's), the warm start kept (`warm`: `μ`, the plateaus
    /// scanned), with the call's `iterations` and `previous_j`.
    fn finish(
        &mut self,
        (fl, s, scan): (&mut Flights<'_, '_, N>, &Setup<K>, &mut ScanLog),
        (obj, last): (
            &PlanObjective<'_, N>,
            Option<(f32, TrackScore, VehicleState<N>)>,
        ),
        (iterations, previous_j): (u32, Option<f32>),
        warm: (f32, u64, bool),
    ) -> Result<Candidate<N>, PlanError> {
        fl.count = fl.count.saturating_add(obj.evaluations);
        let spent = obj.evaluations >= obj.budget;
        let (f, found) = self.verify(fl, s, (last, spent), scan)?;
        self.keep_warm(fl.track, s.h, f.depth, warm);
        self.horizon_len = s.h;
        Ok(Candidate {
            flown: f,
            found,
            iterations,
            evaluations: fl.count,
            h_safe: s.h_safe,
            cert: None,
            previous_j,
        })
    }

    /// The scenario whose penalty acts from `h_a` plus the penalty margin
    /// on a horizon of `h` tracks. One track: no penalty margin, since the
    /// boundary search then lands on the exact safe boundary instead of
    /// `m_p` above it. A horizon keeps the margin for the tracks after the
    /// first, which no boundary search corrects.
    pub(super) fn penalized<'a>(&self, sc: &Scenario<'a, N>, h: usize) -> Scenario<'a, N> {
        let margin = if h == 1 { 0.0 } else { self.cfg.penalty_margin };
        sc.with_penalty_altitude(sc.mission().min_altitude() + margin)
    }

    /// The candidate of a horizon under BFGS: the SQP from the start
    /// point, on `Σ J` with every track's least altitude at or above the
    /// certified altitude plus the boundary tolerance (module docs of
    /// `solve`), then verified as any candidate; the plateaus it scanned
    /// are skipped next call unless the escapes moved the point.
    fn sqp_candidate(
        &mut self,
        sc: &Scenario<'_, N>,
        s: &Setup<K>,
        (fl, scan): (&mut Flights<'_, '_, N>, &mut ScanLog),
        (penalized, z0): (Scenario<'_, N>, &[f32; K]),
    ) -> Result<Candidate<N>, PlanError> {
        let m = sc.mission();
        let tol = boundary_tolerance(m.reference_altitude() - m.min_altitude());
        // Under declared uncertainty, unbudgeted: the targets raised by the
        // certification gaps (the last calls' first, `gaps.rs`).
        let certifying = self.cfg.constrained && self.budget.limit == u32::MAX;
        let mut gaps = [0.0_f32; K];
        if certifying {
            for (dst, src) in gaps.iter_mut().zip(self.gaps.iter().skip(fl.track)) {
                *dst = *src;
            }
        }
        let mut obj = PlanObjective::new(penalized, fl.state, fl.track, s.h, 0.0);
        let declared = obj.declared();
        obj.gaps = Cell::from_mut(&mut gaps[..]).as_slice_of_cells();
        obj.budget = self.budget.optimizer(fl.count)?;
        let band = m.reference_altitude() - m.min_altitude();
        if self.cfg.constrained {
            // The later tracks keep a share of the penalty margin: the next
            // calls start from their depths, and from a measured state a
            // plan on the boundary would not hold (`solve.rs`). Under
            // declared uncertainty the certificate's worlds and vehicle
            // margin hold it instead, and a later call then finds the same
            // continuation (and keeps it, `commit.rs`).
            let later = if declared {
                0.0
            } else {
                later_margin(&self.cfg, m)
            };
            obj.target = (s.h_safe + tol, s.h_safe + tol + later);
            obj.band = band.max(SQP_BAND);
        }
        let (skip, far) = (
            s.warm.map_or(0, |w| w.plateaus),
            s.warm.is_none() && !declared,
        );
        // Started from the previous continuation (its horizon part, as the
        // optimizer starts, in the box)?
        let start = s.bounds.project(z0);
        let from_previous = (0..s.h).all(|i| {
            let (z, c) = (start.get(i), self.cont.depth(fl.track.saturating_add(i)));
            z.zip(c).is_some_and(|(a, b)| a.to_bits() == b.to_bits())
        });
        if certifying {
            self.seed_gaps(sc, &mut obj, (z0, s.h), tol)?;
        }
        self.work.history.clear();
        let (mut iterations, plateaus) =
            self.solve_sqp(&mut obj, z0, (s.h, &s.bounds), tol, (skip, far))?;
        let mut plateaus = ScannedAt::new(&self.work.z, plateaus, band);
        let (at, wide) = ((tol, s.h_safe, iterations), (s.h, &s.bounds, s.mu));
        let due = s.warm.is_none_or(|w| w.escapes);
        iterations = self.cold_escapes((&mut obj, fl, scan), wide, at, due);
        let owed = due && obj.last_violation > tol;
        self.polish_first(&mut obj, (s.h, &s.bounds), tol);
        let previous_j = self.work.history.first().copied().filter(|_| from_previous);
        if certifying {
            let at = (tol, s.h_safe, iterations);
            iterations = self.close_gaps(sc, &mut obj, (s.h, &s.bounds), at)?;
        }
        plateaus.at(&self.work.z);
        let (answer, warm) = ((iterations, previous_j), (0.0, plateaus.bits, owed));
        self.finish((fl, s, scan), (&obj, None), answer, warm)
    }

    /// The scan's decision of a constrained single track (module docs of
    /// `single`): the candidate when it decides, else the start it gives
    /// the optimizer, written into `z0` (and a flat metric if asked).
    fn single_decision(
        &mut self,
        fl: &mut Flights<'_, '_, N>,
        scan: &ScanLog,
        s: &Setup<K>,
        (z0, curvature): (&mut [f32; K], &mut [f32; K]),
    ) -> Result<Option<Candidate<N>>, PlanError> {
        let vertex = z0.first().copied().unwrap_or(0.0);
        let h_a = fl.sc.mission().min_altitude();
        let h = (h_a, s.h_safe);
        let (f, found, h_safe) =
            match single::decide(fl, scan, vertex, h, self.cfg.bisection_steps)? {
                Decision::Done(f, found) => (f, found, s.h_safe),
                Decision::Floor(f, floor) => (f, Found::Boundary(OptimizerStop::None), floor),
                Decision::Optimize { z0: z, flat } => {
                    if let Some(slot) = z0.first_mut() {
                        *slot = z;
                    }
                    if flat {
                        *curvature = [0.0; K];
                    }
                    return Ok(None);
                }
            };
        self.work.history.clear();
        let _ = self.work.history.push(f.score.j());
        let at = (0, fl.count);
        Ok(Some(self.single_candidate(f, found, at, h_safe)))
    }

    /// The candidate when a constrained single track's optimizer left the
    /// safe set at `t` (depth, least altitude; m): the boundary next to it
    /// ([`Planner::answer_tripped`]), or the interior optimum where the
    /// optimizer only overshot ([`Planner::inward`]). Not inlined: the
    /// boundary's flight stays off the horizon path's stack.
    #[inline(never)]
    fn after_trip(
        &mut self,
        fl: &mut Flights<'_, '_, N>,
        (s, obj, scan): (&Setup<K>, &mut PlanObjective<'_, N>, &mut ScanLog),
        t: (f32, f32),
    ) -> Result<Candidate<N>, PlanError> {
        let (f, found) = self.answer_tripped(fl, s, t, obj.best_safe, scan)?;
        if let Some(c) = self.inward(fl, (s, obj, scan), (&f, t.0))? {
            return Ok(c);
        }
        let iterations = self.work.iterations;
        Ok(self.single_candidate(f, found, (iterations, fl.count), s.h_safe))
    }

    /// The answer when a constrained single track's optimizer left the
    /// safe set at `t` (see [`single::tripped`]): the boundary's flight and
    /// status.
    fn answer_tripped(
        &mut self,
        fl: &mut Flights<'_, '_, N>,
        s: &Setup<K>,
        t: (f32, f32),
        best_safe: Option<(f32, f32, f32)>,
        scan: &mut ScanLog,
    ) -> Result<(Flown<N>, Found), PlanError> {
        let lo = s.bounds.lo.first().copied().unwrap_or(t.0);
        let hi = s.bounds.hi.first().copied().unwrap_or(t.0);
        single::tripped(
            fl,
            t,
            best_safe,
            &mut self.work,
            (lo, hi),
            s.h_safe,
            (self.cfg.scan_points, self.cfg.bisection_steps),
            scan,
        )
    }

    /// After a trip, when the optimizer only overshot: where `J` falls
    /// from the boundary `f` into the safe set (away from the trip at
    /// `z_bad`, a finite difference of `CHECK_STEP` or, if not, of a
    /// quarter of it), the optimum is interior and the guarded optimizer
    /// runs once more from the boundary (its steps only lower `J`), then
    /// under BFGS the polish (`polish.rs`); if it trips again, under BFGS
    /// the polish's search from the boundary, else the boundary.
    /// Unbudgeted calls only (the budgeted ones keep the boundary).
    fn inward(
        &mut self,
        fl: &mut Flights<'_, '_, N>,
        (s, obj, scan): (&Setup<K>, &mut PlanObjective<'_, N>, &mut ScanLog),
        (f, z_bad): (&Flown<N>, f32),
    ) -> Result<Option<Candidate<N>>, PlanError> {
        let z_b = f.depth;
        if self.budget.limit != u32::MAX || f.score.min_altitude() < s.h_safe {
            return Ok(None);
        }
        let mut falls = |step: f32| {
            fl.fly(z_b + step.copysign(z_b - z_bad))
                .is_ok_and(|(score, _)| score.j() < f.score.j() && score.min_altitude() >= s.h_safe)
        };
        if !(falls(single::CHECK_STEP) || falls(single::CHECK_SHORT * single::CHECK_STEP)) {
            return Ok(None);
        }
        // (The first run's flights are in `fl.count` already; unbudgeted,
        // `obj` has no limit to keep.)
        obj.evaluations = 0;
        obj.tripped = None;
        let mut z0 = self.work.z;
        if let Some(z) = z0.first_mut() {
            *z = z_b;
        }
        let run = (self.cfg.bfgs.first_step, self.cfg.bfgs.max_iterations);
        let zero = [0.0; K];
        let ran = self.optimize_onto(obj, &z0, &s.bounds, run, &zero, Merge::First);
        let bfgs = self.cfg.method == Method::Bfgs;
        if obj.tripped.is_some() || ran.is_err() {
            // (A sawtooth's teeth may point out, its trend in: polish.rs.)
            if !(bfgs && self.polish_boundary(obj, &s.bounds, (f.depth, f.score.j()))) {
                fl.count = fl.count.saturating_add(obj.evaluations);
                return Ok(None);
            }
        } else if bfgs {
            // (An interior optimum: `J` may be a sawtooth there too.)
            let guard = obj.guard;
            self.polish_single(obj, &s.bounds, guard);
        }
        let last = obj.last_flight;
        let answer = (self.work.iterations, None);
        self.finish((fl, s, scan), (obj, last), answer, (obj.mu, 0, false))
            .map(Some)
    }

    /// The call's horizon, first penalty weight, box and certified
    /// altitude; checks the track and the start state.
    pub(super) fn setup(
        &self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
    ) -> Result<Setup<K>, PlanError> {
        let remaining = sc
            .waypoints()
            .tracks()
            .checked_sub(track)
            .filter(|&r| r > 0)
            .ok_or(PlanError::TrackRange)?;
        // A bad start is the caller's error, named as such (every flight
        // from it would fail the same way).
        sc.check_start(state, track)?;
        // Below the bottom nothing can be made safe. (The unconstrained
        // study of the paper's bare objective flies on regardless.)
        if self.cfg.constrained
            && sc
                .profile()
                .depth_at(state.x())
                .is_ok_and(|b| state.depth() > b)
        {
            return Err(PlanError::StartBelowBottom);
        }
        let h = match self.cfg.mode {
            Mode::TrackWise => 1,
            Mode::Horizon => self.cfg.horizon.min(K).min(remaining),
        };
        let warm = self.warm.filter(|w| w.track == track && w.len > 0);
        let mu = match (self.cfg.constrained, warm) {
            (false, _) => 0.0,
            (true, Some(w)) => w.mu,
            (true, None) => self.cfg.penalty_weight,
        };
        Ok(Setup {
            h,
            warm,
            mu,
            bounds: search_box::<N, K>(sc, state, track, h),
            h_safe: self.cfg.certified_altitude(sc.mission()),
        })
    }

    /// The starting point: the warm start's depths, then a scan of the
    /// tracks it does not cover. Returns the point, the scan's curvatures
    /// and how many tracks the warm start covered.
    fn start_point(
        &self,
        s: &Setup<K>,
        fl: &mut Flights<'_, '_, N>,
        scan: &mut ScanLog,
    ) -> Result<([f32; K], [f32; K], usize), PlanError> {
        let mut z0 = s.bounds.lo;
        let mut from = 0;
        if let Some(w) = s.warm {
            from = w.len.min(s.h);
            for (slot, &z) in z0.iter_mut().zip(w.depths.iter()).take(from) {
                *slot = z;
            }
        }
        let mut curvature = [0.0; K];
        if from < s.h {
            let points = if s.h == 1 && self.cfg.constrained {
                self.cfg.track_scan_points
            } else {
                self.cfg.scan_points
            };
            let spec = ScanSpec {
                bounds: &s.bounds,
                from,
                h: s.h,
                points,
                mu: s.mu,
                beam: self.cfg.method == Method::Bfgs,
                width: BEAM,
            };
            scan_start(fl, &spec, &mut z0, &mut curvature, scan)?;
        }
        Ok((z0, curvature, from))
    }

    /// Verifies the committed depth by simulation (the optimizer's last
    /// evaluation is that very point, so a single track's flight is at
    /// hand) and falls back to the closest safe depth when it is not safe.
    fn verify(
        &self,
        fl: &mut Flights<'_, '_, N>,
        s: &Setup<K>,
        (last, spent): (Option<(f32, TrackScore, VehicleState<N>)>, bool),
        scan: &mut ScanLog,
    ) -> Result<(Flown<N>, Found), PlanError> {
        let z_opt = self.work.z.first().copied().unwrap_or_default();
        let stop = if spent && self.work.status != crate::optim::Status::Converged {
            OptimizerStop::Budget
        } else {
            OptimizerStop::from(self.work.status)
        };
        let (score, next) = match last {
            // Same start, same depth, same track: the flight is identical.
            Some((z, s, n)) if z.to_bits() == z_opt.to_bits() => (s, n),
            _ => fl.fly(z_opt)?,
        };
        let flown = Flown {
            depth: z_opt,
            score,
            next,
        };
        if !self.cfg.constrained || score.min_altitude() >= s.h_safe {
            return Ok((flown, Found::Optimized(stop)));
        }
        // (In horizon mode a single track's aim may be raised by a gap an
        // earlier call kept, `candidate_aimed`; the fallback drops it
        // where no depth meets it.)
        let warm = s.warm.and_then(|w| w.depths.first().copied());
        let warm = warm.filter(|_| s.h == 1);
        let h_cert = match self.cfg.mode {
            Mode::Horizon => self.cfg.certified_altitude(fl.sc.mission()),
            Mode::TrackWise => s.h_safe,
        };
        let lo = s.bounds.lo.first().copied().unwrap_or(z_opt);
        let hi = s.bounds.hi.first().copied().unwrap_or(z_opt);
        let (f, safe) = closest_safe(
            fl,
            (&flown, warm),
            (lo, hi),
            (s.h_safe, h_cert),
            (self.cfg.scan_points, self.cfg.bisection_steps),
            scan,
        )?;
        let found = if safe {
            Found::Boundary(stop)
        } else {
            Found::Infeasible(stop)
        };
        Ok((f, found))
    }

    /// Keeps the rest of the horizon for the next call (horizon mode).
    fn keep_warm(&mut self, track: usize, h: usize, depth: f32, warm: (f32, u64, bool)) {
        let (mu, plateaus, escapes) = warm;
        if let Some(first) = self.work.z.first_mut() {
            *first = depth;
        }
        self.warm = (self.cfg.mode == Mode::Horizon && h > 1).then(|| {
            let mut depths = [0.0; K];
            for (dst, src) in depths.iter_mut().zip(self.work.z.iter().skip(1)) {
                *dst = *src;
            }
            Warm {
                track: track.saturating_add(1),
                depths,
                len: h.saturating_sub(1),
                mu,
                plateaus: plateaus >> 1,
                escapes,
            }
        });
    }

    /// The candidate of a single-track solve decided without the general
    /// path's verification (the depth's flight is at hand): no warm start,
    /// the horizon is the depth alone, the objective its `J`.
    fn single_candidate(
        &mut self,
        f: Flown<N>,
        found: Found,
        (iterations, evaluations): (u32, u32),
        h_safe: f32,
    ) -> Candidate<N> {
        self.warm = None;
        self.work.z = [0.0; K];
        self.work.j = f.score.j();
        self.work.grad_norm = 0.0;
        if let Some(first) = self.work.z.first_mut() {
            *first = f.depth;
        }
        self.horizon_len = 1;
        Candidate {
            flown: f,
            found,
            iterations,
            evaluations,
            h_safe,
            cert: None,
            previous_j: None,
        }
    }
}
