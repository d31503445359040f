//! [`Planner`]: one call plans one track's reference depth, in steps that
//! each live in their own function: set-up (horizon, penalty, box), the
//! starting point (warm start and scan), the single-track decision, the
//! penalized solve with its plateau escape, verification and fallback, and
//! the answer.

use crate::optim::{Bounds, Outcome};
use crate::sim::{Scenario, TrackScore, VehicleState};

use super::fallback::{Flown, fallback};
use super::flights::Flights;
use super::objective::PlanObjective;
use super::scan::{ScanLog, ScanSpec, scan_start, search_box};
use super::single::{self, Decision};
use super::solve::Merge;
use super::{Mode, Plan, PlanError, PlanStatus, PlannerConfig};

/// First step of a warm-started solve, relative to `first_step`.
const WARM_FIRST_STEP: f32 = 0.1;

/// A receding-horizon or track-wise planner of up to `K` tracks at a time.
///
/// Holds its settings, the warm start for the next call, and the last
/// call's workspace: the optimized horizon ([`Planner::horizon`]) and the
/// optimizer's history ([`Planner::history`]). Caller-owned (place it in a
/// `static` or on a task's stack: about `1.1 KiB + 8 K` bytes), so a
/// [`Plan`] stays small.
#[derive(Clone, Debug, PartialEq)]
pub struct Planner<const K: usize> {
    pub(super) cfg: PlannerConfig,
    /// The previous call's plan for the tracks after the committed one.
    warm: Option<Warm<K>>,
    /// The last call's optimizer outcome (its point is the horizon).
    pub(super) work: Outcome<K>,
    /// The last call's horizon length.
    horizon_len: usize,
}

