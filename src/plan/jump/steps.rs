//! The steps of a plateau's scan between neighbouring points (module
//! docs of `jump`): off the plateau, into a lower `J` beyond the band, to
//! a cliff or a dip, and their bisections.

use crate::sim::{TrackScore, VehicleState};

use super::super::objective::PlanObjective;
use super::super::scan::{grid, with_depth};
use super::super::solve::lex_less;

/// Bisections of a scan's step from a point within the band to one
/// beyond it with a lower `J`, or off the plateau to beyond the band.
pub(super) const EDGE: u32 = 3;

/// A scanned point's `J` within this share of the optimum's is on its
/// plateau.
const FLAT: f32 = 1e-5;

/// A scanned point: `(z_j, Σ J, v)`, m, m³, m.
pub(super) type Point = (f32, f32, f32);

/// A step between two scanned points.
pub(super) type Step = (Point, Point);

/// The steps a scan found between its neighbouring points.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Steps {
    /// Off the optimum's plateau to within the band, the lowest off side:
    /// `(on, off)`.
    pub held: Option<Step>,
    /// Into a lower `J` beyond the band from within it, the lowest far
    /// side: `(within, beyond)`.
    pub edge: Option<Step>,
    /// The first off the plateau to beyond the band: `(on, off)`.
    pub cliff: Option<Step>,
    /// The first off the plateau to a lower `J` short of its targets
    /// within the band: `(on, off)`.
    pub dip: Option<Step>,
}

impl Steps {
    /// The steps once the scan has stepped `(a, b)`, off the plateau
    /// `plateau` (its `J`, m³, and shortfall, m; [`flat`]) within `band`
    /// (m of shortfall).
    pub(super) fn see(&mut self, (a, b): Step, plateau: (f32, f32), band: f32) {
        self.edge = lower_edge(self.edge, (a, b), band);
        self.held = off_plateau(self.held, (a, b), plateau, band);
        self.cliff = self.cliff.or_else(|| off_cliff((a, b), plateau, band));
        self.dip = self.dip.or_else(|| off_dip((a, b), plateau, band));
    }
}

/// The point `z_j = zj` (m) of `z`, whose tracks before `j` flew `head`
/// and left `at_j`: one flight of the tail; `None` if it failed.
pub(super) fn at_depth<const K: usize, const N: usize>(
    obj: &mut PlanObjective<'_, N>,
    (head, at_j, j): (&[TrackScore; K], &VehicleState<N>, usize),
    zj: f32,
    z: &[f32; K],
) -> Option<Point> {
    let (jz, v) = obj
        .tail_value(head, (at_j, j), &with_depth(z, j, zj))
        .ok()?;
    Some((zj, jz, v))
}

/// Whether point `p` is on the plateau of `J` `j` (m³): its `J` within
/// [`FLAT`] of it, its shortfall at most `v` (m).
pub(super) fn flat(p: Point, (j, v): (f32, f32)) -> bool {
    libm::fabsf(p.1 - j) <= FLAT * j && p.2 <= v
}

/// `held`, or `step` between neighbouring scanned points if it leaves the
/// plateau `plateau` ([`flat`]) to a point within `band` (m of shortfall)
/// whose `J` is lower than `held`'s off side: `(on, off)`.
fn off_plateau(held: Option<Step>, step: Step, plateau: (f32, f32), band: f32) -> Option<Step> {
    match leaving(step, plateau) {
        Some((on, off)) if off.2 <= band && held.is_none_or(|(_, e)| off.1 < e.1) => {
            Some((on, off))
        }
        _ => held,
    }
}

/// `step` between neighbouring scanned points if it leaves the plateau
/// `plateau` ([`flat`]) to a point beyond `band` (m of shortfall):
/// `(on, off)`.
fn off_cliff(step: Step, plateau: (f32, f32), band: f32) -> Option<Step> {
    leaving(step, plateau).filter(|(_, off)| off.2 > band)
}

