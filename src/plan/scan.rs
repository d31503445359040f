//! The starting point: the box of depths worth searching, and a coarse
//! scan of it track by track (model contract §10: never start on a
//! plateau that is not the best scanned value).

use crate::num::DEG;
use crate::optim::Bounds;
use crate::sim::{Scenario, TrackScore, VehicleState};

use super::flights::Flights;
use super::{MAX_SCAN, PlanError};

/// Point `k` of `n >= 2` evenly spaced over `[lo, hi]`.
pub(super) fn grid(lo: f32, hi: f32, k: u32, n: u32) -> f32 {
    let z = lo + (hi - lo) * (k as f32) / (n.saturating_sub(1).max(1) as f32);
    // Rounding must not put a point outside the box (hence, possibly,
    // outside the depth limits).
    if z > hi {
        hi
    } else if z < lo {
        lo
    } else {
        z
    }
}

/// The horizon `z` with depth `j` at `zj` (m); `z` itself past its end.
pub(super) fn with_depth<const K: usize>(z: &[f32; K], j: usize, zj: f32) -> [f32; K] {
    let mut out = *z;
    if let Some(v) = out.get_mut(j) {
        *v = zj;
    }
    out
}

/// What the reach of a track's depth is made of: `sin` of the steepest
/// flight path (a little over the pitch limit) and the depth error that
/// saturates the pitch reference plus 20 m (m).
fn reach_terms<const N: usize>(sc: &Scenario<'_, N>) -> (f32, f32) {
    let ap = sc.vehicle().autopilot().config();
    let angle = ((1.3 * ap.pitch_limit).min(90.0) * DEG).min(core::f32::consts::FRAC_PI_2);
    let (sin, _) = crate::num::sin_cos(angle);
    let saturation = if ap.depth_pid.kp > 0.0 {
        3.0 * ap.pitch_limit / ap.depth_pid.kp
    } else {
        f32::INFINITY
    };
    (sin, saturation + 20.0)
}

/// The depths of track `t` worth scanning from a state at depth `d` (m)
/// at its start: within `d ± (L sin θ + saturation + 20 m)` (beyond, the
/// pitch reference stays saturated over the whole track and the flight
/// does not change), inside `[lo, hi]`.
pub(super) fn reach_from<const N: usize>(
    sc: &Scenario<'_, N>,
    t: usize,
    d: f32,
    (lo, hi): (f32, f32),
) -> (f32, f32) {
    let (sin, base) = reach_terms(sc);
    let wp = sc.waypoints().positions();
    let len = match (wp.get(t), wp.get(t.saturating_add(1))) {
        (Some(a), Some(b)) => b - a,
        _ => 0.0,
    };
    let reach = base + len * sin;
    ((d - reach).max(lo).min(hi), (d + reach).max(lo).min(hi))
}

/// The box of depths worth searching for each track of the horizon (see
/// the module docs of [`crate::plan`]); variables past `h` are pinned.
pub(super) fn search_box<const N: usize, const K: usize>(
    sc: &Scenario<'_, N>,
    state: &VehicleState<N>,
    track: usize,
    h: usize,
) -> Bounds<K> {
    let (sin, base) = reach_terms(sc);
    let [dmin, dmax] = sc.mission().depth_limits();
    let wp = sc.waypoints().positions();
    let d = state.depth();
    let mut reach = base;
    let mut b = Bounds::<K>::uniform(dmin, dmin);
    for j in 0..h.min(K) {
        let t = track.saturating_add(j);
        let len = match (wp.get(t), wp.get(t.saturating_add(1))) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        reach += len * sin;
        let lo = (d - reach).max(dmin).min(dmax);
        let hi = (d + reach).max(dmin).min(dmax);
        if let (Some(l), Some(u)) = (b.lo.get_mut(j), b.hi.get_mut(j)) {
            *l = lo;
            *u = hi;
        }
    }
    b
}

/// Depths tried on the committed track, with their `J` and minimum
/// altitudes.
pub(super) struct ScanLog {
    z: [f32; MAX_SCAN as usize],
    j: [f32; MAX_SCAN as usize],
    alt: [f32; MAX_SCAN as usize],
    len: usize,
}

impl Default for ScanLog {
    fn default() -> Self {
        Self {
            z: [0.0; MAX_SCAN as usize],
            j: [0.0; MAX_SCAN as usize],
            alt: [0.0; MAX_SCAN as usize],
            len: 0,
        }
    }
}

impl ScanLog {
    pub(super) fn push(&mut self, z: f32, s: &TrackScore) {
        if let (Some(zs), Some(js), Some(a)) = (
            self.z.get_mut(self.len),
            self.j.get_mut(self.len),
            self.alt.get_mut(self.len),
        ) {
            *zs = z;
            *js = s.j();
            *a = s.min_altitude();
            self.len = self.len.saturating_add(1);
        }
    }

