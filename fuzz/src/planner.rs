//! The planner entry: `Planner::<1>` or `Planner::<3>` (track-wise or
//! receding horizon, BFGS or gradient descent, constrained or not, any
//! settings) plans one to five successive tracks of a fuzzed line, each
//! from the state the previous plan predicts.
//!
//! Contract checked on every `Ok` plan (the library's docs and README):
//! - every `f32` of the plan is finite (depth, `J`, RMS, minimum altitude,
//!   objective, gradient norm, history, horizon, next state);
//! - the depth, and the whole optimized horizon, lie within the mission's
//!   depth limits; `1 <= horizon_len <= min(K, tracks left)`;
//! - `safe` is exactly `min_altitude >= h_a + safety_margin`; a safe
//!   fallback is safe, an infeasible plan is not, and a constrained plan is
//!   safe unless it is flagged infeasible;
//! - iterations stay within the iteration cap, the history within its
//!   capacity;
//! - flying the committed depth with `Scenario::simulate` gives the same
//!   `J`, minimum altitude and next state, bit for bit.
//!
//! An `Err` is a typed error and is accepted, except that a start state
//! the simulation rejects (not finite, or off the track) must be reported
//! as such (`PlanError::Sim(NonFiniteState / StateOffTrack)`, as
//! `Planner::plan` documents).

use arbitrary::Arbitrary;
use auvnav::optim::{Armijo, BfgsConfig, HISTORY, Tolerances};
use auvnav::{
    Method, Mode, Plan, PlanError, PlanStatus, Planner, PlannerConfig, Scenario, SimError,
    TrackScore, VehicleState,
};

use crate::known;
use crate::line::{
    Line, LineIn, MissionIn, StartIn, Val, VehicleIn, c_auv4, state_is_finite, state_is_physical,
};

/// Most optimizer iterations per call: the cap is part of the contract
/// whatever its value, and a small one keeps executions fast.
pub const MAX_ITERATIONS: u32 = 40;

/// Largest penalty weight (after all stages) of a physical input: `μ V`
/// stays finite for physical violations.
pub const PHYSICAL_PENALTY: f32 = 1e12;

/// One fuzzer input.
#[derive(Arbitrary, Debug)]
pub struct Input {
    pub vehicle: VehicleIn,
    pub mission: MissionIn,
    pub line: LineIn,
    pub start: StartIn,
    pub settings: Settings,
    /// First track planned (modulo the number of tracks + 1: one past the
    /// end is `TrackRange`).
    pub first_track: u8,
    /// Successive calls (1 + `calls % 5`).
    pub calls: u8,
}

/// The planner's settings.
#[derive(Arbitrary, Debug)]
pub struct Settings {
    /// `Planner::<3>` (else `Planner::<1>`).
    pub horizon3: bool,
    pub gradient_descent: bool,
    pub track_wise: bool,
    /// `None`: as many tracks as `K` allows; `Some(0)` is invalid.
    pub horizon: Option<u8>,
    pub unconstrained: bool,
    pub tuning: Option<Box<Tuning>>,
}

/// Everything else in `PlannerConfig`.
#[derive(Arbitrary, Debug)]
pub struct Tuning {
    /// 0 is invalid; else `1 + n % MAX_ITERATIONS`.
    pub max_iterations: u8,
    pub first_step: Val,
    pub max_step: Val,
    pub tol: [Val; 3],
    pub c1: Val,
    pub shrink: Val,
    pub max_backtracks: u8,
    pub interpolate: bool,
    pub gd_rate: Val,
    pub penalty_weight: Val,
    /// 0 is invalid; at most 4 stages.
    pub penalty_stages: u8,
    pub penalty_margin: Val,
    pub safety_margin: Val,
    /// 0..=65 (0, 1 and 65 are invalid).
    pub scan_points: u8,
    /// The same, for a constrained single track.
    pub track_scan_points: u8,
    /// 0..=24.
    pub bisection_steps: u8,
}

/// What one execution did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The vehicle, line or mission was rejected (or too long to fly).
    Rejected,
    /// `Planner::new` rejected the settings.
    Settings,
    /// A plan call returned this error after this many good plans, for an
    /// input of physical magnitudes or not.
    Error(usize, PlanError, bool),
    /// Every call returned a plan; the last one's status.
    Planned(PlanStatus),
}

