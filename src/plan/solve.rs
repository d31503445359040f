//! The optimizer runs of a horizon. Under BFGS: the SQP on the segments'
//! minimum-altitude constraints (`optim::sqp`) and its plateau escape.
//! Under GD (the paper's baseline): one optimizer run merged onto the
//! planner's workspace, the sequential penalty stages (N&W §17.1: `μ`
//! ×100 while the optimum still violates), the plateau escape (a single
//! track's: `plateau.rs`), and the committed track moved onto the
//! certified boundary.

use crate::model::Mission;
use crate::optim::root;
use crate::optim::sqp::{SqpEnd, sqp_into};
use crate::optim::{self, BfgsConfig, Bounds, GdConfig, OptimError};
use crate::sim::{SimError, TrackScore};

use super::fallback::boundary_rule;
use super::objective::{PlanObjective, Stop};
use super::scan::grid;
use super::{Method, PlanError, Planner, PlannerConfig};

/// Rounds of the SQP's plateau escape: each scans every plateau, then
/// restarts once from the best point found. A third round: on a random
/// line on the `integ` vehicle (`check_planner.py --seed 1403`,
/// `unseen_1403_5`) the first two restored feasibility by jumping tracks
/// 2 and 3, and track 1, left on a saturated climb's plateau, needed a
/// third (1.72× → 1.007× the f64 search's best safe plan).
const PLATEAU_ROUNDS: u32 = 3;

/// What a metre of a plateau point's shortfall is taken to cost in `J`
/// when it is weighed as a restart, as a share of the finished run's ℓ1
/// merit weight `ρ` (m³/m; `ρ` is 1.5 times the largest multipliers met,
/// and restoring feasibility from a plateau's point has cost a tenth to
/// a half of `ρ v` where it paid). A point whose `J` gain does not cover
/// it brings the SQP back to the optimum it left, or to one as good, at
/// the cost of a second solve (measured: 5 to 14 iterations).
pub(super) const RESTORE_SHARE: f32 = 0.1;

/// Factor on `μ` between penalty stages.
const PENALTY_GROWTH: f32 = 100.0;

/// Share of the penalty margin `m_p` above `h_a` that the later tracks of
/// the horizon keep when the committed depth moves (or what they had, if
/// less). With none kept, the next calls start on the boundary and the
/// last, single-track call can lose the safe depths of its track (Medes 1:
/// `J` +40 %); with all of it, the committed depth cannot move wherever the
/// later tracks are held too.
pub(super) const LATER_SHARE: f32 = 0.25;

/// At most this share of `h_r − h_a` is what the later tracks keep (of
/// [`LATER_SHARE`] `m_p`): on a tight mission (Aburatsubo, `h_r − h_a` =
/// 1 m, the default `m_p` a quarter of it) the full share held the line's
/// `J` 1.02 % above the best safe plan's. At 5 % the later tracks still
/// clear a start state measured 5 cm off (`tests/budget.rs`, which a 4 %
/// cap failed on Aburatsubo); Monterey and Medes keep the full share.
const LATER_BAND: f32 = 0.05;

/// The later tracks' margin above `h_a + m_s` that the horizon keeps, m
/// ([`LATER_SHARE`], [`LATER_BAND`]).
pub(super) fn later_margin(cfg: &PlannerConfig, m: &Mission) -> f32 {
    let band = m.reference_altitude() - m.min_altitude();
    crate::num::min(LATER_SHARE * cfg.penalty_margin, LATER_BAND * band)
}

/// `(Σ J, least altitude of the first track, least altitude of the later
/// ones)` of the horizon `z` by a plain flight (m³, m, m; `+∞` with no
/// later track), counted in `obj`'s evaluations, within its
/// budget.
pub(super) fn horizon_flight<const N: usize, const K: usize>(
    obj: &mut PlanObjective<'_, N>,
    z: &[f32; K],
) -> Result<(f32, f32, f32), Stop> {
    let scores = obj.flight(z)?;
    let sc = scores.get(..obj.count).unwrap_or(&[]);
    let j: f32 = sc.iter().map(TrackScore::j).sum();
    let first = sc.first().map_or(f32::INFINITY, TrackScore::min_altitude);
    let later = sc
        .iter()
        .skip(1)
        .map(TrackScore::min_altitude)
        .fold(f32::INFINITY, f32::min);
    Ok((j, first, later))
}

