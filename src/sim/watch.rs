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

    /// Piece `p` of track `slot`; `de[j] = (∂e_lo, ∂e_hi)` for the
    /// columns `j <= slot`.
    pub(super) fn piece(&mut self, slot: usize, p: &PieceLin, de: &[(f32, f32); K]) {
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