    /// Whether nothing was logged.
    pub(super) fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// `(z, alt)` of each entry.
    pub(super) fn iter(&self) -> impl Iterator<Item = (f32, f32)> + '_ {
        self.z
            .iter()
            .copied()
            .zip(self.alt.iter().copied())
            .take(self.len)
    }

    /// The entry `(z, J, alt)` nearest to `z` (m) whose minimum altitude is
    /// at least `h_safe` (m), if any.
    pub(super) fn nearest_safe(&self, z: f32, h_safe: f32) -> Option<(f32, f32, f32)> {
        self.entries()
            .filter(|e| e.2 >= h_safe)
            .min_by(|a, b| libm::fabsf(a.0 - z).total_cmp(&libm::fabsf(b.0 - z)))
    }

    /// The safest entry's depth, m.
    pub(super) fn safest(&self) -> Option<f32> {
        self.iter().max_by(|a, b| a.1.total_cmp(&b.1)).map(|e| e.0)
    }

    /// `(z, J, alt)` of each entry.
    pub(super) fn entries(&self) -> impl Iterator<Item = (f32, f32, f32)> + '_ {
        self.z
            .iter()
            .copied()
            .zip(self.j.iter().copied())
            .zip(self.alt.iter().copied())
            .map(|((z, j), a)| (z, j, a))
            .take(self.len)
    }
}

/// The scan's result for one track: the best scanned value `phis[i]` and
/// a parabola through it and its neighbours.
struct Scanned {
    /// Objective at each grid point (`+inf` where the flight failed).
    phis: [f32; MAX_SCAN as usize],
    /// Whether the penalty acts there (a kink: no parabola through it).
    kinked: [bool; MAX_SCAN as usize],
}

/// The start of track `j` of the horizon from the scan: the parabola's
/// vertex through the best scanned value and its neighbours (a Newton step
/// for free) and, for a single track, its curvature as BFGS's first metric
/// (successive parabolic interpolation).
fn vertex(s: &Scanned, i: usize, lo: f32, hi: f32, n: u32, single: bool) -> (f32, f32) {
    let h_grid = (hi - lo) / (n.saturating_sub(1).max(1) as f32);
    let z_best = grid(lo, hi, i as u32, n);
    let smooth = i.checked_sub(1).is_some_and(|m| {
        s.kinked
            .get(m..=i.saturating_add(1))
            .is_some_and(|w| w.iter().all(|k| !k))
    });
    if !smooth || beside_plateau(s, i, n) {
        // Keep the scanned depth; the first-step scaling sets A_0.
        return (z_best, 0.0);
    }
    if let (Some(&pm), Some(&p0), Some(&pp)) = (
        i.checked_sub(1).and_then(|m| s.phis.get(m)),
        s.phis.get(i),
        s.phis
            .get(i.saturating_add(1))
            .filter(|_| i.saturating_add(1) < n as usize),
    ) {
        let second = pp - 2.0 * p0 + pm;
        if second.is_finite() && second > 0.0 && h_grid > 0.0 {
            // Per-track curvatures ignore the coupling of a horizon:
            // there the measured BFGS scaling does better.
            let c = if single {
                second / (h_grid * h_grid)
            } else {
                0.0
            };
            return (z_best - 0.5 * h_grid * (pp - pm) / second, c);
        }
    }
    (z_best, 0.0)
}

/// Whether a neighbour of the best scanned point `i` lies on a plateau:
/// its objective that of the next point out to within a millionth (the
/// pitch reference saturated over the whole track: the same flight, model
/// contract §10). A parabola through a plateau's point models nothing; its
/// vertex can land on the plateau's edge, where `J`'s gradient is next to
/// nothing, and BFGS then crawls out of it (`check_planner.py --seed 2622
/// --vehicle tools/reference/vehicles/rate.toml`, `unseen_2622_6`, track 1
/// unconstrained: the vertex 27.5 m from the best scanned depth toward the
/// plateau, `J` 5.6 % above it there, 11 iterations to the optimum).
fn beside_plateau(s: &Scanned, i: usize, n: u32) -> bool {
    let flat = |a: usize, b: usize| match (s.phis.get(a), s.phis.get(b)) {
        (Some(&pa), Some(&pb)) if a < n as usize && b < n as usize => {
            pa.is_finite() && libm::fabsf(pa - pb) <= 1e-6 * libm::fabsf(pa)
        }
        _ => false,
    };
    let left = i
        .checked_sub(2)
        .is_some_and(|o| flat(o.saturating_add(1), o));
    let right = flat(i.saturating_add(1), i.saturating_add(2));
    left || right
}

