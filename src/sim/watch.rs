//! What a tangent pass can record for a constrained optimizer beyond the
//! gradient of `J`: the least altitude of each *segment* of the tracks
//! with its gradient, and the Gauss–Newton matrix of `Σ J`.
//!
//! **Segments.** The constraint `h >= h_a` holds at every sample; its
//! per-track form, the least altitude of a track, is a minimum over
//! thousands of samples whose arg-min jumps between distant dips of the
//! terrain as the depths move, and its gradient at one dip says nothing
//! of the next. So each track is cut into segments of about
//! [`SEGMENT_LENGTH`] (at most 8 a track, and as many as the caller's
//! storage holds over a run: 32 for the planner): each segment's
//! least altitude, with `∂h/∂z` at the sample that set it, is one
//! constraint row of the SQP step ([`crate::optim`]), so that two dips of
//! one track are two rows. A segment is a fixed interval of `x` on its
//! track; the ends of scored pieces (the samples and the waypoint clips)
//! are assigned to it by position.
//!
//! **Gauss–Newton.** `J = Σ_pieces L (e_lo² + e_hi²) / 4`, so
//! `∇²J ≈ Σ L/2 (∂e_lo ∂e_loᵀ + ∂e_hi ∂e_hiᵀ)` (the second derivatives of
//! `e` and the length's derivative dropped): the SQP's first metric, on
//! request.
//!
//! The records live in the caller's storage (borrowed), so that a watched
//! pass costs no stack of its own; [`Watch::off`] records nothing, and
//! the plain gradient is the same pass with it.

use super::lin::PieceLin;

/// Target length of a segment, m: two or three of the vehicle's depth
/// responses (its closed loop settles a step in about 150 m at 1.5 m/s),
/// so that one segment rarely holds two independent dips.
pub(crate) const SEGMENT_LENGTH: f32 = 100.0;

/// Most segments of one track.
const PER_TRACK: usize = 8;

/// The borrowed records: each segment's least altitude (m), `∂h/∂z_j`
/// where it was set (m/m), and its track (index in the run).
pub(crate) type Records<'a, const K: usize> = (&'a mut [f32], &'a mut [[f32; K]], &'a mut [u8]);

/// Segments' least altitudes with their gradients, and optionally the
/// Gauss–Newton matrix, of one run over up to `K` tracks.
pub(crate) struct Watch<'a, const K: usize> {
    /// Per track of the run: its first segment, how many, where it starts
    /// (m) and segments per metre.
    layout: [(usize, usize, f32, f32); K],
    /// Segments used.
    segments: usize,
    min: &'a mut [f32],
    grad: &'a mut [[f32; K]],
    /// Reference altitude `h_r`, m (`h = e + h_r`).
    h_r: f32,
    /// The Gauss–Newton matrix of `Σ J` (m), when asked for.
    gn: Option<&'a mut [[f32; K]; K]>,
    /// Where the last piece recorded ended, m (NaN: none yet): a piece
    /// that starts there has its lower end recorded already.
    last: f32,
}

impl<'a, const K: usize> Watch<'a, K> {
    /// Records nothing: the plain gradient.
    pub(crate) fn off() -> Self {
        Self {
            layout: [(0, 0, 0.0, 0.0); K],
            segments: 0,
            min: &mut [],
            grad: &mut [],
            h_r: 0.0,
            gn: None,
            last: f32::NAN,
        }
    }

