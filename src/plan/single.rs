//! A constrained single track (track-wise mode, the last track of a
//! horizon). The scan gives each scanned depth's minimum altitude. When the
//! scan's best depth is unsafe, or safe with its parabola pointing to an
//! unsafe neighbour, the optimum of `J` lies beyond the safe set and the
//! constrained optimum on its boundary next to it: the root search of
//! [`super::fallback::boundary`] finds it in a few plain flights, and a
//! finite difference of `J` there confirms that `J` does not decrease into
//! the safe set (if it does, the optimizer runs from there). With no
//! scanned depth safe, the track is infeasible, unless its least altitude
//! is a floor set by the arrival that clears `h_a` inside the planner's
//! margin: then the floor's least `J` is answered, certified against the
//! floor ([`safest`]).

use crate::optim::Outcome;

use super::PlanError;
use super::fallback::{Flown, boundary, fallback};
use super::flights::Flights;
use super::objective::teeth;
use super::scan::ScanLog;
use super::status::{Found, OptimizerStop};

/// The finite-difference step, m, that checks a boundary optimum (`J` must
/// not decrease into the safe set).
pub(super) const CHECK_STEP: f32 = 2.0;

/// Where `J` rises over the check's step, the second look's share of it:
/// an interior optimum within the first step leaves `J` higher at its end.
pub(super) const CHECK_SHORT: f32 = 0.25;

/// How far below the safest scanned altitude (m) a depth still shares
/// it: the floor of [`safest`].
const FLOOR: f32 = 1e-4;

/// One end of a boundary bracket: a depth (m) and its minimum altitude
/// (m) when known.
type End = (f32, Option<f32>);

/// What the scan says of a single track.
pub(super) enum Decision<const N: usize> {
    /// Answered without the optimizer.
    Done(Flown<N>, Found),
    /// Answered on the arrival's floor (m, the altitude the answer
    /// clears): no depth clears the planner's margin over `h_a`, every
    /// depth of the floor clears `h_a` ([`safest`]).
    Floor(Flown<N>, f32),
    /// Optimize, from `z0` (with the scan's curvature unless `flat`).
    Optimize { z0: f32, flat: bool },
}

/// Decides from the scanned minimum altitudes whether the optimum lies
/// beyond the safe set (and answers with the boundary search), whether
/// nothing is safe (infeasible), or whether the optimizer should run,
/// possibly from a better start. `vertex` is the scan's start point.
pub(super) fn decide<const N: usize>(
    fl: &mut Flights<'_, '_, N>,
    scan: &ScanLog,
    vertex: f32,
    (h_a, h_safe): (f32, f32),
    steps: u32,
) -> Result<Decision<N>, PlanError> {
    match bracket(scan, vertex, h_safe) {
        Bracket::Infeasible => match safest(fl, scan, (vertex, h_a), steps)? {
            (f, Some(floor)) => Ok(Decision::Floor(f, floor)),
            (f, None) => Ok(Decision::Done(f, Found::Infeasible(OptimizerStop::None))),
        },
        Bracket::None => Ok(Decision::Optimize {
            z0: vertex,
            flat: false,
        }),
        Bracket::Found(good, bad) => {
            let b = boundary(fl, good, bad, h_safe, steps)?;
            let z_b = b.at.depth;
            // Does `J` decrease from the boundary into the safe set? A
            // finite difference towards the safe side: the search's previous
            // safe depth when within `CHECK_STEP` (no extra flight), else
            // one flight there.
            let inward = good.0 - z_b;
            let step = CHECK_STEP.min(libm::fabsf(inward)).copysign(inward);
            // (Where the depth loop integrates, `J` has teeth a few
            // centimetres wide: a previous depth closer than the second
            // look's step reads a tooth's slope, not the trend.)
            let least = if teeth(&fl.sc) {
                CHECK_SHORT * CHECK_STEP
            } else {
                0.0
            };
            let near = b
                .inner
                .filter(|p| (least..=CHECK_STEP).contains(&libm::fabsf(p.0 - z_b)));
            let (z_in, j_in) = match near {
                Some(p) => p,
                None => {
                    let z = z_b + step;
                    (z, fl.fly(z).map_or(f32::INFINITY, |(s, _)| s.j()))
                }
            };
            let slope = (j_in - b.at.score.j()) / (z_in - z_b);
            // (Where `J` rises over that step, the optimum may still lie
            // within it: a second look, one flight.)
            let mut short = || {
                let z = z_b + CHECK_SHORT * step;
                fl.fly(z).is_ok_and(|(s, _)| s.j() < b.at.score.j())
            };
            if slope * inward < 0.0 || (libm::fabsf(z_in - z_b) > 0.5 * CHECK_STEP && short()) {
                // An interior optimum: optimize from the boundary.
                Ok(Decision::Optimize {
                    z0: z_b,
                    flat: true,
                })
            } else {
                Ok(Decision::Done(b.at, Found::Boundary(OptimizerStop::None)))
            }
        }
    }
}

