//! Declared uncertainty: how far the real vehicle and the real bottom may
//! be from the model and the map, and the certification bottom that
//! covers every map error of the declared set.
//!
//! A *world* is a map error `s(x)` (along track, `|s| <= e_h + r (x − X_0)`)
//! and `v(x)` (vertical, `|v| <= e_v`), a true speed `U` within
//! `U0 (1 ± ε_U)`, a flight-path offset `|α| <= α_max` and a vertical
//! current `|w| <= w_max`; the bottom under the navigated position `x` is
//! `b(x + s(x)) + v(x)`.
//!
//! **The map part is exact.** Whatever `s(·)` and `v(·)` are, the bottom
//! under `x` is no shallower than the lower envelope
//! `b_c(x) = min { b(y) : |y − x| <= e(x) } − e_v`, and the envelope is
//! reached by some world at each `x`, so flying over `b_c` certifies every
//! map error at once. [`lower_envelope`] builds `b_c` as a profile: its
//! exact values at every breakpoint (the samples, and the positions where a
//! window edge crosses a sample), joined by chords. Between two
//! breakpoints `b_c` is the minimum of fixed linear pieces, hence concave,
//! so the chord lies on or below it: conservative by at most the
//! concavity between breakpoints. Beyond the map's ends the bottom is
//! taken as the end's depth (the map must extend past the line by the
//! horizontal uncertainty for this to be a statement about real terrain).

use heapless::Vec;

use super::check::{ConfigError, non_negative};
use super::profile::{Profile, ProfileError, ProfileView};

/// Bounds on how the real vehicle and bottom differ from the model and
/// the map (all zero: nominal). Validated by [`Uncertainty::new`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Uncertainty {
    horizontal: f32,
    drift: f32,
    vertical: f32,
    speed: f32,
    flight_path_offset: f32,
    vertical_current: f32,
}

impl Uncertainty {
    /// No uncertainty: the nominal model and map.
    pub const NONE: Self = Self {
        horizontal: 0.0,
        drift: 0.0,
        vertical: 0.0,
        speed: 0.0,
        flight_path_offset: 0.0,
        vertical_current: 0.0,
    };

    /// Validates the six bounds: `horizontal` `e_h` (m, along-track offset
    /// of map and navigation at `X_0`), `drift` `r` (m per m travelled,
    /// `< 1`), `vertical` `e_v` (m), `speed` `ε_U` (fraction of `U0`,
    /// `< 1`), `flight_path_offset` `α_max` (deg, `< 90`),
    /// `vertical_current` `w_max` (m/s). Each finite and `>= 0`.
    ///
    /// # Errors
    /// [`ConfigError::NonFinite`] / [`ConfigError::Negative`] naming the
    /// key, [`ConfigError::OutOfRange`] for `nav_drift` or
    /// `speed_uncertainty` of 1 or more, or a flight-path offset of 90° or
    /// more.
    pub fn new(
        horizontal: f32,
        drift: f32,
        vertical: f32,
        speed: f32,
        flight_path_offset: f32,
        vertical_current: f32,
    ) -> Result<Self, ConfigError> {
        non_negative(horizontal, "horizontal_uncertainty")?;
        non_negative(drift, "nav_drift")?;
        non_negative(vertical, "vertical_uncertainty")?;
        non_negative(speed, "speed_uncertainty")?;
        non_negative(flight_path_offset, "flight_path_offset")?;
        non_negative(vertical_current, "vertical_current")?;
        if drift >= 1.0 {
            return Err(ConfigError::OutOfRange("nav_drift"));
        }
        if speed >= 1.0 {
            return Err(ConfigError::OutOfRange("speed_uncertainty"));
        }
        if flight_path_offset >= 90.0 {
            return Err(ConfigError::OutOfRange("flight_path_offset"));
        }
        Ok(Self {
            horizontal,
            drift,
            vertical,
            speed,
            flight_path_offset,
            vertical_current,
        })
    }

    /// `e_h`, m.
    pub fn horizontal(&self) -> f32 {
        self.horizontal
    }
    /// `r`, m per m.
    pub fn drift(&self) -> f32 {
        self.drift
    }
    /// `e_v`, m.
    pub fn vertical(&self) -> f32 {
        self.vertical
    }
    /// `ε_U`, fraction of the speed.
    pub fn speed(&self) -> f32 {
        self.speed
    }
    /// `α_max`, deg.
    pub fn flight_path_offset(&self) -> f32 {
        self.flight_path_offset
    }
    /// `w_max`, m/s.
    pub fn vertical_current(&self) -> f32 {
        self.vertical_current
    }

    /// Whether every bound is zero.
    pub fn is_none(&self) -> bool {
        *self == Self::NONE
    }

    /// Whether the map may differ from the real bottom.
    pub fn map_uncertain(&self) -> bool {
        self.horizontal > 0.0 || self.drift > 0.0 || self.vertical > 0.0
    }

    /// Whether the vehicle's motion may differ from the model's (speed,
    /// flight-path offset or vertical current declared): else the declared
    /// worlds fly one vehicle, the nominal one.
    pub fn motion_uncertain(&self) -> bool {
        self.speed > 0.0 || self.flight_path_offset > 0.0 || self.vertical_current > 0.0
    }

    /// The along-track offset bound `e(x) = e_h + r (x − X_0)` at `x` (m;
    /// `e_h` before `X_0`).
    pub fn offset_at(&self, x: f32, x0: f32) -> f32 {
        self.horizontal + self.drift * (x - x0).max(0.0)
    }
}

