//! Scoring (model contract §8): the clipped trapezoid for `J`, the
//! violation, and the minimum altitude, per track.

use crate::model::{Cursor, Point};
use crate::num::{Comp, Sum, min};

use super::lin::{End, EndAt, FastPiece, PieceLin, Sensitivity};
use super::{Scenario, SimError};

/// Score of one track over `[X_i, X_{i+1}]` (contract §8).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrackScore {
    x_start: f32,
    x_end: f32,
    pub(super) j: Sum,
    pub(super) violation: Sum,
    pub(super) min_altitude: f32,
}

#[cfg(feature = "defmt")]
impl defmt::Format for TrackScore {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "TrackScore {{ x: {}..{} m, J: {} m^3, min_altitude: {} m }}",
            self.x_start,
            self.x_end,
            self.j(),
            self.min_altitude
        );
    }
}

impl TrackScore {
    pub(super) fn new(x_start: f32, x_end: f32) -> Self {
        Self {
            x_start,
            x_end,
            j: Sum::default(),
            violation: Sum::default(),
            min_altitude: f32::INFINITY,
        }
    }

    /// Start of the track `X_i`, m.
    pub fn x_start(&self) -> f32 {
        self.x_start
    }
    /// End of the track `X_{i+1}`, m.
    pub fn x_end(&self) -> f32 {
        self.x_end
    }
    /// `J = ½ ∫ (d_t − d)² dx` by the clipped trapezoid rule, m³.
    pub fn j(&self) -> f32 {
        self.j.value()
    }
    /// RMS deviation from the target depth `sqrt(2 J / (X_{i+1} − X_i))`, m.
    pub fn rms(&self) -> f32 {
        // √J / √L · √2: no overflow of `2 J` where `J` is near f32's range,
        // nor of `2 / L` where `L` is subnormal (√J / √L is about |e| / √2).
        libm::sqrtf(self.j()) / libm::sqrtf(self.x_end - self.x_start) * core::f32::consts::SQRT_2
    }
    /// Constraint violation `½ ∫ max(0, h_p − h)² dx` by the same
    /// trapezoid, m³, with `h_p` the scenario's penalty altitude (`h_a`
    /// unless set otherwise); zero when the altitude never drops below
    /// `h_p` at a scored point.
    pub fn violation(&self) -> f32 {
        self.violation.value()
    }
    /// Least altitude above the bottom at the samples on the track and its
    /// clipped end points, m.
    pub fn min_altitude(&self) -> f32 {
        self.min_altitude
    }
    /// `h >= h_a` at every scored point: the track is safe for the model.
    /// (A certifying caller adds its own margin to `h_a`.)
    pub fn is_safe(&self, min_altitude: f32) -> bool {
        self.min_altitude >= min_altitude
    }
}

/// A sample's position and depth, with the bottom under it when scored.
#[derive(Clone, Copy, Debug)]
pub(super) struct Geo {
    pub x: Comp,
    pub d: Comp,
    /// Where the sample is scored (`x <= x_end`): what scoring needs of it.
    pub at: Option<At>,
    /// `x − x_end`, m: the run ends at the first sample with `past >= 0`.
    pub past: f32,
}

/// A scored sample: altitude `h`, bottom slope `b'`, `e = h − h_r` and
/// `p = max(0, h_p − h)` (m, m/m, m, m), computed once per sample.
#[derive(Clone, Copy, Debug)]
pub(super) struct At {
    pub h: f32,
    pub slope: f32,
    pub e: f32,
    pub p: f32,
}

impl At {
    /// The scoring kernel at one sample of altitude `h` (m) over a bottom
    /// of slope `slope`: `e = h − h_r` and `p = max(0, h_p − h)` (m), for
    /// the reference altitude `h_r` and the penalty altitude `h_p`.
    #[inline(always)]
    pub(super) fn new(h: f32, slope: f32, h_r: f32, h_p: f32) -> Self {
        let (e, p) = terms(h, h_r, h_p);
        Self { h, slope, e, p }
    }

    /// As [`At::new`] with `p = 0`, for a sample known to be at or above
    /// the penalty altitude (the fast path computes `p` only below it).
    #[inline(always)]
    pub(super) fn clear(h: f32, slope: f32, h_r: f32) -> Self {
        Self {
            h,
            slope,
            e: deviation(h, h_r),
            p: 0.0,
        }
    }
}

/// `e = h − h_r`, m: the deviation `J` integrates, squared.
#[inline(always)]
fn deviation(h: f32, h_r: f32) -> f32 {
    h - h_r
}

/// `p = max(0, h_p − h)`, m: the shortfall the violation integrates,
/// squared.
#[inline(always)]
pub(super) fn shortfall(h: f32, h_p: f32) -> f32 {
    let p = h_p - h;
    if p > 0.0 { p } else { 0.0 }
}

/// Both terms at altitude `h` (m).
#[inline(always)]
fn terms(h: f32, h_r: f32, h_p: f32) -> (f32, f32) {
    (deviation(h, h_r), shortfall(h, h_p))
}

/// The trapezoid over a piece of length `len` (m) between two ends whose
/// integrand is `a2` and `b2`, without the rule's ¼ (a power of two, which
/// the callers apply where it rounds the same).
#[inline(always)]
pub(super) fn trapezoid(len: f32, a2: f32, b2: f32) -> f32 {
    len * (a2 + b2)
}