/// No scanned depth is safe: the safest one. Where several share the
/// safest altitude (within [`FLOOR`]) and it clears `h_a` (m: safe in the
/// model, inside the planner's margin only), it is a floor the depth does
/// not move (the track's least altitude set where it begins, by the
/// arrival), and the answer is the least `J` on that floor: the scanned
/// one, or the floor's edge by the boundary search towards a lower `J`
/// beyond it. (Below `h_a` the first safest depth stays the answer: on the
/// 256 random lines of BENCHMARKS.md, the least `J` on such a floor moved
/// 85 unsafe lines track by track, 7 of them to lower flights later on.)
/// Returns the answer and, where it is on such a floor, the floor (m).
/// (`check_planner.py --seed 2530 --vehicle .../low.toml`,
/// `unseen_2530_2` track 3: every depth down to 1 131.5 m leaves the track
/// 28.0016 m above its bottom, 0.4 mm inside the margin; the first safest
/// scanned depth, 987.4 m, was 6.7× the f64 best `J` at 1 131.5 m.)
fn safest<const N: usize>(
    fl: &mut Flights<'_, '_, N>,
    scan: &ScanLog,
    (vertex, h_a): (f32, f32),
    steps: u32,
) -> Result<(Flown<N>, Option<f32>), PlanError> {
    let (z_safest, top) = scan
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((vertex, f32::NEG_INFINITY));
    let floor = top - FLOOR;
    let on_floor = scan.iter().filter(|e| e.1 >= floor).count();
    let mut at = (z_safest, None);
    if on_floor >= 2 && floor >= h_a {
        match bracket(scan, vertex, floor) {
            Bracket::Found(good, bad) => {
                return Ok((boundary(fl, good, bad, floor, steps)?.at, Some(floor)));
            }
            Bracket::None => {
                let least = scan
                    .entries()
                    .filter(|e| e.2 >= floor && e.1.is_finite())
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                if let Some((z_l, _, _)) = least {
                    at = (z_l, Some(floor));
                }
            }
            Bracket::Infeasible => {}
        }
    }
    let (depth, kept) = at;
    let (score, next) = fl.fly(depth)?;
    Ok((Flown { depth, score, next }, kept))
}

/// What the scan brackets.
enum Bracket {
    /// Nothing scanned is safe.
    Infeasible,
    /// The optimum may be interior.
    None,
    /// (safe end, unsafe end) of the boundary next to the optimum.
    Found(End, End),
}

/// A bracket of the boundary when the scan puts the optimum beyond it.
fn bracket(scan: &ScanLog, vertex: f32, h_safe: f32) -> Bracket {
    let Some((z_best, _, alt_best)) = scan
        .entries()
        .filter(|e| e.1.is_finite())
        .min_by(|a, b| a.1.total_cmp(&b.1))
    else {
        return Bracket::None;
    };
    // The scanned neighbour of `from` in the direction of `to`.
    let neighbour = |from: f32, to: f32| {
        scan.entries()
            .filter(|e| (e.0 - from) * (to - from) > 0.0)
            .min_by(|a, b| libm::fabsf(a.0 - from).total_cmp(&libm::fabsf(b.0 - from)))
    };
    if alt_best < h_safe {
        return match scan.nearest_safe(z_best, h_safe) {
            Some(sf) => {
                let unsafe_end =
                    neighbour(sf.0, z_best).map_or((z_best, Some(alt_best)), |e| (e.0, Some(e.2)));
                Bracket::Found((sf.0, Some(sf.2)), unsafe_end)
            }
            None => Bracket::Infeasible,
        };
    }
    match neighbour(z_best, vertex) {
        Some(n) if n.2 < h_safe && libm::fabsf(vertex - z_best) > 0.0 => {
            Bracket::Found((z_best, Some(alt_best)), (n.0, Some(n.2)))
        }
        _ => Bracket::None,
    }
}

/// The optimizer of a constrained single track left the safe set at
/// `(z_bad, alt_bad)` (m, m): the optimum lies beyond the boundary it was
/// descending towards. Searches that boundary between the best safe depth
/// it evaluated (or else scanned) and the unsafe one; with none safe, the
/// general fallback. Appends the answer's `J` to `out`'s history (the
/// boundary search counts as one iteration after the optimizer's).
#[allow(clippy::too_many_arguments)]
pub(super) fn tripped<const N: usize, const K: usize>(
    fl: &mut Flights<'_, '_, N>,
    (z_bad, alt_bad): (f32, f32),
    best_safe: Option<(f32, f32, f32)>,
    out: &mut Outcome<K>,
    (lo, hi): (f32, f32),
    h_safe: f32,
    (scan_points, steps): (u32, u32),
    scan: &mut ScanLog,
) -> Result<(Flown<N>, Found), PlanError> {
    let good = match best_safe {
        Some((z, _, alt)) => Some((z, alt)),
        None => scan.nearest_safe(z_bad, h_safe).map(|e| (e.0, e.2)),
    };
    let (f, status) = match good {
        Some((z_good, alt_good)) => {
            let b = boundary(
                fl,
                (z_good, Some(alt_good)),
                (z_bad, Some(alt_bad)),
                h_safe,
                steps,
            )?;
            (b.at, Found::Boundary(OptimizerStop::Converged))
        }
        None => {
            let (f, safe) = fallback(
                fl,
                (z_bad, Some(alt_bad)),
                (lo, hi),
                h_safe,
                scan_points,
                steps,
                scan,
            )?;
            let status = if safe {
                Found::Boundary(OptimizerStop::Converged)
            } else {
                Found::Infeasible(OptimizerStop::Converged)
            };
            (f, status)
        }
    };
    if !out.history.is_empty() {
        out.iterations = out.iterations.saturating_add(1);
    }
    let _ = out.history.push(f.score.j());
    Ok((f, status))
}
