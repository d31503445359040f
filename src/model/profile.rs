//! The bottom under the track: a bounded array of along-track samples.
//!
//! `b(x)` is the linear interpolation of samples `(x_i, b_i)` with `x`
//! strictly increasing (model contract §2). Depth is positive down, both in
//! metres. Evaluating `b` outside `[x_0, x_{S-1}]` is an error, never an
//! extrapolation: a planner must not invent terrain it was not given.

use core::fmt;

use heapless::Vec;

use crate::num::Comp;

/// Why a bottom profile was rejected or a query failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ProfileError {
    /// Fewer than two samples: nothing to interpolate.
    TooFewSamples {
        /// Number of samples given.
        len: usize,
    },
    /// More samples than the profile's capacity `S`.
    OverCapacity {
        /// Number of samples given.
        len: usize,
        /// The capacity `S`.
        capacity: usize,
    },
    /// The position and depth arrays differ in length.
    LengthMismatch {
        /// Number of positions.
        x_len: usize,
        /// Number of depths.
        depth_len: usize,
    },
    /// A position or depth is NaN or infinite.
    NonFinite {
        /// Index of the offending sample.
        index: usize,
    },
    /// `x[index] <= x[index - 1]`: positions must strictly increase.
    NotIncreasing {
        /// Index of the offending sample.
        index: usize,
    },
    /// A query outside `[x_0, x_{S-1}]`.
    OutOfRange,
}

impl fmt::Display for ProfileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::TooFewSamples { len } => {
                write!(f, "bottom profile needs at least 2 samples, got {len}")
            }
            Self::OverCapacity { len, capacity } => write!(
                f,
                "bottom profile has {len} samples, more than the capacity {capacity}"
            ),
            Self::LengthMismatch { x_len, depth_len } => write!(
                f,
                "bottom profile has {x_len} positions but {depth_len} depths"
            ),
            Self::NonFinite { index } => {
                write!(f, "bottom profile sample {index} is not finite")
            }
            Self::NotIncreasing { index } => write!(
                f,
                "bottom profile x is not strictly increasing at sample {index}"
            ),
            Self::OutOfRange => f.write_str("position outside the bottom profile"),
        }
    }
}

impl core::error::Error for ProfileError {}

/// The rules of model contract §2: equal lengths, at least two samples,
/// all finite, `x` strictly increasing.
fn validate(x: &[f32], depth: &[f32]) -> Result<(), ProfileError> {
    if x.len() != depth.len() {
        return Err(ProfileError::LengthMismatch {
            x_len: x.len(),
            depth_len: depth.len(),
        });
    }
    if x.len() < 2 {
        return Err(ProfileError::TooFewSamples { len: x.len() });
    }
    let mut last = f32::NEG_INFINITY;
    for (index, (&xi, &bi)) in x.iter().zip(depth).enumerate() {
        if !xi.is_finite() || !bi.is_finite() {
            return Err(ProfileError::NonFinite { index });
        }
        if xi <= last {
            return Err(ProfileError::NotIncreasing { index });
        }
        last = xi;
    }
    Ok(())
}

/// Along-track bottom profile with room for `S` samples.
///
/// Positions `x` in metres from the first waypoint (strictly increasing),
/// bottom depths in metres, positive down.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Profile<const S: usize> {
    x: Vec<f32, S>,
    depth: Vec<f32, S>,
}

impl<const S: usize> Profile<S> {
    /// Builds a profile from positions `x` (m) and bottom depths (m,
    /// positive down), validating every sample.
    ///
    /// # Errors
    /// [`ProfileError`] when there are fewer than two samples, more than `S`,
    /// the arrays differ in length, a value is not finite, or `x` does not
    /// strictly increase.
    pub fn new(x: &[f32], depth: &[f32]) -> Result<Self, ProfileError> {
        const { assert!(S >= 2, "a profile needs capacity for at least 2 samples") };
        let over = ProfileError::OverCapacity {
            len: x.len(),
            capacity: S,
        };
        if x.len() == depth.len() && x.len() > S {
            return Err(over);
        }
        validate(x, depth)?;
        Ok(Self {
            x: Vec::from_slice(x).map_err(|_| over)?,
            depth: Vec::from_slice(depth).map_err(|_| over)?,
        })
    }