/// A piece of a segment inside one track, between two scored samples at
/// `x0` and `x1` (m): the fast path's, in parts (see [`FastPiece`]).
#[inline(always)]
pub(super) fn piece_within(
    dx: f32,
    dd: f32,
    (a0, x0): (&At, f32),
    (a1, x1): (&At, f32),
) -> FastPiece {
    FastPiece {
        dx,
        dd,
        lo: End {
            at: EndAt::Start { slope: a0.slope },
            x: x0,
            e: a0.e,
            p: a0.p,
        },
        hi: End {
            at: EndAt::End { slope: a1.slope },
            x: x1,
            e: a1.e,
            p: a1.p,
        },
    }
}

impl<const N: usize> Scenario<'_, N> {
    /// A sample's geometry; the bottom is looked up only where scoring
    /// needs it (`x <= x_end`), since the last sample may lie past the
    /// profile.
    #[inline]
    pub(super) fn geo(
        &self,
        cursor: &mut Cursor,
        x: Comp,
        d: Comp,
        x_end: f32,
    ) -> Result<Geo, SimError> {
        let past = x.minus(x_end);
        let at = if past <= 0.0 {
            let p: Point = self
                .profile
                .locate(cursor, x)
                .ok_or(SimError::OutOfProfile)?;
            Some(At::new(
                p.altitude(d),
                p.slope,
                self.mission.reference_altitude(),
                self.penalty_altitude,
            ))
        } else {
            None
        };
        Ok(Geo { x, d, at, past })
    }

    /// Scores segment `s0 → s1`, flown from track `track`, into every track
    /// of `first..last` it overlaps, clipping at the waypoints (§8).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(super) fn score<Sn: Sensitivity<N>>(
        &self,
        s0: &Geo,
        s1: &Geo,
        track: usize,
        first: usize,
        last: usize,
        scores: &mut [TrackScore],
        sens: &mut Sn,
    ) -> Result<(), SimError> {
        let wp = self.waypoints.positions();
        let dx = s1.x.diff(s0.x);
        let dd = s1.d.diff(s0.d);
        let mut t = track.max(first);
        while t < last {
            let next = t.saturating_add(1);
            let (Some(&a), Some(&b)) = (wp.get(t), wp.get(next)) else {
                return Err(SimError::TrackRange);
            };
            if s1.x.minus(a) <= 0.0 {
                break;
            }
            let lo = if s0.x.minus(a) >= 0.0 {
                self.sample_end(s0, true)?
            } else {
                self.clip_end(s0, dx, dd, t)?
            };
            let ends_here = s1.x.minus(b) <= 0.0;
            let hi = if ends_here {
                self.sample_end(s1, false)?
            } else {
                self.clip_end(s0, dx, dd, next)?
            };
            let len = match (lo.0.at, hi.0.at) {
                (EndAt::Start { .. }, EndAt::End { .. }) => dx,
                (EndAt::Clip { .. }, EndAt::End { .. }) => s1.x.minus(a),
                (EndAt::Start { .. }, _) => -s0.x.minus(b),
                _ => b - a,
            };
            let slot = t.saturating_sub(first);
            let s = scores.get_mut(slot).ok_or(SimError::ScoreBuffer)?;
            let (lo, h_lo) = lo;
            let (hi, h_hi) = hi;
            // The constraint holds at the end points too, even of a piece
            // of zero length (a sample exactly on a waypoint).
            s.min_altitude = min(min(s.min_altitude, h_lo), h_hi);
            if len > 0.0 {
                s.j.add(0.25 * trapezoid(len, lo.e * lo.e, hi.e * hi.e));
                // Most pieces keep clear of the penalty altitude.
                if lo.p > 0.0 || hi.p > 0.0 {
                    s.violation
                        .add(0.25 * trapezoid(len, lo.p * lo.p, hi.p * hi.p));
                }
                sens.piece(
                    slot,
                    &PieceLin {
                        len,
                        dx,
                        dd,
                        lo,
                        hi,
                    },
                );
            }
            if ends_here {
                break;
            }
            t = next;
        }
        Ok(())
    }

    /// A piece end at one of the segment's samples, with its altitude.
    #[inline]
    fn sample_end(&self, s: &Geo, first: bool) -> Result<(End, f32), SimError> {
        let a = s.at.ok_or(SimError::OutOfProfile)?;
        let at = if first {
            EndAt::Start { slope: a.slope }
        } else {
            EndAt::End { slope: a.slope }
        };
        Ok((
            End {
                at,
                x: s.x.value(),
                e: a.e,
                p: a.p,
            },
            a.h,
        ))
    }

    /// A piece end clipped at waypoint `i`, depth interpolated in `x`.
    #[inline]
    fn clip_end(&self, s0: &Geo, dx: f32, dd: f32, i: usize) -> Result<(End, f32), SimError> {
        let c = *self
            .waypoints
            .positions()
            .get(i)
            .ok_or(SimError::TrackRange)?;
        // (Looked up anew: a clip happens once per waypoint crossed.)
        let b = self
            .profile
            .depth_at(c)
            .map_err(|_| SimError::OutOfProfile)?;
        let t = -s0.x.minus(c) / dx;
        let h = -s0.d.minus(b) - dd * t;
        Ok((self.end(EndAt::Clip { t }, c, h), h))
    }

    #[inline(always)]
    fn end(&self, at: EndAt, x: f32, h: f32) -> End {
        let (e, p) = terms(h, self.mission.reference_altitude(), self.penalty_altitude);
        End { at, x, e, p }
    }
}