/// How [`Planner::optimize_onto`] merges a run.
#[derive(Clone, Copy)]
pub(super) enum Merge {
    /// The first run: replaces.
    First,
    /// A continuation of the last run.
    Continue,
    /// A restart, kept only if better.
    IfBetter,
}

/// The planner's error for an optimizer that could not start.
fn start_error(e: OptimError<Stop>) -> PlanError {
    match e {
        OptimError::Config(p) => PlanError::Config(p.into()),
        OptimError::Start(Stop::Sim(e)) => PlanError::Sim(e),
        OptimError::Start(Stop::LeftSafeSet | Stop::Budget) | OptimError::NonFinite => {
            PlanError::Sim(SimError::Diverged)
        }
    }
}

impl<const K: usize, const N: usize> Planner<K, N> {
    /// The SQP of a horizon (BFGS), from `z0`, onto the workspace; then
    /// the plateau escape: a coordinate whose gradient is exactly zero is
    /// scanned over its box, the others held, and the SQP restarted from
    /// a feasible point of lower `J` (kept if it ends lower). A coordinate
    /// in `skip` (bit `j`) was scanned by the previous call, whose plan
    /// this one continues, and is not scanned again. `far`: a cold call's
    /// run, whose kink escape may move further (`kink.rs`). `tol` is the
    /// feasibility tolerance (m). Returns the iterations and the
    /// coordinates scanned (bits).
    pub(super) fn solve_sqp(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        z0: &[f32; K],
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        (skip, far): (u64, bool),
    ) -> Result<(u32, u64), PlanError> {
        // (A run after the call's first continues its history: its start
        // counts as one more iteration, as a plateau's restart does.)
        let chained = !self.work.history.is_empty();
        let before = if chained {
            self.work.iterations.saturating_add(1)
        } else {
            0
        };
        let out = self.solve_sqp_run(obj, z0, (h, bounds), tol, (skip, far))?;
        self.work.iterations = before.saturating_add(out.0);
        Ok((self.work.iterations, out.1))
    }

    /// [`Planner::solve_sqp`]'s run, its iterations counted from 0.
    fn solve_sqp_run(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        z0: &[f32; K],
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        (skip, far): (u64, bool),
    ) -> Result<(u32, u64), PlanError> {
        // (No run's rows yet: the last call's must not steer this one;
        // nor its plateau scans.)
        self.blended = 0;
        self.scanned.clear();
        let run = sqp_into(
            obj,
            (z0, 0.0, false),
            (bounds, h),
            &self.cfg.bfgs,
            tol,
            &mut self.work,
        );
        let unstarted = matches!(run, Err(OptimError::Start(Stop::Budget)));
        if unstarted {
            self.work.reset_at(z0);
            return Ok((0, 0));
        }
        let end = run.map_err(start_error)?;
        let rho = end.rho;
        self.blended = end.blended;
        let mut iterations = self.work.iterations;
        iterations = self.follow_up(obj, &end, (h, bounds), tol, iterations);
        let mut scanned = 0_u64;
        // The coordinates a kept restart jumped: the next round scans the
        // others again (the restart moved the point, and a plateau's best
        // may need the jump: `check_planner.py --seed 13`, `unseen_13_7`,
        // track 3's climb left only once track 1 had jumped).
        let mut jumped = 0_u64;
        for _ in 0..PLATEAU_ROUNDS {
            if iterations >= self.cfg.bfgs.max_iterations {
                break;
            }
            // Every plateau's scan first, then one restart from the best.
            let mut best: Option<((f32, f32), [f32; K], u64)> = None;
            for j in 0..h {
                let bit = u32::try_from(j)
                    .ok()
                    .and_then(|j| 1_u64.checked_shl(j))
                    .unwrap_or(0);
                if (skip | jumped) & bit != 0 {
                    continue;
                }
                if self.work.gradient.get(j).is_some_and(|&g| g == 0.0) {
                    scanned |= bit;
                }
                if let Some(c) = self.sqp_plateau_jump(obj, bounds, j, (tol, rho, false))
                    && best.as_ref().is_none_or(|b| lex_less(c.0, b.0))
                {
                    best = Some((c.0, c.1, bit));
                }
            }
            let Some((_, z, bit)) = best else { break };
            match self.sqp_restart(obj, &z, (h, bounds), (tol, 0.0, false), iterations) {
                Some(total) => iterations = total,
                None => break,
            }
            jumped |= bit;
        }
        // (The kink is the first run's: a kept plateau restart may have
        // moved the point since; `kink.rs` flies the lift test from where
        // the workspace now stands, and keeps a restart only if better.)
        if end.kink != 0 && iterations < self.cfg.bfgs.max_iterations {
            iterations = self.leave_kink(obj, (h, bounds), (end.kink, tol, far), iterations);
        }
        self.work.iterations = iterations;
        Ok((iterations, scanned | skip))
    }