/// The certification bottom `b_c` of `map` under `u` for a line starting at
/// `x0` (m), with room for `S` samples (at most `3 × map samples + 1` are
/// needed; see the module docs).
///
/// # Errors
/// [`ProfileError::OverCapacity`] when `S` is too small.
pub fn lower_envelope<const S: usize>(
    map: ProfileView<'_>,
    u: &Uncertainty,
    x0: f32,
) -> Result<Profile<S>, ProfileError> {
    let xs = map.positions();
    let (first, last) = (map.start(), map.end());
    let over = |len| ProfileError::OverCapacity { len, capacity: S };
    let mut at: Vec<f32, S> = Vec::new();
    let add = |x: f32, at: &mut Vec<f32, S>| {
        if x.is_finite() && x >= first && x <= last {
            at.push(x).map_err(|_| over(at.len().saturating_add(1)))
        } else {
            Ok(())
        }
    };
    let (e_h, r) = (u.horizontal(), u.drift());
    for &xj in xs {
        add(xj, &mut at)?;
        // Where the window's right edge `x + e(x)` and left edge
        // `x − e(x)` cross the sample `x_j`, before and after `X_0`.
        for x in [
            xj - e_h,
            (xj - e_h + r * x0) / (1.0 + r),
            xj + e_h,
            (xj + e_h - r * x0) / (1.0 - r),
        ] {
            let e = u.offset_at(x, x0);
            // Keep the root of the branch it belongs to.
            if ((x + e - xj).abs() <= 1e-3 * (1.0 + xj.abs())
                || (x - e - xj).abs() <= 1e-3 * (1.0 + xj.abs()))
                && x.to_bits() != xj.to_bits()
            {
                add(x, &mut at)?;
            }
        }
    }
    add(x0, &mut at)?;
    crate::num::sort_total(&mut at);
    let mut xv: Vec<f32, S> = Vec::new();
    let mut bv: Vec<f32, S> = Vec::new();
    for &x in at.iter() {
        if xv.last().is_some_and(|&l| x <= l) {
            continue;
        }
        let e = u.offset_at(x, x0);
        let b = window_min(map, x - e, x + e)? - u.vertical();
        xv.push(x).map_err(|_| over(at.len()))?;
        bv.push(b).map_err(|_| over(at.len()))?;
    }
    Profile::new(&xv, &bv)
}

/// `min b(y)` over `[lo, hi]` clamped to the map, m: the least of its ends
/// and of the samples inside.
fn window_min(map: ProfileView<'_>, lo: f32, hi: f32) -> Result<f32, ProfileError> {
    let lo = lo.max(map.start());
    let hi = hi.min(map.end());
    let mut m = map.depth_at(lo)?.min(map.depth_at(hi)?);
    for (&x, &b) in map.positions().iter().zip(map.depths()) {
        if x > lo && x < hi {
            m = m.min(b);
        }
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map() -> Profile<8> {
        Profile::new(&[0.0, 100.0, 150.0, 300.0], &[200.0, 120.0, 180.0, 190.0]).unwrap()
    }

    /// The envelope is below every shifted-and-lowered bottom of the set,
    /// and touches the pointwise minimum at its breakpoints.
    #[test]
    fn envelope_covers_every_map_error() {
        let m = map();
        let u = Uncertainty::new(12.0, 0.05, 3.0, 0.0, 0.0, 0.0).unwrap();
        let env = lower_envelope::<32>(m.view(), &u, 0.0).unwrap();
        let mut k = 0;
        while k <= 3000 {
            let x = k as f32 * 0.1;
            let e = u.offset_at(x, 0.0);
            // The exact window minimum, by brute force.
            let mut want = f32::INFINITY;
            for j in 0..=200 {
                let y = (x - e + 2.0 * e * j as f32 / 200.0).clamp(0.0, 300.0);
                want = want.min(m.depth_at(y).unwrap());
            }
            let got = env.depth_at(x).unwrap();
            assert!(
                got <= want - 3.0 + 1e-3,
                "x {x}: {got} above {}",
                want - 3.0
            );
            k += 1;
        }
        for (&x, &b) in env.positions().iter().zip(env.depths()) {
            let e = u.offset_at(x, 0.0);
            let w = window_min(m.view(), x - e, x + e).unwrap() - 3.0;
            assert!((b - w).abs() < 1e-4, "breakpoint {x}");
        }
    }

    #[test]
    fn vertical_only_is_the_map_lowered() {
        let m = map();
        let u = Uncertainty::new(0.0, 0.0, 5.0, 0.0, 0.0, 0.0).unwrap();
        let env = lower_envelope::<16>(m.view(), &u, 0.0).unwrap();
        assert_eq!(env.positions(), m.positions());
        for (a, b) in env.depths().iter().zip(m.depths()) {
            assert_eq!(*a, b - 5.0);
        }
    }

    #[test]
    fn validates() {
        assert!(
            Uncertainty::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
                .unwrap()
                .is_none()
        );
        assert_eq!(
            Uncertainty::new(-1.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            Err(ConfigError::Negative("horizontal_uncertainty"))
        );
        assert_eq!(
            Uncertainty::new(0.0, 0.0, 0.0, 1.0, 0.0, 0.0),
            Err(ConfigError::OutOfRange("speed_uncertainty"))
        );
        assert_eq!(
            Uncertainty::new(0.0, 0.0, f32::NAN, 0.0, 0.0, 0.0),
            Err(ConfigError::NonFinite("vertical_uncertainty"))
        );
        assert_eq!(
            Uncertainty::new(0.0, 1.5, 0.0, 0.0, 0.0, 0.0),
            Err(ConfigError::OutOfRange("nav_drift"))
        );
    }
}