/// The step `(a, b)` as `(on, off)` where exactly one of its points is
/// on the plateau `plateau` ([`flat`]).
fn leaving((a, b): Step, plateau: (f32, f32)) -> Option<Step> {
    match (flat(a, plateau), flat(b, plateau)) {
        (true, false) => Some((a, b)),
        (false, true) => Some((b, a)),
        _ => None,
    }
}

/// The scan of `z_j` over `n` points evenly spaced on `[lo, hi]` (m; one
/// flight of the tail each, the tracks before `j` flown as in `flown`),
/// each offered to `keep`: its steps off the plateau `plateau` within
/// `band` (none where `restoring`: the optimum is short of its targets)
/// and whether `keep` kept any point.
pub(super) fn scan_steps<const K: usize, const N: usize>(
    obj: &mut PlanObjective<'_, N>,
    (flown, z): ((&[TrackScore; K], &VehicleState<N>, usize), &[f32; K]),
    (lo, hi, n): (f32, f32, u32),
    (plateau, band, restoring): ((f32, f32), f32, bool),
    keep: &mut impl FnMut(Point) -> bool,
) -> (Steps, bool) {
    let (mut steps, mut kept, mut prev) = (Steps::default(), false, None::<Point>);
    for k in 0..n {
        let Some(p) = at_depth(obj, flown, grid(lo, hi, k, n), z) else {
            continue;
        };
        kept |= keep(p);
        if let Some(q) = prev.filter(|_| !restoring) {
            steps.see((q, p), plateau, band);
        }
        prev = Some(p);
    }
    (steps, kept)
}

/// The scan's steps bisected, [`EDGE`] times each (one flight of the tail
/// each; module docs): `edge`, from within `band` (m of shortfall) to a
/// lower `J` beyond it, for the feasible point nearest the cliff; then,
/// where no point of it was kept, `cliff`, off the plateau `plateau`
/// ([`flat`]) to beyond the band, for the first point off the plateau
/// within it. Each point flown of `z` (tracks before `j` flown as in
/// `flown`) is offered to `keep`, which tells whether it was kept.
/// Returns the cliff's step off the plateau to within the band that its
/// bisection found, `(on, off)`, if any: a held edge's step (module docs
/// of `jump`).
pub(super) fn bisect_steps<const K: usize, const N: usize>(
    obj: &mut PlanObjective<'_, N>,
    (flown, z): ((&[TrackScore; K], &VehicleState<N>, usize), &[f32; K]),
    (edge, cliff): (Option<Step>, Option<Step>),
    (band, plateau): (f32, (f32, f32)),
    keep: &mut impl FnMut(Point) -> bool,
) -> Option<Step> {
    let mut kept = false;
    if let Some(step) = edge {
        bisect(obj, (flown, z), step, |p| {
            kept |= keep(p);
            Some(p.2 <= band)
        });
    }
    let step = cliff.filter(|_| !kept)?;
    let (mut on, mut within) = (step.0, None);
    bisect(obj, (flown, z), step, |p| {
        if flat(p, plateau) {
            on = p;
            Some(true)
        } else if p.2 <= band {
            keep(p);
            within = Some((on, p));
            None
        } else {
            Some(false)
        }
    });
    within
}

/// `step` `(a, b)` bisected [`EDGE`] times, one flight of the tail each
/// (as [`at_depth`]): `side` tells which end each midpoint replaces
/// (`true`: `a`), or that the bisection stops there (`None`); so does a
/// flight that fails.
fn bisect<const K: usize, const N: usize>(
    obj: &mut PlanObjective<'_, N>,
    (flown, z): ((&[TrackScore; K], &VehicleState<N>, usize), &[f32; K]),
    (mut a, mut b): Step,
    mut side: impl FnMut(Point) -> Option<bool>,
) {
    for _ in 0..EDGE {
        let Some(p) = at_depth(obj, flown, 0.5 * (a.0 + b.0), z) else {
            return;
        };
        match side(p) {
            Some(true) => a = p,
            Some(false) => b = p,
            None => return,
        }
    }
}