    /// A first run's follow-up, from its `end`: gone back, or converged on
    /// a sliver, once more, careful, with a fresh metric, kept if it ends
    /// better. Returns the iterations so far.
    fn follow_up(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        end: &SqpEnd<K>,
        (h, bounds): (usize, &Bounds<K>),
        tol: f32,
        iterations: u32,
    ) -> u32 {
        if iterations >= self.cfg.bfgs.max_iterations {
            return iterations;
        }
        // Gone back (`optim/best.rs`): once more, careful, the merit weight
        // learnt, from there or the edge towards where it left (`edge.rs`).
        // Converged on a sliver (`SqpEnd::sliver`): once more from there,
        // careful (a metric out of scale proposes long steps, which a
        // careful QP checks against the rows beyond the band they cross).
        // On a random line on the `integ` vehicle (`check_planner.py
        // --seed 1902`, `unseen_1902_0`) the cold run's first step took
        // `z_2` off its plateau; the metric's next step, (−210, −52, 0,
        // +235) m, was cut to α = 9e-6, and the run converged there with
        // every track 16 m or more above its target and `∂J/∂z_4` =
        // −23 400 m³/m: the line's `J` 1.41× the f64 best safe plan's;
        // restarted, 1.005× (1.095× not careful).
        let from = if end.returned {
            let left = end.left.filter(|_| end.lower);
            let edge = left.and_then(|l| self.edge_toward(obj, &l, tol));
            Some(edge.unwrap_or(self.work.z))
        } else {
            end.sliver.then_some(self.work.z)
        };
        let Some(z) = from else {
            return iterations;
        };
        let again = self.sqp_restart(obj, &z, (h, bounds), (tol, end.rho, true), iterations);
        again.unwrap_or(iterations)
    }

    /// Further penalty stages: each re-solves from the last optimum with
    /// `μ` a hundred times larger while that optimum still violates, at most
    /// `penalty_stages` in all (one for a single track, whose boundary
    /// search finds the safe boundary exactly), all within the one
    /// iteration cap. Returns the iterations so far.
    pub(super) fn penalty_stages(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        first_step: f32,
    ) -> Result<u32, PlanError> {
        let cap = self.cfg.bfgs.max_iterations;
        let mut iterations = self.work.iterations;
        let stages = if h == 1 { 1 } else { self.cfg.penalty_stages };
        let max_mu = (1..stages).fold(self.cfg.penalty_weight, |m, _| m * PENALTY_GROWTH);
        // Another stage only while the optimum is below the certified
        // altitude `h_a + m_s`: a violation of the penalty altitude
        // `h_a + m_p` alone is what the margin is there to absorb.
        let h_safe = self.cfg.certified_altitude(obj.sc.mission());
        while obj.mu > 0.0
            && obj.mu < max_mu
            && obj.last_violation > 0.0
            && obj.last_min_altitude < h_safe
            && iterations < cap
        {
            obj.mu *= PENALTY_GROWTH;
            let from = self.work.z;
            let left = cap.saturating_sub(iterations);
            let taken = self.optimize_onto(
                obj,
                &from,
                bounds,
                (first_step, left),
                &[0.0; K],
                Merge::Continue,
            )?;
            iterations = iterations.saturating_add(taken.unwrap_or(0));
        }
        Ok(iterations)
    }

    /// Plateau escape: a coordinate whose gradient is exactly zero has its
    /// pitch reference saturated over the whole track, and no gradient
    /// step will ever move it off that plateau, which need not be the best
    /// (model contract §10). Scan it over its box, the others held, and
    /// restart from anything better. Returns the iterations so far (a
    /// jump counts as one).
    pub(super) fn escape_plateaus(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
        first_step: f32,
        mut iterations: u32,
    ) -> Result<u32, PlanError> {
        if h <= 1 {
            return self.escape_plateau_single(obj, bounds, first_step, iterations);
        }
        let cap = self.cfg.bfgs.max_iterations;
        for j in 0..h {
            let Some(z) = self.plateau_jump(obj, bounds, j) else {
                continue;
            };
            // The jump costs one iteration of the cap; none left, no restart.
            let budget = cap.saturating_sub(iterations).saturating_sub(1);
            if budget == 0 {
                break;
            }
            let taken = self.optimize_onto(
                obj,
                &z,
                bounds,
                (first_step, budget),
                &[0.0; K],
                Merge::IfBetter,
            )?;
            if let Some(taken) = taken {
                iterations = iterations.saturating_add(taken).saturating_add(1);
            }
        }
        Ok(iterations)
    }