    /// The segments of tracks `first..first + count` of `waypoints` (m),
    /// at reference altitude `h_r` (m), recorded into `records` (cleared
    /// here: `+inf`, zero gradients) and the Gauss–Newton matrix into `gn`
    /// (zeroed) if given. Returns the watch and the segments used.
    pub(crate) fn new(
        (waypoints, first, count): (&[f32], usize, usize),
        h_r: f32,
        (min, grad, track): Records<'a, K>,
        gn: Option<&'a mut [[f32; K]; K]>,
    ) -> (Self, usize) {
        let count = count.min(K);
        let room = min.len().min(grad.len()).min(track.len());
        let cap = PER_TRACK
            .min(room.checked_div(count).unwrap_or(room))
            .max(1);
        let mut layout = [(0, 0, 0.0, 0.0); K];
        let mut next = 0_usize;
        for (i, slot) in layout.iter_mut().enumerate().take(count) {
            let t = first.saturating_add(i);
            let (Some(&a), Some(&b)) = (waypoints.get(t), waypoints.get(t.saturating_add(1)))
            else {
                break;
            };
            let len = b - a;
            let want = libm::ceilf(len / SEGMENT_LENGTH);
            let n = if want.is_finite() && want >= 1.0 {
                (want as usize).min(cap)
            } else {
                1
            };
            let n = n.min(room.saturating_sub(next));
            *slot = (next, n, a, n as f32 / len);
            for s in track.iter_mut().skip(next).take(n) {
                *s = u8::try_from(i).unwrap_or(u8::MAX);
            }
            next = next.saturating_add(n);
        }
        min.iter_mut().for_each(|m| *m = f32::INFINITY);
        grad.iter_mut().for_each(|g| *g = [0.0; K]);
        let gn = gn.map(|m| {
            *m = [[0.0; K]; K];
            m
        });
        let watch = Self {
            layout,
            segments: next,
            min,
            grad,
            h_r,
            gn,
            last: f32::NAN,
        };
        (watch, next)
    }

    /// Whether anything is recorded.
    #[inline(always)]
    pub(super) fn on(&self) -> bool {
        self.segments > 0 || self.gn.is_some()
    }

    /// The segment of track `slot` holding position `x` (m).
    fn segment(&self, slot: usize, x: f32) -> Option<usize> {
        let &(first, n, a, per_m) = self.layout.get(slot)?;
        let k = (x - a) * per_m;
        let k = if k >= 0.0 {
            (k as usize).min(n.saturating_sub(1))
        } else {
            0
        };
        Some(first.saturating_add(k)).filter(|&s| s < self.segments)
    }

    /// One end at `x` with `e` and the columns' `∂e` (`hi`: the second).
    fn end(&mut self, slot: usize, (x, e): (f32, f32), de: &[(f32, f32); K], hi: bool) {
        let Some(g) = self.new_least(slot, (x, e)) else {
            return;
        };
        for (j, (gj, d)) in g.iter_mut().zip(de.iter()).enumerate() {
            *gj = match (j <= slot, hi) {
                (false, _) => 0.0,
                (true, true) => d.1,
                (true, false) => d.0,
            };
        }
    }

    /// A sample at `x` with `e` (m) on track `slot`: when it sets its
    /// segment's least altitude, the altitude is recorded and the
    /// segment's gradient row returned for the caller to write.
    #[inline(always)]
    fn new_least(&mut self, slot: usize, (x, e): (f32, f32)) -> Option<&mut [f32; K]> {
        let s = self.segment(slot, x)?;
        let h = e + self.h_r;
        let m = self.min.get_mut(s)?;
        // (Strictly lower: a NaN records nothing.)
        if h.partial_cmp(m) != Some(core::cmp::Ordering::Less) {
            return None;
        }
        *m = h;
        self.grad.get_mut(s)
    }

    /// Whether a piece starting at `lo` (m) needs only its upper end
    /// ([`Watch::upper`]): it starts where the last one recorded ended
    /// (the same sample, so the same altitude, which a strict minimum
    /// would not take twice), and no Gauss–Newton matrix is asked for.
    #[inline(always)]
    pub(super) fn lower_recorded(&self, lo: f32) -> bool {
        self.gn.is_none() && lo.to_bits() == self.last.to_bits()
    }

    /// A piece's upper end at `x` with `e` (m) on track `slot`, its lower
    /// end recorded ([`Watch::lower_recorded`]): when it sets its
    /// segment's least altitude, the altitude is recorded and the
    /// segment's gradient row returned, zeroed past `slot`, for the
    /// caller to fill with `∂e_hi` (columns `j <= slot`).
    #[inline(always)]
    pub(super) fn upper(&mut self, slot: usize, (x, e): (f32, f32)) -> Option<&mut [f32; K]> {
        self.last = x;
        let g = self.new_least(slot, (x, e))?;
        for gj in g.iter_mut().skip(slot.saturating_add(1)) {
            *gj = 0.0;
        }
        Some(g)
    }