/// `step` between neighbouring scanned points if it leaves the plateau
/// `plateau` ([`flat`]) to a point short of its targets (beyond the
/// plateau's shortfall) within `band` (m of shortfall) whose `J` is lower
/// than the plateau's: `(on, off)`.
fn off_dip(step: Step, plateau: (f32, f32), band: f32) -> Option<Step> {
    leaving(step, plateau)
        .filter(|(_, off)| off.2 > plateau.1 && off.2 <= band && off.1 < plateau.0)
}

/// The step `(on, off)` off the plateau to a lower `J` short of its
/// targets ([`off_dip`]) bisected [`EDGE`] times (one flight of the tail
/// each) towards the dip: of the points `kept` scores (a restart's start),
/// the one of least score, with it, if any.
pub(super) fn bisect_dip<const K: usize, const N: usize>(
    obj: &mut PlanObjective<'_, N>,
    (flown, z): ((&[TrackScore; K], &VehicleState<N>, usize), &[f32; K]),
    (step, plateau): (Step, (f32, f32)),
    kept: impl Fn(Point) -> Option<(f32, f32)>,
) -> Option<((f32, f32), Point)> {
    let mut least: Option<((f32, f32), Point)> = None;
    bisect(obj, (flown, z), step, |p| match kept(p) {
        Some(s) => {
            least = least.filter(|l| !lex_less(s, l.0)).or(Some((s, p)));
            Some(true)
        }
        None => Some(flat(p, plateau)),
    });
    least
}

/// `edge`, or the step `(a, b)` between neighbouring scanned points if one
/// is within `band` (m of shortfall) and the other beyond it with a lower
/// `J`, lower than `edge`'s far side.
fn lower_edge(edge: Option<Step>, (a, b): Step, band: f32) -> Option<Step> {
    let step = match (a.2 <= band, b.2 <= band) {
        (true, false) => (a, b),
        (false, true) => (b, a),
        _ => return edge,
    };
    let (inside, beyond) = step;
    let lower = beyond.1 < inside.1 && edge.is_none_or(|(_, e)| beyond.1 < e.1);
    if lower { Some(step) } else { edge }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plateau of `unseen_3113_7`'s track 1 (`J`, shortfall + tol).
    const PLATEAU: (f32, f32) = (2.680_518e6, 0.035);
    const ON: Point = (138.2, 2.680_518e6, 0.015);

    #[test]
    fn a_step_off_the_plateau_to_a_lower_j_short_within_the_band_is_a_dip() {
        let off = (223.4, 2.623_723e6, 13.06);
        let mut steps = Steps::default();
        steps.see((ON, off), PLATEAU, 15.0);
        assert_eq!(steps.dip, Some((ON, off)));
        assert_eq!(steps.cliff, None);
        // Either way round; the first only.
        let mut back = Steps::default();
        back.see((off, ON), PLATEAU, 15.0);
        assert_eq!(back.dip, Some((ON, off)));
        back.see((ON, (250.0, 2.0e6, 14.0)), PLATEAU, 15.0);
        assert_eq!(back.dip, Some((ON, off)));
        // Not a dip: a higher `J`, beyond the band (a cliff), as
        // feasible as the plateau, or a step along the plateau.
        let dip = |p: Point| off_dip((ON, p), PLATEAU, 15.0);
        assert_eq!(dip((223.4, 2.7e6, 13.06)), None);
        assert_eq!(dip((223.4, 2.6e6, 16.0)), None);
        assert!(off_cliff((ON, (223.4, 2.6e6, 16.0)), PLATEAU, 15.0).is_some());
        assert_eq!(dip((223.4, 2.6e6, 0.02)), None);
        assert_eq!(dip((150.0, 2.680_518e6, 0.015)), None);
    }
}