    /// The committed (first) depth of a constrained horizon moved onto the
    /// certified boundary. The horizon is penalized below `h_a + m_p`, so a
    /// first track the constraint holds sits up to `m_p` above the
    /// certified altitude `h_a + m_s`, and the commit keeps it there (only
    /// an unsafe candidate goes to the boundary search): on the shallow
    /// sites, where `m_p` is a large share of `h_r − h_a`, that costs
    /// whole percents of `J`. When the first track's least altitude is
    /// below `h_a + 2 m_p` and the horizon is safe, the first depth is
    /// searched deeper, the later depths held, for the point where the
    /// first track's least altitude reaches `h_a + m_s` or the later
    /// tracks' `h_a + LATER_SHARE m_p` (or what it was, if lower): a root
    /// search from the safe side; it is kept where `Σ J` is lower (the
    /// optimizer's objective and history stay the optimizer's). Plain
    /// flights of the horizon, counted in the objective's evaluations,
    /// within its budget.
    pub(super) fn committed_to_boundary(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        (h, bounds): (usize, &Bounds<K>),
    ) {
        let (Some(&z0), Some(&hi)) = (self.work.z.first(), bounds.hi.first()) else {
            return;
        };
        if h <= 1 || obj.mu <= 0.0 || z0 >= hi {
            return;
        }
        let m = *obj.sc.mission();
        let h_safe = self.cfg.certified_altitude(&m);
        let band = obj.sc.penalty_altitude() + self.cfg.penalty_margin;
        let rule = boundary_rule(&m, self.cfg.bisection_steps);
        let tol = rule.tol;
        let base = self.work.z;
        let Ok((j0, first, later)) = horizon_flight(obj, &base) else {
            return;
        };
        if first < h_safe + tol || first >= band || later < h_safe {
            return;
        }
        // The later tracks keep part of their margin: the next calls start
        // from their depths.
        let floor = later.min(m.min_altitude() + later_margin(&self.cfg, &m));
        let margin = |a: f32, b: f32| (a - h_safe).min(b - floor);
        // Altitude falls at most a metre per metre of reference depth: twice
        // the headroom deeper is past the boundary unless the flight there
        // is held by something else (then that depth itself is tried).
        let bad = (z0 + 2.0 * (first - h_safe) + tol).min(hi);
        let good = (z0, Some(margin(first, later)));
        let found = root::safe_boundary(good, (bad, None), rule, |t| {
            let mut z = base;
            if let Some(slot) = z.first_mut() {
                *slot = t;
            }
            horizon_flight(obj, &z).map(|(j, a, b)| (margin(a, b), j))
        });
        let Ok(r) = found else {
            return;
        };
        if let Some(j) = r.at
            && j < j0
            && r.z > z0
            && let Some(slot) = self.work.z.first_mut()
        {
            *slot = r.z;
        }
    }

    /// The best point of a scan of coordinate `j` over its box when its
    /// gradient is exactly zero, if it beats the optimum by more than the
    /// stopping threshold.
    fn plateau_jump(
        &self,
        obj: &mut PlanObjective<'_, N>,
        bounds: &Bounds<K>,
        j: usize,
    ) -> Option<[f32; K]> {
        let (&lo, &hi) = bounds.lo.get(j).zip(bounds.hi.get(j))?;
        let out = &self.work;
        if lo >= hi || out.gradient.get(j).is_none_or(|&g| g != 0.0) {
            return None;
        }
        let mut best: Option<(f32, [f32; K])> = None;
        for k in 0..self.cfg.scan_points {
            let mut z = out.z;
            if let Some(zj) = z.get_mut(j) {
                *zj = grid(lo, hi, k, self.cfg.scan_points);
            }
            if let Ok(phi) = obj.flight_value(&z)
                && phi < best.as_ref().map_or(out.j, |b| b.0)
            {
                best = Some((phi, z));
            }
        }
        best.filter(|b| b.0 < out.j - self.cfg.bfgs.tol.j_threshold(out.j))
            .map(|b| b.1)
    }