/// What the scan of a horizon needs to know.
pub(super) struct ScanSpec<'b, const K: usize> {
    /// The box.
    pub bounds: &'b Bounds<K>,
    /// Tracks already started (warm), and the horizon length.
    pub from: usize,
    pub h: usize,
    /// Grid points per track.
    pub points: u32,
    /// Penalty weight of the objective scanned.
    pub mu: f32,
    /// Whether a horizon is scanned as a beam search (else greedily,
    /// track by track: the paper's GD keeps its start).
    pub beam: bool,
    /// The beam's width (paths kept at each track, at most
    /// [`BEAM_WIDE`]).
    pub width: usize,
}

/// Coarse scan of tracks `from..h` of the horizon, each from the state
/// the best scanned depth of the previous one leaves; fills `z0` and
/// `curvature`, logs the first track's flights.
pub(super) fn scan_start<const N: usize, const K: usize>(
    fl: &mut Flights<'_, '_, N>,
    spec: &ScanSpec<'_, K>,
    z0: &mut [f32; K],
    curvature: &mut [f32; K],
    log: &mut ScanLog,
) -> Result<(), PlanError> {
    // The state at the start of track `from`, along the plan so far.
    let mut st = *fl.state;
    for j in 0..spec.from {
        let z = z0.get(j).copied().unwrap_or(0.0);
        match fl.fly_from(&st, j, z) {
            Ok((_, n)) => st = n,
            Err(e) if j == 0 => return Err(e.into()),
            Err(_) => break,
        }
    }
    if spec.beam && spec.h.saturating_sub(spec.from) >= 2 {
        return beam_scan(fl, spec, st, z0, log);
    }
    let n = spec.points;
    for j in spec.from..spec.h {
        let (lo, hi) = (
            spec.bounds.lo.get(j).copied().unwrap_or(0.0),
            spec.bounds.hi.get(j).copied().unwrap_or(0.0),
        );
        let mut s = Scanned {
            phis: [f32::INFINITY; MAX_SCAN as usize],
            kinked: [true; MAX_SCAN as usize],
        };
        let mut best: Option<(usize, VehicleState<N>)> = None;
        for k in 0..n {
            let z = grid(lo, hi, k, n);
            let Ok((sc, next)) = fl.fly_from(&st, j, z) else {
                continue;
            };
            if j == 0 {
                log.push(z, &sc);
            }
            let phi = sc.j() + spec.mu * sc.violation();
            let i = k as usize;
            if let Some(p) = s.phis.get_mut(i) {
                *p = phi;
            }
            if let Some(kk) = s.kinked.get_mut(i) {
                *kk = spec.mu > 0.0 && sc.violation() > 0.0;
            }
            if best.is_none_or(|(b, _)| s.phis.get(b).is_none_or(|&pb| phi < pb)) {
                best = Some((i, next));
            }
        }
        let Some((i, next)) = best else {
            return Err(PlanError::Sim(crate::sim::SimError::Diverged));
        };
        let (z, c) = vertex(&s, i, lo, hi, n, spec.h == 1);
        if let Some(slot) = z0.get_mut(j) {
            *slot = z;
        }
        if let Some(slot) = curvature.get_mut(j) {
            *slot = c;
        }
        st = next;
    }
    Ok(())
}

/// Paths kept by the horizon's beam scan at each track.
pub(super) const BEAM: usize = 2;

/// Paths kept by the wider beam of a second start where the cold SQP
/// ended infeasible (`wider.rs`), and the most any beam keeps.
pub(super) const BEAM_WIDE: usize = 8;

/// Paths kept by the wider beam of a second start where the cold SQP
/// ended feasible with a held track (`wider.rs`).
pub(super) const BEAM_HELD: usize = 4;

/// One path of the beam scan: its depths so far, the objective they add
/// up to and the state they leave.
#[derive(Clone, Copy)]
struct Path<const N: usize, const K: usize> {
    z: [f32; K],
    /// Grid point of the last track scanned.
    k: u32,
    phi: f32,
    st: VehicleState<N>,
}

/// Keeps `p` among the `width` lowest-objective paths of `beam`, sorted,
/// at most one per grid point of the track scanned (so that the beam keeps
/// distinct depths of it, not one depth from several parents).
fn keep<const N: usize, const K: usize>(
    beam: &mut [Option<Path<N, K>>; BEAM_WIDE],
    p: Path<N, K>,
    width: usize,
) {
    let beam = beam.get_mut(..width).unwrap_or(&mut []);
    if let Some(i) = beam.iter().position(|s| s.is_some_and(|s| s.k == p.k)) {
        if beam
            .get(i)
            .copied()
            .flatten()
            .is_some_and(|s| s.phi <= p.phi)
        {
            return;
        }
        // Drop the worse path of the same grid point, closing the gap.
        for m in i..width {
            let after = beam.get(m.saturating_add(1)).copied().flatten();
            if let Some(slot) = beam.get_mut(m) {
                *slot = after;
            }
        }
    }
    let mut cur = Some(p);
    for slot in beam.iter_mut() {
        match (cur, *slot) {
            (Some(c), Some(s)) if c.phi < s.phi => {
                *slot = Some(c);
                cur = Some(s);
            }
            (Some(c), None) => {
                *slot = Some(c);
                cur = None;
            }
            _ => {}
        }
    }
}

