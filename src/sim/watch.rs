//! What a tangent pass can record for a constrained optimizer beyond the
//! gradient of `J`: the least altitude of each *segment* of the tracks
//! with its gradient, and the Gauss–Newton matrix of `Σ J`.
//!
//! **Segments.** The constraint `h >= h_a` holds at every sample; its
//! per-track form, the least altitude of a track, is a minimum over
//! thousands of samples whose arg-min jumps between distant dips of the
//! terrain as the depths move, and its gradient at one dip says nothing
//! of the next. So each track is cut into segments of about
//! [`SEGMENT_LENGTH`] (at most [`SEGMENTS`] over a run): each segment's
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

use nalgebra::SMatrix;

use super::lin::PieceLin;

/// Most constraint segments of one run.
pub(crate) const SEGMENTS: usize = 48;

/// Target length of a segment, m: two or three of the vehicle's depth
/// responses (its closed loop settles a step in about 150 m at 1.5 m/s),
/// so that one segment rarely holds two independent dips.
pub(crate) const SEGMENT_LENGTH: f32 = 100.0;

/// Most segments of one track.
const PER_TRACK: usize = 8;

/// Receives each scored piece with the active columns' `∂e` at its ends.
pub(crate) trait Watcher<const K: usize> {
    /// Whether anything is recorded (the plain gradient's watcher is not).
    const ACTIVE: bool;
    /// Piece `p` of track `slot`; `de[j] = (∂e_lo, ∂e_hi)` for the
    /// columns `j <= slot`.
    fn piece(&mut self, slot: usize, p: &PieceLin, de: &[(f32, f32); K]);
}

/// Records nothing.
pub(crate) struct NoWatch;

impl<const K: usize> Watcher<K> for NoWatch {
    const ACTIVE: bool = false;
    #[inline(always)]
    fn piece(&mut self, _: usize, _: &PieceLin, _: &[(f32, f32); K]) {}
}

/// Segments' least altitudes with their gradients, and optionally the
/// Gauss–Newton matrix, of one run over up to `K` tracks.
#[derive(Clone, Debug)]
pub(crate) struct Watch<const K: usize> {
    /// Per track of the run: its first segment, how many, where it starts
    /// (m) and segments per metre.
    layout: [(usize, usize, f32, f32); K],
    /// Segments used.
    pub segments: usize,
    /// Each segment's least altitude, m (`+inf` where nothing was scored).
    pub min: [f32; SEGMENTS],
    /// `∂h/∂z_j` where that least altitude was set (m/m).
    pub grad: [[f32; K]; SEGMENTS],
    /// The track (index in the run) of each segment.
    pub track: [u8; SEGMENTS],
    /// Reference altitude `h_r`, m (`h = e + h_r`).
    h_r: f32,
    /// The Gauss–Newton matrix of `Σ J` (m), when asked for.
    pub gn: Option<SMatrix<f32, K, K>>,
}

impl<const K: usize> Watch<K> {
    /// The segments of tracks `first..first + count` of `waypoints` (m),
    /// at reference altitude `h_r` (m); with the Gauss–Newton matrix if
    /// `gn`.
    pub(crate) fn new(waypoints: &[f32], first: usize, count: usize, h_r: f32, gn: bool) -> Self {
        let count = count.min(K);
        let cap = PER_TRACK
            .min(SEGMENTS.checked_div(count).unwrap_or(SEGMENTS))
            .max(1);
        let mut layout = [(0, 0, 0.0, 0.0); K];
        let mut track = [0_u8; SEGMENTS];
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
            *slot = (next, n, a, n as f32 / len);
            for s in track.iter_mut().skip(next).take(n) {
                *s = u8::try_from(i).unwrap_or(u8::MAX);
            }
            next = next.saturating_add(n);
        }
        Self {
            layout,
            segments: next.min(SEGMENTS),
            min: [f32::INFINITY; SEGMENTS],
            grad: [[0.0; K]; SEGMENTS],
            track,
            h_r,
            gn: gn.then(SMatrix::zeros),
        }
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
        let Some(s) = self.segment(slot, x) else {
            return;
        };
        let h = e + self.h_r;
        let (Some(m), Some(g)) = (self.min.get_mut(s), self.grad.get_mut(s)) else {
            return;
        };
        if h < *m {
            *m = h;
            for (j, (gj, d)) in g.iter_mut().zip(de.iter()).enumerate() {
                *gj = match (j <= slot, hi) {
                    (false, _) => 0.0,
                    (true, true) => d.1,
                    (true, false) => d.0,
                };
            }
        }
    }
}

impl<const K: usize> Watcher<K> for Watch<K> {
    const ACTIVE: bool = true;

    fn piece(&mut self, slot: usize, p: &PieceLin, de: &[(f32, f32); K]) {
        self.end(slot, (p.lo.x, p.lo.e), de, false);
        self.end(slot, (p.hi.x, p.hi.e), de, true);
        if let Some(gn) = self.gn.as_mut() {
            let half = 0.5 * p.len;
            let n = slot.saturating_add(1).min(K);
            for (a, da) in de.iter().enumerate().take(n) {
                for (b, db) in de.iter().enumerate().take(n) {
                    if let Some(v) = gn.get_mut((a, b)) {
                        *v += half * (da.0 * db.0 + da.1 * db.1);
                    }
                }
            }
        }
    }
}