    /// The capacity-erased view a [`crate::sim::Scenario`] holds.
    pub fn view(&self) -> ProfileView<'_> {
        ProfileView {
            x: &self.x,
            depth: &self.depth,
        }
    }

    /// Number of samples (at least 2).
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Always `false`: a valid profile has at least two samples.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Sample positions, m.
    pub fn positions(&self) -> &[f32] {
        &self.x
    }

    /// Sample bottom depths, m, positive down.
    pub fn depths(&self) -> &[f32] {
        &self.depth
    }

    /// First sample position, m.
    pub fn start(&self) -> f32 {
        self.view().start()
    }

    /// Last sample position, m.
    pub fn end(&self) -> f32 {
        self.view().end()
    }

    /// Bottom depth `b(x)` at position `x` (m), linearly interpolated, m.
    ///
    /// # Errors
    /// [`ProfileError::OutOfRange`] when `x` is outside the samples or NaN.
    pub fn depth_at(&self, x: f32) -> Result<f32, ProfileError> {
        self.view().depth_at(x)
    }
}

/// A borrowed, capacity-erased view of a validated profile: what a
/// [`crate::sim::Scenario`] holds, whatever the capacity `S` of the
/// [`Profile`] it came from (as heapless' `VecView`).
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ProfileView<'a> {
    x: &'a [f32],
    depth: &'a [f32],
}

impl<'a> ProfileView<'a> {
    /// Validates borrowed samples (e.g. `static` arrays in firmware) with
    /// the rules of [`Profile::new`], without copying them.
    ///
    /// # Errors
    /// [`ProfileError`] as [`Profile::new`], except `OverCapacity`.
    pub fn new(x: &'a [f32], depth: &'a [f32]) -> Result<Self, ProfileError> {
        validate(x, depth)?;
        Ok(Self { x, depth })
    }

    /// Number of samples (at least 2).
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Always `false`: a valid profile has at least two samples.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Sample positions, m.
    pub fn positions(&self) -> &'a [f32] {
        self.x
    }

    /// Sample bottom depths, m, positive down.
    pub fn depths(&self) -> &'a [f32] {
        self.depth
    }

    /// First sample position, m.
    pub fn start(&self) -> f32 {
        self.x.first().copied().unwrap_or(0.0)
    }

    /// Last sample position, m.
    pub fn end(&self) -> f32 {
        self.x.last().copied().unwrap_or(0.0)
    }

    /// Bottom depth `b(x)` at position `x` (m), linearly interpolated, m.
    ///
    /// # Errors
    /// [`ProfileError::OutOfRange`] when `x` is outside the samples or NaN.
    pub fn depth_at(&self, x: f32) -> Result<f32, ProfileError> {
        let mut cursor = Cursor::default();
        self.locate(&mut cursor, Comp::new(x))
            .map(|p| p.depth)
            .ok_or(ProfileError::OutOfRange)
    }

    /// Moves `cursor` to the segment that holds `x` and interpolates there.
    ///
    /// The cursor makes the lookups of a simulation, whose `x` moves by a
    /// fraction of a sample spacing per step, O(1) instead of a search.
    /// Returns `None` outside the profile.
    #[inline]
    pub(crate) fn locate(&self, cursor: &mut Cursor, x: Comp) -> Option<Point> {
        let xv = x.value();
        // Fast path: still in the cached segment (plain f32 compares; the
        // choice of segment only matters away from the shared end points,
        // where both neighbours interpolate to the same depth).
        if !(cursor.valid && xv >= cursor.x0 && xv < cursor.x1) {
            // Outside the profile (or NaN): fail, never extrapolate. The
            // range test is on the compensated position, exact at the ends.
            let (&first, &last) = (self.x.first()?, self.x.last()?);
            if !(x.minus(first) >= 0.0 && x.minus(last) <= 0.0) {
                return None;
            }
            let next = cursor.seg.saturating_add(1);
            cursor.seg = if cursor.valid
                && xv >= cursor.x1
                && self
                    .x
                    .get(next.saturating_add(1))
                    .is_some_and(|&x2| xv < x2)
            {
                next
            } else {
                self.search(xv)?
            };
            self.load(cursor)?;
        }
        let offset = x.minus(cursor.x0);
        Some(Point {
            depth: cursor.b0 + cursor.slope * offset,
            base: cursor.b0,
            offset,
            slope: cursor.slope,
        })
    }

    /// Index of the segment `[x_i, x_{i+1}]` holding `x` (binary search).
    fn search(&self, x: f32) -> Option<usize> {
        let last = self.x.len().checked_sub(2)?;
        let i = self.x.partition_point(|&xi| xi <= x);
        Some(i.saturating_sub(1).min(last))
    }

    fn load(&self, cursor: &mut Cursor) -> Option<()> {
        let i = cursor.seg;
        let x0 = *self.x.get(i)?;
        let x1 = *self.x.get(i.checked_add(1)?)?;
        let b0 = *self.depth.get(i)?;
        let b1 = *self.depth.get(i.checked_add(1)?)?;
        cursor.x0 = x0;
        cursor.x1 = x1;
        cursor.b0 = b0;
        cursor.slope = (b1 - b0) / (x1 - x0);
        cursor.valid = true;
        Some(())
    }
}