/// Scan of a horizon (two tracks or more from `from`) as a beam search:
/// each track's grid is flown from the end state of each of the `BEAM`
/// best paths so far, ranked by their summed objective `Σ J + μ Σ V`, so
/// that a depth which leaves a later track no safe depth loses to one that
/// does (a greedy track-by-track scan cannot see that). The best path's
/// depths start the optimizer; the first track's flights are logged.
fn beam_scan<const N: usize, const K: usize>(
    fl: &mut Flights<'_, '_, N>,
    spec: &ScanSpec<'_, K>,
    st: VehicleState<N>,
    z0: &mut [f32; K],
    log: &mut ScanLog,
) -> Result<(), PlanError> {
    let n = spec.points;
    let width = spec.width.clamp(1, BEAM_WIDE);
    let mut beam: [Option<Path<N, K>>; BEAM_WIDE] = [None; BEAM_WIDE];
    keep(
        &mut beam,
        Path {
            z: *z0,
            k: 0,
            phi: 0.0,
            st,
        },
        width,
    );
    for j in spec.from..spec.h {
        let (lo, hi) = (
            spec.bounds.lo.get(j).copied().unwrap_or(0.0),
            spec.bounds.hi.get(j).copied().unwrap_or(0.0),
        );
        let mut next: [Option<Path<N, K>>; BEAM_WIDE] = [None; BEAM_WIDE];
        for parent in beam.iter().flatten() {
            // Each parent's own reach: beyond it the track flies the same.
            let t = fl.track.saturating_add(j);
            let (lo, hi) = reach_from(&fl.sc, t, parent.st.depth(), (lo, hi));
            for k in 0..n {
                let z = grid(lo, hi, k, n);
                let Ok((sc, end)) = fl.fly_from(&parent.st, j, z) else {
                    continue;
                };
                if j == 0 {
                    log.push(z, &sc);
                }
                let mut path = *parent;
                if let Some(slot) = path.z.get_mut(j) {
                    *slot = z;
                }
                path.phi = parent.phi + sc.j() + spec.mu * sc.violation();
                path.st = end;
                path.k = k;
                if path.phi.is_finite() {
                    keep(&mut next, path, width);
                }
            }
        }
        if next.first().is_none_or(Option::is_none) {
            return Err(PlanError::Sim(crate::sim::SimError::Diverged));
        }
        beam = next;
    }
    if let Some(Some(best)) = beam.first() {
        *z0 = best.z;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scan of `phis` over `[0, 80]` m (9 points, 10 m apart).
    fn scanned(phis: [f32; 9]) -> Scanned {
        let mut s = Scanned {
            phis: [f32::INFINITY; MAX_SCAN as usize],
            kinked: [true; MAX_SCAN as usize],
        };
        for (k, p) in phis.into_iter().enumerate() {
            s.phis[k] = p;
            s.kinked[k] = false;
        }
        s
    }

    /// The parabola's vertex starts the optimizer, but not where a
    /// neighbour of the best scanned depth lies on a plateau (its value
    /// that of the next point out): the best scanned depth does, with the
    /// measured first step.
    #[test]
    fn a_neighbour_on_a_plateau_keeps_the_best_scanned_depth() {
        // J of the shape of unseen_2622_6's track 1: flat to the left.
        let flat = [9.0, 9.0, 9.0, 9.0, 9.0, 8.0, 30.0, 60.0, 90.0];
        assert_eq!(vertex(&scanned(flat), 5, 0.0, 80.0, 9, true), (50.0, 0.0));
        // The same, mirrored.
        let mut mirrored = flat;
        mirrored.reverse();
        assert_eq!(
            vertex(&scanned(mirrored), 3, 0.0, 80.0, 9, true),
            (30.0, 0.0)
        );
        // A slope to the left instead of a plateau: the parabola's vertex
        // (4.57 m left of the best) and its curvature.
        let sloped = [13.0, 12.0, 11.0, 10.0, 9.0, 8.0, 30.0, 60.0, 90.0];
        let (z, c) = vertex(&scanned(sloped), 5, 0.0, 80.0, 9, true);
        let second = 30.0 - 2.0 * 8.0 + 9.0;
        assert!(
            (z - (50.0 - 5.0 * (30.0 - 9.0) / second)).abs() < 1e-4,
            "{z}"
        );
        assert!((c - second / 100.0).abs() < 1e-6, "{c}");
    }
}
