//! When the optimum is not safe: the safe depth closest to it (among the
//! scanned depths, then on the safe-set boundary by a root search), or,
//! when no depth in the box is safe, the safest one found.

use crate::model::Mission;
use crate::optim::root::{self, RootTol};
use crate::sim::{Scenario, TrackScore, VehicleState};

use super::PlanError;
use super::flights::Flights;
use super::objective::teeth;
use super::scan::{ScanLog, grid};

/// The boundary search stops when the safe end is within this much of the
/// certified altitude `h_a + m_s` at most, m (where `h_r − h_a` is 10 m or
/// more).
const BOUNDARY_ALTITUDE: f32 = 0.02;

/// ... or within this share of `h_r − h_a`, if less.
const BOUNDARY_SHARE: f32 = 0.002;

/// ... or when the bracket is this narrow, m (see `BOUNDARY_ALTITUDE`).
const BOUNDARY_DEPTH: f32 = 1e-3;

/// The first probe past a boundary with teeth, m ([`past_teeth`]).
const PAST_FIRST: f32 = 0.01;

/// Most probes past it (the last 2^5 = 32 × the first).
const PAST_PROBES: u32 = 6;

/// A depth with its flight.
#[derive(Clone, Copy, Debug)]
pub(super) struct Flown<const N: usize> {
    pub depth: f32,
    pub score: TrackScore,
    pub next: VehicleState<N>,
}

/// What [`boundary`] found.
pub(super) struct Boundary<const N: usize> {
    /// The safe end, m, with its flight.
    pub at: Flown<N>,
    /// The safe end before it, with its `J` (m, m³), if it moved.
    pub inner: Option<(f32, f32)>,
}

/// The stopping rule of every search of a safe-set boundary in depth, in
/// at most `steps` flights, for mission `m`. The altitude tolerance: `J`
/// changes by about `2 δz / (h_r − h_a)` relatively when the boundary
/// moves by `δz`, so 0.2 % of the envelope keeps that under 0.4 %; at
/// most `BOUNDARY_ALTITUDE`, at least a millimetre.
pub(super) fn boundary_rule(m: &Mission, steps: u32) -> RootTol {
    RootTol {
        tol: (BOUNDARY_SHARE * (m.reference_altitude() - m.min_altitude()))
            .clamp(BOUNDARY_DEPTH, BOUNDARY_ALTITUDE),
        width: BOUNDARY_DEPTH,
        steps,
    }
}

/// The safe-set boundary between a safe depth `good` and an unsafe one
/// `bad` (each with its minimum altitude when known), from the safe side:
/// [`crate::optim::root`] on `g(z) = min altitude − h_safe`, stopped by
/// [`boundary_rule`].
pub(super) fn boundary<const N: usize>(
    fl: &mut Flights<'_, '_, N>,
    good: (f32, Option<f32>),
    bad: (f32, Option<f32>),
    h_safe: f32,
    steps: u32,
) -> Result<Boundary<N>, PlanError> {
    let rule = boundary_rule(fl.sc.mission(), steps);
    let margin = |a: Option<f32>| a.map(|a| a - h_safe);
    let r = root::safe_boundary(
        (good.0, margin(good.1)),
        (bad.0, margin(bad.1)),
        rule,
        |z| fl.fly(z).map(|(s, n)| (s.min_altitude() - h_safe, (s, n))),
    )?;
    let (score, next) = match r.at {
        Some(f) => f,
        None => fl.fly(r.z)?,
    };
    let at = Flown {
        depth: r.z,
        score,
        next,
    };
    Ok(Boundary {
        at: if teeth(&fl.sc) {
            past_teeth(fl, at, bad.0, h_safe)
        } else {
            at
        },
        inner: r.inner.map(|(z, (s, _))| (z, s.j())),
    })
}

/// A boundary `at` of a least altitude with teeth (a depth loop that
/// integrates conditionally, `polish.rs`): where the trend of the least
/// altitude crosses `h_safe` (m) slowly, teeth past the crossing the root
/// search found still clear it (on `check_planner.py --seed 2933
/// --vehicle tools/reference/vehicles/twoki.toml`, `unseen_2933_0` track
/// 2, constrained, teeth 8 cm wide and 1 cm high on a trend of 6 cm per
/// metre: the boundary at 581.20 m, safe teeth to 581.44 m, `J` 1.0059×
/// the best safe). Probes towards the unsafe end `bad` (m), doubling from
/// [`PAST_FIRST`]: the lowest `J` of those that clear `h_safe`, else
/// `at`. At most [`PAST_PROBES`] flights; a refused one ends them.
fn past_teeth<const N: usize>(
    fl: &mut Flights<'_, '_, N>,
    at: Flown<N>,
    bad: f32,
    h_safe: f32,
) -> Flown<N> {
    let toward = bad - at.depth;
    let (mut best, mut step) = (at, PAST_FIRST);
    for _ in 0..PAST_PROBES {
        if step >= libm::fabsf(toward) {
            break;
        }
        let depth = at.depth + step.copysign(toward);
        let Ok((score, next)) = fl.fly(depth) else {
            break;
        };
        if score.min_altitude() >= h_safe && score.j() < best.score.j() {
            best = Flown { depth, score, next };
        }
        step *= 2.0;
    }
    best
}