impl Cursor {
    /// End `x_{i+1}` of the cached segment, m; `-inf` before the first
    /// lookup.
    #[inline(always)]
    pub(crate) fn end(&self) -> f32 {
        if self.valid {
            self.x1
        } else {
            f32::NEG_INFINITY
        }
    }

    /// The bottom at `x`, interpolated on the cached segment: for an `x`
    /// the caller knows lies on it (see [`Profile::locate`]).
    #[inline(always)]
    pub(crate) fn point(&self, x: Comp) -> Point {
        let offset = x.minus(self.x0);
        Point {
            depth: self.b0 + self.slope * offset,
            base: self.b0,
            offset,
            slope: self.slope,
        }
    }
}

/// Cached segment of an incremental profile lookup.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Cursor {
    seg: usize,
    valid: bool,
    x0: f32,
    x1: f32,
    b0: f32,
    slope: f32,
}

/// The bottom at one position: `depth = base + slope * offset`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Point {
    /// `b(x)`, m.
    pub depth: f32,
    /// `b` at the start of the segment, m.
    pub base: f32,
    /// `x - x_i`, m (computed from the compensated position).
    pub offset: f32,
    /// `db/dx` on the segment, m/m.
    pub slope: f32,
}

impl Point {
    /// Altitude `b(x) - d` above the bottom for a compensated depth, m.
    ///
    /// `base - d.hi` is exact when the two are within a factor of two, so
    /// the altitude keeps its absolute accuracy even 5 km down.
    #[inline(always)]
    pub(crate) fn altitude(&self, d: Comp) -> f32 {
        -d.minus(self.base) + self.slope * self.offset
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Profile<8> {
        Profile::new(&[0.0, 10.0, 20.0, 40.0], &[100.0, 90.0, 90.0, 130.0]).unwrap()
    }

    #[test]
    fn validates() {
        assert_eq!(
            Profile::<4>::new(&[0.0], &[1.0]).unwrap_err(),
            ProfileError::TooFewSamples { len: 1 }
        );
        assert_eq!(
            Profile::<2>::new(&[0.0, 1.0, 2.0], &[1.0; 3]).unwrap_err(),
            ProfileError::OverCapacity {
                len: 3,
                capacity: 2
            }
        );
        assert_eq!(
            Profile::<4>::new(&[0.0, 1.0], &[1.0]).unwrap_err(),
            ProfileError::LengthMismatch {
                x_len: 2,
                depth_len: 1
            }
        );
        assert_eq!(
            Profile::<4>::new(&[0.0, f32::NAN], &[1.0, 2.0]).unwrap_err(),
            ProfileError::NonFinite { index: 1 }
        );
        assert_eq!(
            Profile::<4>::new(&[0.0, 1.0], &[1.0, f32::INFINITY]).unwrap_err(),
            ProfileError::NonFinite { index: 1 }
        );
        assert_eq!(
            Profile::<4>::new(&[0.0, 1.0, 1.0], &[1.0; 3]).unwrap_err(),
            ProfileError::NotIncreasing { index: 2 }
        );
        assert_eq!(
            Profile::<4>::new(&[0.0, 2.0, 1.0], &[1.0; 3]).unwrap_err(),
            ProfileError::NotIncreasing { index: 2 }
        );
    }

    #[test]
    fn interpolates_linearly() {
        let p = ramp();
        assert_eq!(p.depth_at(0.0).unwrap(), 100.0);
        assert_eq!(p.depth_at(5.0).unwrap(), 95.0);
        assert_eq!(p.depth_at(15.0).unwrap(), 90.0);
        assert_eq!(p.depth_at(30.0).unwrap(), 110.0);
        assert_eq!(p.depth_at(40.0).unwrap(), 130.0);
    }

    #[test]
    fn refuses_to_extrapolate() {
        let p = ramp();
        assert_eq!(p.depth_at(-0.01), Err(ProfileError::OutOfRange));
        assert_eq!(p.depth_at(40.01), Err(ProfileError::OutOfRange));
        assert_eq!(p.depth_at(f32::NAN), Err(ProfileError::OutOfRange));
    }

    #[test]
    fn cursor_moves_both_ways() {
        let p = ramp();
        let mut c = Cursor::default();
        for &(x, want) in &[(1.0, 99.0), (35.0, 120.0), (12.0, 90.0), (2.0, 98.0)] {
            let got = p.view().locate(&mut c, Comp::new(x)).unwrap().depth;
            assert!((got - want).abs() < 1e-5, "{x}: {got} vs {want}");
        }
    }
}