impl Settings {
    /// The planner settings.
    pub fn config(&self) -> PlannerConfig {
        let d = PlannerConfig::default();
        let mut c = PlannerConfig {
            method: if self.gradient_descent {
                Method::GradientDescent
            } else {
                Method::Bfgs
            },
            mode: if self.track_wise {
                Mode::TrackWise
            } else {
                Mode::Horizon
            },
            horizon: self.horizon.map_or(usize::MAX, usize::from),
            constrained: !self.unconstrained,
            bfgs: BfgsConfig {
                max_iterations: MAX_ITERATIONS,
                ..d.bfgs
            },
            ..d
        };
        if let Some(t) = &self.tuning {
            let (b, a, tol) = (d.bfgs, Armijo::default(), Tolerances::default());
            c.bfgs = BfgsConfig {
                max_iterations: match t.max_iterations {
                    0 => 0,
                    n => 1 + u32::from(n) % MAX_ITERATIONS,
                },
                first_step: t.first_step.get(b.first_step, 0.0, 100.0),
                max_step: t.max_step.get(b.max_step, 0.0, 1000.0),
                armijo: Armijo {
                    c1: t.c1.get(a.c1, 0.0, 1.0),
                    shrink: t.shrink.get(a.shrink, 0.0, 1.0),
                    max_backtracks: u32::from(t.max_backtracks % 32),
                    interpolate: t.interpolate,
                },
                tol: Tolerances {
                    grad: t.tol[0].get(tol.grad, 0.0, 1.0),
                    rel: t.tol[1].get(tol.rel, 0.0, 0.1),
                    floor: t.tol[2].get(tol.floor, 0.0, 100.0),
                },
            };
            c.gd_rate = t.gd_rate.get(d.gd_rate, 0.0, 1e-2);
            c.penalty_weight = t.penalty_weight.get(d.penalty_weight, 0.0, 1e8);
            c.penalty_stages = u32::from(t.penalty_stages % 5);
            c.penalty_margin = t.penalty_margin.get(d.penalty_margin, 0.0, 5.0);
            c.safety_margin = t.safety_margin.get(d.safety_margin, 0.0, 1.0);
            c.scan_points = u32::from(t.scan_points % 66);
            c.track_scan_points = u32::from(t.track_scan_points % 66);
            c.bisection_steps = u32::from(t.bisection_steps % 25);
        }
        c
    }
}

/// Runs one input.
pub fn run(data: &[u8]) -> Outcome {
    let Ok(input) = Input::arbitrary_take_rest(arbitrary::Unstructured::new(data)) else {
        return Outcome::Rejected;
    };
    run_input(&input)
}

/// Runs one decoded input.
pub fn run_input(input: &Input) -> Outcome {
    match &input.vehicle {
        VehicleIn::CAuv4 => with_line(*c_auv4(), input),
        VehicleIn::Tuned(t) => match t.vehicle() {
            Some(v) => with_line(v, input),
            None => Outcome::Rejected,
        },
    }
}

fn with_line<const N: usize>(vehicle: auvnav::Vehicle<N>, input: &Input) -> Outcome {
    let Some(line) = Line::new(vehicle, &input.line, &input.mission) else {
        return Outcome::Rejected;
    };
    let Some(sc) = line.scenario() else {
        return Outcome::Rejected;
    };
    let cfg = input.settings.config();
    if input.settings.horizon3 {
        plan_line::<N, 3>(&sc, &line, cfg, input)
    } else {
        plan_line::<N, 1>(&sc, &line, cfg, input)
    }
}