#[cfg(feature = "defmt")]
impl<const K: usize> defmt::Format for Planner<K> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "Planner {{ cfg: {}, horizon: {}, warm: {} }}",
            self.cfg,
            self.horizon(),
            self.warm.is_some()
        );
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Warm<const K: usize> {
    track: usize,
    depths: [f32; K],
    len: usize,
    /// The penalty weight the previous call ended with.
    mu: f32,
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

impl<const K: usize> Planner<K> {
    /// A planner with validated settings.
    ///
    /// # Errors
    /// [`PlanError::Config`] naming the first setting out of range.
    pub fn new(cfg: PlannerConfig) -> Result<Self, PlanError> {
        const { assert!(K >= 1, "a planner optimizes at least one track") };
        cfg.validate().map_err(PlanError::Config)?;
        Ok(Self {
            cfg,
            warm: None,
            work: Outcome::at(&[0.0; K]),
            horizon_len: 0,
        })
    }

    /// The settings.
    pub fn config(&self) -> &PlannerConfig {
        &self.cfg
    }

    /// Forgets the warm start (e.g. after a re-route).
    pub fn reset(&mut self) {
        self.warm = None;
    }

    /// The last call's optimized horizon, m: the committed depth first,
    /// then the later tracks' depths that warm-start the next call.
    pub fn horizon(&self) -> &[f32] {
        self.work.z.get(..self.horizon_len).unwrap_or(&[])
    }

    /// The last call's optimizer objective (m³) at its start and after
    /// each iteration (at most [`crate::optim::HISTORY`] values). In horizon mode it is
    /// the penalized horizon objective `Σ J + μ Σ V`, penalty stages and
    /// restarts chained; a single track's boundary search adds the
    /// answer's `J` as one more entry.
    pub fn history(&self) -> &[f32] {
        &self.work.history
    }

    /// Plans the reference depth of `track` (0-based) for a vehicle in
    /// `state`, the state in which it reaches the track's first waypoint.
    ///
    /// # Errors
    /// [`PlanError`] for a track outside the line, or a simulation that
    /// fails at the very start (a non-finite state, one off the track).
    pub fn plan<const N: usize>(
        &mut self,
        sc: &Scenario<'_, N>,
        state: &VehicleState<N>,
        track: usize,
    ) -> Result<Plan<N>, PlanError> {
        let s = self.setup(sc, state, track)?;
        // One track: no penalty margin, since the boundary search then
        // lands on the exact safe boundary instead of `m_p` above it. A
        // horizon keeps the margin for the tracks after the first, which no
        // boundary search corrects.
        let margin = if s.h == 1 {
            0.0
        } else {
            self.cfg.penalty_margin
        };
        let penalized = sc.with_penalty_altitude(sc.mission().min_altitude() + margin);
        let mut fl = Flights {
            sc: penalized,
            state,
            track,
            count: 0,
        };
        let mut scan = ScanLog::default();
        let (mut z0, mut curvature, from) = self.start_point(&s, &mut fl, &mut scan)?;
        // One track, constrained, scanned: the scan may decide it (module
        // docs of `single`); it is then optimized without the penalty.
        let single = s.h == 1 && self.cfg.constrained && from == 0 && !scan.is_empty();
        if single {
            let vertex = z0.first().copied().unwrap_or(0.0);
            match single::decide(&mut fl, &scan, vertex, s.h_safe, self.cfg.bisection_steps)? {
                Decision::Done(f, status) => {
                    self.work.history.clear();
                    let _ = self.work.history.push(f.score.j());
                    return Ok(self.answer_single(f, status, (0, fl.count), s.h_safe));
                }
                Decision::Optimize { z0: z, flat } => {
                    if let Some(slot) = z0.first_mut() {
                        *slot = z;
                    }
                    if flat {
                        curvature = [0.0; K];
                    }
                }
            }
        }
        let mu = if single { 0.0 } else { s.mu };
        let mut obj = PlanObjective::new(penalized, state, track, s.h, mu);
        obj.guard = single.then_some(s.h_safe);
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
            return self.answer_tripped(&mut fl, &s, t, obj.best_safe, &mut scan);
        }
        first?;
        let iterations = self.penalty_stages(&mut obj, (s.h, &s.bounds), first_step)?;
        let iterations =
            self.escape_plateaus(&mut obj, (s.h, &s.bounds), first_step, iterations)?;
        fl.count = fl.count.saturating_add(obj.evaluations);
        let (f, status) = self.verify(&mut fl, &s, obj.last_flight, &mut scan)?;
        self.keep_warm(track, s.h, f.depth, obj.mu);
        Ok(self.answer(f, status, iterations, fl.count, (s.h, s.h_safe)))
    }

    /// The answer when a constrained single track's optimizer left the
    /// safe set at `t` (see [`single::tripped`]).
    fn answer_tripped<const N: usize>(
        &mut self,
        fl: &mut Flights<'_, '_, N>,
        s: &Setup<K>,
        t: (f32, f32),
        best_safe: Option<(f32, f32, f32)>,
        scan: &mut ScanLog,
    ) -> Result<Plan<N>, PlanError> {
        let lo = s.bounds.lo.first().copied().unwrap_or(t.0);
        let hi = s.bounds.hi.first().copied().unwrap_or(t.0);
        let (f, status) = single::tripped(
            fl,
            t,
            best_safe,
            &mut self.work,
            (lo, hi),
            s.h_safe,
            (self.cfg.scan_points, self.cfg.bisection_steps),
            scan,
        )?;
        let iterations = self.work.iterations;
        Ok(self.answer_single(f, status, (iterations, fl.count), s.h_safe))
    }

    /// The call's horizon, first penalty weight, box and certified
    /// altitude; checks the track and the start state.
    fn setup<const N: usize>(
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
            h_safe: sc.mission().min_altitude() + self.cfg.safety_margin,
        })
    }

    /// The starting point: the warm start's depths, then a scan of the
    /// tracks it does not cover. Returns the point, the scan's curvatures
    /// and how many tracks the warm start covered.
    fn start_point<const N: usize>(
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
            };
            scan_start(fl, &spec, &mut z0, &mut curvature, scan)?;
        }
        Ok((z0, curvature, from))
    }

    /// Verifies the committed depth by simulation (the optimizer's last
    /// evaluation is that very point, so a single track's flight is at
    /// hand) and falls back to the closest safe depth when it is not safe.
    fn verify<const N: usize>(
        &self,
        fl: &mut Flights<'_, '_, N>,
        s: &Setup<K>,
        last: Option<(f32, TrackScore, VehicleState<N>)>,
        scan: &mut ScanLog,
    ) -> Result<(Flown<N>, PlanStatus), PlanError> {
        let z_opt = self.work.z.first().copied().unwrap_or_default();
        let status = PlanStatus::from(self.work.status);
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
            return Ok((flown, status));
        }
        let lo = s.bounds.lo.first().copied().unwrap_or(z_opt);
        let hi = s.bounds.hi.first().copied().unwrap_or(z_opt);
        let (f, safe) = fallback(
            fl,
            (z_opt, Some(score.min_altitude())),
            (lo, hi),
            s.h_safe,
            self.cfg.scan_points,
            self.cfg.bisection_steps,
            scan,
        )?;
        let status = if safe {
            PlanStatus::SafeFallback
        } else {
            PlanStatus::Infeasible
        };
        Ok((f, status))
    }

    /// Keeps the rest of the horizon for the next call (horizon mode).
    fn keep_warm(&mut self, track: usize, h: usize, depth: f32, mu: f32) {
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
            }
        });
    }

    /// The answer of a single-track solve decided without the general
    /// path's verification (the depth's flight is at hand): no warm start,
    /// the horizon is the depth alone, the objective its `J`.
    fn answer_single<const N: usize>(
        &mut self,
        f: Flown<N>,
        status: PlanStatus,
        (iterations, evaluations): (u32, u32),
        h_safe: f32,
    ) -> Plan<N> {
        self.warm = None;
        self.work.z = [0.0; K];
        self.work.j = f.score.j();
        self.work.grad_norm = 0.0;
        if let Some(first) = self.work.z.first_mut() {
            *first = f.depth;
        }
        self.answer(f, status, iterations, evaluations, (1, h_safe))
    }

    /// The one place a [`Plan`] is built and logged.
    fn answer<const N: usize>(
        &mut self,
        f: Flown<N>,
        status: PlanStatus,
        iterations: u32,
        evaluations: u32,
        (h, h_safe): (usize, f32),
    ) -> Plan<N> {
        self.horizon_len = h;
        let plan = Plan {
            depth: f.depth,
            status,
            safe: f.score.min_altitude() >= h_safe,
            j: f.score.j(),
            rms: f.score.rms(),
            min_altitude: f.score.min_altitude(),
            objective: self.work.j,
            iterations,
            evaluations,
            grad_norm: self.work.grad_norm,
            horizon_len: h,
            next_state: f.next,
        };
        crate::log::debug!(
            "plan: depth {=f32} m, {=str}, J {=f32} m3, min altitude {=f32} m, {=u32} iterations, {=u32} evaluations",
            plan.depth,
            plan.status.as_str(),
            plan.j,
            plan.min_altitude,
            plan.iterations,
            plan.evaluations
        );
        plan
    }
}