/// The verification fallback of a single track whose optimum `opt` falls
/// below the aimed altitude `h_aim` (m): the boundary from the warm start
/// `warm` (m, [`from_warm`]) when it flies safe, else the closest safe
/// depth ([`fallback`]). Returns the answer and whether it clears the aim.
///
/// Where the aim is the certified altitude `h_cert` (m) raised by a gap
/// an earlier call's screening kept (`gaps.rs`, `candidate_aimed`) and no
/// depth meets it, the aim is dropped: the optimum if it clears `h_cert`,
/// else the same fallback towards `h_cert`, kept where it clears it.
/// Where the track's least altitude is a floor set by its arrival, below
/// the aim, the fallback answered the first safest scanned depth, not the
/// least `J` on the floor (`check_planner.py --seed 3015 --vehicle
/// tools/reference/vehicles/fast.toml`, `unseen_3015_3`, track 5: the
/// floor 22.028 m down to 1 074 m, 2.6 cm over `h_cert`, the aim 8.5 cm
/// over it from a branch at waypoint 3 two calls before; the answer was
/// 1 029.4 m, `J` 1.20e6 against 3.1e5 m³ at 1 074 m). The scan is
/// shared: the second fallback flies only its boundary search.
pub(super) fn closest_safe<const N: usize>(
    fl: &mut Flights<'_, '_, N>,
    (opt, warm): (&Flown<N>, Option<f32>),
    (lo, hi): (f32, f32),
    (h_aim, h_cert): (f32, f32),
    (scan_points, steps): (u32, u32),
    log: &mut ScanLog,
) -> Result<(Flown<N>, bool), PlanError> {
    let toward = |fl: &mut Flights<'_, '_, N>, h_safe: f32, log: &mut ScanLog| {
        let at = (opt.depth, opt.score.min_altitude());
        if let Some(z0) = warm
            && let Some(f) = from_warm(fl, z0, at, h_safe, steps)?
        {
            return Ok((f, true));
        }
        let bad = (at.0, Some(at.1));
        fallback(fl, bad, (lo, hi), h_safe, scan_points, steps, log)
    };
    let aimed = toward(fl, h_aim, log)?;
    if aimed.1 || h_cert >= h_aim {
        return Ok(aimed);
    }
    if opt.score.min_altitude() >= h_cert {
        return Ok((*opt, true));
    }
    let dropped = toward(fl, h_cert, log)?;
    Ok(if dropped.1 { dropped } else { aimed })
}

/// A warm-started single track (the last of a horizon) whose optimum
/// `(z_opt, alt_opt)` (m, m) fell below `h_safe`: the boundary between the
/// warm start `z0` (the continuation's depth, which the previous call
/// certified) and that optimum, when `z0` flies safe here. The general
/// fallback picks the scanned safe depth nearest the optimum instead,
/// which on a hinge (the least altitude flat on one side, falling slowly
/// on the other) can lie far beyond the boundary: on a random canyon line
/// (`check_planner.py --seed 41`, `unseen_41_5`) the last track went from
/// its safe 136.95 m to 68.8 m, its `J` 2.33e6 to 5.71e6 m³.
pub(super) fn from_warm<const N: usize>(
    fl: &mut Flights<'_, '_, N>,
    z0: f32,
    (z_opt, alt_opt): (f32, f32),
    h_safe: f32,
    steps: u32,
) -> Result<Option<Flown<N>>, PlanError> {
    if z0.to_bits() == z_opt.to_bits() {
        return Ok(None);
    }
    let (s0, _) = fl.fly(z0)?;
    if s0.min_altitude() < h_safe {
        return Ok(None);
    }
    let b = boundary(
        fl,
        (z0, Some(s0.min_altitude())),
        (z_opt, Some(alt_opt)),
        h_safe,
        steps,
    )?;
    Ok((b.at.score.min_altitude() >= h_safe).then_some(b.at))
}

/// The safe depth closest to `z_opt` in `[lo, hi]` (flagged safe), or the
/// safest depth when none is safe.
#[allow(clippy::too_many_arguments)]
pub(super) fn fallback<const N: usize>(
    fl: &mut Flights<'_, '_, N>,
    (z_opt, alt_opt): (f32, Option<f32>),
    (lo, hi): (f32, f32),
    h_safe: f32,
    scan_points: u32,
    steps: u32,
    log: &mut ScanLog,
) -> Result<(Flown<N>, bool), PlanError> {
    if log.is_empty() {
        for k in 0..scan_points {
            let z = grid(lo, hi, k, scan_points);
            if let Ok((s, _)) = fl.fly(z) {
                log.push(z, &s);
            }
        }
    }
    match log.nearest_safe(z_opt, h_safe) {
        Some((z_safe, _, alt_safe)) => {
            let b = boundary(
                fl,
                (z_safe, Some(alt_safe)),
                (z_opt, alt_opt),
                h_safe,
                steps,
            )?;
            let safe = b.at.score.min_altitude() >= h_safe;
            Ok((b.at, safe))
        }
        None => {
            let z = log
                .safest()
                .ok_or(PlanError::Sim(crate::sim::SimError::Diverged))?;
            let (score, next) = fl.fly(z)?;
            Ok((
                Flown {
                    depth: z,
                    score,
                    next,
                },
                false,
            ))
        }
    }
}

/// The committed depth's flight: the candidate's when the depth is its,
/// else flown (one more flight in `flights`).
pub(super) fn fly_committed<const N: usize>(
    sc: &Scenario<'_, N>,
    (state, track): (&VehicleState<N>, usize),
    depth: f32,
    candidate: Flown<N>,
    flights: &mut u32,
) -> Result<Flown<N>, PlanError> {
    if depth.to_bits() == candidate.depth.to_bits() {
        return Ok(candidate);
    }
    let mut fl = Flights {
        sc: *sc,
        state,
        track,
        count: *flights,
        limit: u32::MAX,
    };
    let (score, next) = fl.fly(depth)?;
    *flights = fl.count;
    Ok(Flown { depth, score, next })
}