fn plan_line<const N: usize, const K: usize>(
    sc: &Scenario<'_, N>,
    line: &Line<N>,
    cfg: PlannerConfig,
    input: &Input,
) -> Outcome {
    let planner = Planner::<K, N>::new(cfg);
    assert_eq!(
        planner.is_ok(),
        cfg.validate().is_ok(),
        "Planner::new and PlannerConfig::validate disagree on {cfg:?}"
    );
    let Ok(mut planner) = planner else {
        return Outcome::Settings;
    };
    let tracks = sc.waypoints().tracks();
    let first = usize::from(input.first_track) % (tracks + 1);
    let (track_len, len) = line.lengths();
    let wp = sc.waypoints().positions();
    let mut state: VehicleState<N> = input.start.state(
        wp.get(first).copied().unwrap_or(wp[0]),
        track_len,
        len,
        sc.default_initial_depth(),
    );
    let mu = cfg.penalty_weight * 100_f32.powi(cfg.penalty_stages.min(8) as i32 - 1);
    let physical = line.physical
        && state_is_physical(&state)
        && mu <= PHYSICAL_PENALTY
        && cfg.bfgs.first_step <= crate::line::PHYSICAL_LENGTH
        && cfg.bfgs.max_step <= crate::line::PHYSICAL_LENGTH;
    let calls = 1 + usize::from(input.calls % 5);
    let mut last = None;
    for (done, track) in (first..first + calls).enumerate() {
        if done > 0 && track >= tracks {
            break;
        }
        let result = planner.plan(sc, &state, track);
        // The first state only: a predicted one keeps a compensation term
        // that `x()` rounds away.
        if let Some(expected) = bad_start(sc, &state, track).filter(|_| done == 0) {
            let reported = result.as_ref().err();
            let known = crate::known::START_ERROR_AS_DIVERGED
                && reported == Some(&PlanError::Sim(SimError::Diverged));
            assert!(
                reported == Some(&PlanError::Sim(expected)) || known,
                "a start state the simulation rejects with {expected:?}: plan gives {:?}",
                result.as_ref().map(|p| p.depth)
            );
        }
        match result {
            Ok(plan) => {
                check(sc, &cfg, &state, track, (&plan, &planner), physical);
                state = plan.next_state;
                last = Some(plan.status);
            }
            // A predicted start in the rock: the tool's climb, with the
            // worlds carried through it (`Planner::carry`), then on.
            Err(PlanError::StartBelowBottom) if done > 0 => {
                let shallow = sc.mission().depth_limits()[0];
                match planner.carry(sc, &state, track, shallow) {
                    Ok(next) => {
                        assert!(state_is_finite(&next), "carry: a state not finite");
                        assert!(planner.continuation().is_empty());
                        state = next;
                    }
                    Err(e) => return Outcome::Error(done, e, physical),
                }
            }
            Err(e) => {
                if track >= tracks {
                    assert_eq!(e, PlanError::TrackRange);
                }
                return Outcome::Error(done, e, physical);
            }
        }
    }
    last.map_or(Outcome::Rejected, Outcome::Planned)
}

/// The error the simulation gives for `state` on `track`, when it is not
/// a state to fly that track from (not finite, or not on the track).
fn bad_start<const N: usize>(
    sc: &Scenario<'_, N>,
    state: &VehicleState<N>,
    track: usize,
) -> Option<SimError> {
    let wp = sc.waypoints().positions();
    let (&a, &b) = (wp.get(track)?, wp.get(track + 1)?);
    if !state_is_finite(state) {
        Some(SimError::NonFiniteState)
    } else if state.x() - a >= 0.0 && state.x() - b < 0.0 {
        None
    } else {
        Some(SimError::StateOffTrack)
    }
}

/// The contract of one plan (`physical`: the input's magnitudes are, see
/// [`crate::known`]).
pub fn check<const N: usize, const K: usize>(
    sc: &Scenario<'_, N>,
    cfg: &PlannerConfig,
    state: &VehicleState<N>,
    track: usize,
    (plan, planner): (&Plan<N>, &Planner<K, N>),
    physical: bool,
) {
    if known::applies(known::ABSURD_OVERFLOW, physical) {
        check_finite(track, plan, planner);
    }
    check_contract(sc, cfg, state, track, (plan, planner));
}

fn check_finite<const N: usize, const K: usize>(
    track: usize,
    plan: &Plan<N>,
    planner: &Planner<K, N>,
) {
    let finite = [
        plan.depth,
        plan.j,
        plan.rms,
        plan.min_altitude,
        plan.objective,
        plan.grad_norm,
    ];
    assert!(
        finite.iter().all(|v| v.is_finite()),
        "non-finite plan on track {track}: {plan:?}"
    );
    assert!(
        planner.history().iter().all(|v| v.is_finite()),
        "non-finite history: {plan:?}"
    );
    assert!(
        state_is_finite(&plan.next_state),
        "non-finite next state: {plan:?}"
    );
    assert!(
        plan.j >= 0.0 && plan.rms >= 0.0,
        "negative J or RMS: {plan:?}"
    );
}