    /// One optimizer run (BFGS or GD, as configured) on `obj` from `z0`
    /// with start `curvature` and `(first_step, max_iterations)`, merged
    /// onto the workspace in place: the first run, a continuation (the next
    /// penalty stage: its history after its start, whose value the
    /// workspace ends with) or, with [`Merge::IfBetter`], a restart kept
    /// only if it ends lower (its whole history). Returns the run's
    /// iterations, `None` when not kept.
    pub(super) fn optimize_onto(
        &mut self,
        obj: &mut PlanObjective<'_, N>,
        z0: &[f32; K],
        bounds: &Bounds<K>,
        (first_step, max_iterations): (f32, u32),
        curvature: &[f32; K],
        merge: Merge,
    ) -> Result<Option<u32>, PlanError> {
        let acc = &mut self.work;
        // What a rejected restart restores.
        let kept = acc.mark();
        if let Merge::First = merge {
            acc.history.clear();
        }
        let continued = matches!(merge, Merge::Continue);
        let bfgs = BfgsConfig {
            first_step,
            max_iterations,
            ..self.cfg.bfgs
        };
        let run = match self.cfg.method {
            Method::Bfgs => optim::bfgs::bfgs_into(
                obj,
                z0,
                bounds,
                &bfgs,
                &bfgs.armijo,
                curvature,
                acc,
                continued,
            ),
            Method::GradientDescent => {
                let gd = GdConfig {
                    rate: self.cfg.gd_rate,
                    max_iterations,
                    tol: self.cfg.bfgs.tol,
                };
                optim::gd::gradient_descent_into(obj, z0, bounds, &gd, acc, continued)
            }
        };
        // A run the budget does not allow to start is not a run.
        let unstarted = matches!(run, Err(OptimError::Start(Stop::Budget)));
        if !unstarted {
            run.map_err(start_error)?;
        }
        // (A NaN objective is not better either.)
        let worse = acc.j.partial_cmp(&kept.j) != Some(core::cmp::Ordering::Less);
        if unstarted || (matches!(merge, Merge::IfBetter) && worse) {
            acc.restore(&kept);
            return Ok(None);
        }
        Ok(Some(acc.iterations))
    }
}

/// `a < b` in the order of their first entries, then their second.
pub(super) fn lex_less(a: (f32, f32), b: (f32, f32)) -> bool {
    match a.0.partial_cmp(&b.0) {
        Some(core::cmp::Ordering::Less) => true,
        Some(core::cmp::Ordering::Equal) => a.1 < b.1,
        _ => false,
    }
}

/// The plateaus a horizon's SQP scanned (bits, `z_j` for bit `j`) and
/// the point it scanned them at: a scan holds the other depths where
/// they are, so a move of any depth by more than `within` drops them all,
/// and the next call scans them again where this call ends.
/// `check_planner.py --seed 3260 --vehicle tools/reference/vehicles/slow.toml`
/// (`unseen_3260_6`): the cold call scanned track 4's plateau with
/// track 5 at 1 059.7 m and found nothing; its escapes then moved tracks
/// 3–5 by 40–168 m and left track 4 on the plateau with track 5 at
/// 892.1 m, where the scan finds 910.5 m, and the later calls skipped it:
/// the line 1.14× the f64 best safe plan, 1.0012× when they scan again.
pub(super) struct ScannedAt<const K: usize> {
    /// The point the bits were scanned at (m).
    z: [f32; K],
    /// How far a depth may move before the bits drop (m).
    within: f32,
    /// The coordinates scanned there.
    pub(super) bits: u64,
}

impl<const K: usize> ScannedAt<K> {
    /// `bits` scanned at `z`, held while no depth moves more than
    /// `within` (m).
    pub(super) fn new(z: &[f32; K], bits: u64, within: f32) -> Self {
        Self {
            z: *z,
            within,
            bits,
        }
    }

    /// Now at `z` (m): the bits drop if a depth moved more than `within`.
    pub(super) fn at(&mut self, z: &[f32; K]) {
        let moved = self
            .z
            .iter()
            .zip(z)
            .any(|(a, b)| libm::fabsf(a - b) > self.within);
        if moved {
            *self = Self::new(z, 0, self.within);
        }
    }
}