    /// Piece `p` of track `slot`; `de[j] = (∂e_lo, ∂e_hi)` for the
    /// columns `j <= slot`.
    pub(super) fn piece(&mut self, slot: usize, p: &PieceLin, de: &[(f32, f32); K]) {
        self.last = p.hi.x;
        self.end(slot, (p.lo.x, p.lo.e), de, false);
        self.end(slot, (p.hi.x, p.hi.e), de, true);
        if let Some(gn) = self.gn.as_deref_mut() {
            let half = 0.5 * p.len;
            let n = slot.saturating_add(1).min(K);
            for (a, da) in de.iter().enumerate().take(n) {
                for (b, db) in de.iter().enumerate().take(n) {
                    if let Some(v) = gn.get_mut(a).and_then(|r| r.get_mut(b)) {
                        *v += half * (da.0 * db.0 + da.1 * db.1);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    //! The records of a watched pass: each segment's least altitude is
    //! its samples' least (flown without tangents, sample by sample), and
    //! the pass that takes each piece's upper end alone (no Gauss–Newton
    //! matrix) records exactly what the pass through both ends records.
    use super::*;
    use crate::model::{Mission, Profile, Vehicle, Waypoints};
    use crate::sim::{Scenario, TrackScore};

    const K: usize = 3;
    const ROWS: usize = 24;

    type Rec = ([f32; ROWS], [[f32; K]; ROWS], [u8; ROWS]);

    fn watched(sc: &Scenario<'_, 3>, z: &[f32; K], gn: bool) -> (Rec, usize) {
        let (mut min, mut grad, mut track) = ([0.0; ROWS], [[0.0; K]; ROWS], [0; ROWS]);
        let mut m = [[0.0; K]; K];
        let wp = sc.waypoints().positions();
        let h_r = sc.mission().reference_altitude();
        let records = (&mut min[..], &mut grad[..], &mut track[..]);
        let (mut w, rows) = Watch::new((wp, 0, K), h_r, records, gn.then_some(&mut m));
        let start = sc.start_state(z[0]);
        sc.evaluate_watched(&start, 0, z, K, &mut w).unwrap();
        ((min, grad, track), rows)
    }

    #[test]
    fn records_are_the_segments_least_samples_either_way() {
        let v = Vehicle::c_auv4().unwrap();
        let x = [0.0, 150.0, 420.0, 700.0, 980.0, 1300.0, 1500.0];
        let b = [300.0, 260.0, 340.0, 180.0, 240.0, 150.0, 200.0];
        let p = Profile::<8>::new(&x, &b).unwrap();
        let w = Waypoints::<4>::new(&[0.0, 450.0, 1000.0, 1450.0]).unwrap();
        let sc =
            Scenario::new(&v, &p, &w, Mission::new(40.0, 20.0, [0.0, 1000.0]).unwrap()).unwrap();
        for z in [
            [230.0, 170.0, 120.0],
            [250.0, 120.0, 95.0],
            [200.0, 200.0, 60.0],
        ] {
            let ((min, grad, track), rows) = watched(&sc, &z, false);
            let ((min_gn, grad_gn, _), rows_gn) = watched(&sc, &z, true);
            assert!(rows >= 2 * K && rows == rows_gn);
            for s in 0..rows {
                assert_eq!(min[s].to_bits(), min_gn[s].to_bits(), "segment {s}");
                assert_eq!(grad[s], grad_gn[s], "segment {s}");
                let t = usize::from(track[s]);
                assert!(grad[s].iter().skip(t + 1).all(|&g| g == 0.0));
            }
            // Each segment's least sample, flown plainly.
            let mut least = [f32::INFINITY; ROWS];
            let (wp, mut scores) = (w.positions(), [TrackScore::default(); K]);
            let start = sc.start_state(z[0]);
            let mut seen = |s: &crate::sim::Sample| {
                let Some((t, _)) = s.reference else { return };
                let (a, end) = (wp[t], wp[t + 1]);
                let first = (0..rows).find(|&r| usize::from(track[r]) == t).unwrap();
                let n = (0..rows).filter(|&r| usize::from(track[r]) == t).count();
                let k = (((s.x - a) * n as f32 / (end - a)).max(0.0) as usize).min(n - 1);
                let h = p.depth_at(s.x).unwrap() - s.depth;
                least[first + k] = least[first + k].min(h);
            };
            sc.simulate(&start, 0, &z, &mut scores, &mut seen).unwrap();
            for s in 0..rows {
                // (A segment's least may sit at a waypoint, between samples:
                // within a step's climb of the samples' least.)
                assert!(
                    (min[s] - least[s]).abs() < 0.05,
                    "segment {s}: {} vs {}",
                    min[s],
                    least[s]
                );
            }
        }
    }
}