fn check_contract<const N: usize, const K: usize>(
    sc: &Scenario<'_, N>,
    cfg: &PlannerConfig,
    state: &VehicleState<N>,
    track: usize,
    (plan, planner): (&Plan<N>, &Planner<K, N>),
) {
    let tracks_left = sc.waypoints().tracks() - track;
    let h = plan.horizon_len;
    assert!(
        h >= 1 && h <= K && h <= tracks_left,
        "horizon_len {h} with K = {K}, {tracks_left} tracks left"
    );
    if cfg.mode == Mode::TrackWise {
        assert_eq!(h, 1, "track-wise plan over {h} tracks");
    }
    let [lo, hi] = sc.mission().depth_limits();
    // Rounding of the scan grid (crate::known::SCAN_GRID_ROUNDING).
    let slack = if crate::known::SCAN_GRID_ROUNDING {
        4.0 * f32::EPSILON * lo.abs().max(hi.abs())
    } else {
        0.0
    };
    let (lo, hi) = (lo - slack, hi + slack);
    assert!(
        plan.depth >= lo && plan.depth <= hi,
        "depth {} outside the limits [{lo}, {hi}]",
        plan.depth
    );
    assert_eq!(planner.horizon().len(), h);
    assert_eq!(planner.horizon()[0].to_bits(), plan.depth.to_bits());
    for &z in planner.horizon() {
        assert!(
            z.is_finite() && z >= lo && z <= hi,
            "horizon depth {z} outside the limits [{lo}, {hi}]: {plan:?}"
        );
    }

    let h_safe = sc.mission().min_altitude() + cfg.safety_margin;
    // Safe is certified; infeasible exactly when not. A certified track is
    // safe for the model; nothing uncertain is declared here, so the
    // certificate of the track alone is its nominal flight, and in
    // unconstrained planning that is all `safe` says (constrained, the
    // other switch of a knife edge too, and in horizon mode the
    // continuation must certify too).
    assert_eq!(plan.safe, plan.status != PlanStatus::Infeasible, "{plan:?}");
    // (A single track on a floor set by its arrival, over `h_a` but
    // inside the margin, is certified against that floor: `single.rs`.)
    if plan.safe {
        let h_a = sc.mission().min_altitude();
        let floor = plan.status == PlanStatus::Constrained && plan.horizon_len == 1;
        let bar = if floor { h_a } else { h_safe };
        assert!(
            plan.min_altitude >= bar,
            "safe at {} < {bar}: {plan:?}",
            plan.min_altitude
        );
    }
    assert_eq!(
        plan.certified_min_altitude.to_bits(),
        plan.min_altitude.to_bits(),
        "certified {} vs nominal {} with nothing declared",
        plan.certified_min_altitude,
        plan.min_altitude
    );
    // (Constrained, the certificate also flies a knife edge's other switch
    // after an earlier track ended on it, in either mode: `knife.rs`.)
    if !cfg.constrained && !plan.safe {
        assert!(plan.min_altitude < h_safe, "{plan:?}");
    }
    assert!(
        plan.iterations <= cfg.bfgs.max_iterations,
        "{} iterations, cap {}: {plan:?}",
        plan.iterations,
        cfg.bfgs.max_iterations
    );
    assert!(planner.history().len() <= HISTORY);
    assert!(plan.evaluations >= 1, "a plan without a simulation");

    // The committed depth, flown on its own.
    let mut score = [TrackScore::default()];
    let end = sc.simulate(state, track, &[plan.depth], &mut score, |_| {});
    let end = match end {
        Ok(e) => e,
        Err(e) => panic!("the planned depth {} does not fly: {e}", plan.depth),
    };
    let s = score[0];
    let same = |a: f32, b: f32| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
    assert!(
        same(s.j(), plan.j) && same(s.min_altitude(), plan.min_altitude) && end == plan.next_state,
        "re-simulation differs: J {} vs {}, min altitude {} vs {}, end {end:?} vs {:?}",
        s.j(),
        plan.j,
        s.min_altitude(),
        plan.min_altitude,
        plan.next_state
    );
}
