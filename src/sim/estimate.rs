//! The planner's start state from what a vehicle measures.
//!
//! A planner predicts the state in which the vehicle reaches a waypoint;
//! the vehicle then measures where it really is. [`VehicleState::measured`]
//! keeps the prediction for what the vehicle cannot measure and takes the
//! measurement for the rest: depth, pitch, pitch rate and position. The
//! realization of `Plant` carries pitch and pitch rate as its first two
//! states (`θ = η1`, `q = η2`), so the correction is the least-norm change
//! of `η` that agrees with the measured pitch and pitch rate; the
//! unmeasured states (`η3…`, the elevator's effect not yet in `θ` or `q`)
//! keep their predicted values.

use super::error::SimError;
use super::state::VehicleState;
use crate::num::Comp;

/// What the vehicle measures at one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Measurement {
    /// Along-track position `x`, m (from navigation).
    pub x: f32,
    /// Depth `d`, m, positive down (pressure sensor).
    pub depth: f32,
    /// Pitch `θ`, deg, nose up positive (attitude sensor).
    pub pitch: f32,
    /// Pitch rate `q`, deg/s (gyro).
    pub pitch_rate: f32,
}

impl Measurement {
    fn is_finite(&self) -> bool {
        [self.x, self.depth, self.pitch, self.pitch_rate]
            .iter()
            .all(|v| v.is_finite())
    }
}

impl<const N: usize> VehicleState<N> {
    /// The predicted state `prior` corrected by the measurement `m`:
    /// depth, position, pitch and pitch rate from `m`; the depth rate
    /// (`d − d_prev`), the step `x − x_prev`, the unmeasured plant states
    /// and the autopilot's integrators from `prior`. Use
    /// [`VehicleState::with_integrals`] when the autopilot's own
    /// integrators are at hand.
    ///
    /// # Errors
    /// [`SimError::NonFiniteState`] if `m` or `prior` is not finite.
    pub fn measured(prior: &Self, m: &Measurement) -> Result<Self, SimError> {
        if !m.is_finite() || !prior.is_finite() {
            return Err(SimError::NonFiniteState);
        }
        let mut s = *prior;
        if let Some(theta) = s.eta.get_mut(0) {
            *theta = m.pitch;
        }
        if let Some(q) = s.eta.get_mut(1) {
            *q = m.pitch_rate;
        }
        let depth_step = prior.depth() - prior.depth_prev();
        let x_step = prior.x() - prior.x_prev();
        s.depth = Comp::new(m.depth);
        s.depth_prev = Comp::new(m.depth - depth_step);
        s.x = Comp::new(m.x);
        s.x_prev = Comp::new(m.x - x_step);
        if s.is_finite() {
            Ok(s)
        } else {
            Err(SimError::NonFiniteState)
        }
    }

    /// The same state with the autopilot's integrators `I_d` (m s) and
    /// `I_θ` (deg s) as the real autopilot holds them.
    ///
    /// # Errors
    /// [`SimError::NonFiniteState`] if either is not finite.
    pub fn with_integrals(
        mut self,
        depth_integral: f32,
        pitch_integral: f32,
    ) -> Result<Self, SimError> {
        if !depth_integral.is_finite() || !pitch_integral.is_finite() {
            return Err(SimError::NonFiniteState);
        }
        self.depth_integral = depth_integral;
        self.pitch_integral = pitch_integral;
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prior() -> VehicleState<3> {
        VehicleState::new([1.0, 0.5, -0.2], 100.0, 99.9, 50.0, 49.85, 3.0, -1.0)
    }

    #[test]
    fn measured_takes_the_measurement_and_keeps_the_rest() {
        let m = Measurement {
            x: 52.0,
            depth: 101.0,
            pitch: 2.0,
            pitch_rate: -0.3,
        };
        let s = VehicleState::measured(&prior(), &m).unwrap_or(prior());
        assert_eq!(s.eta(), [2.0, -0.3, -0.2]);
        assert_eq!(s.depth(), 101.0);
        assert!((s.depth() - s.depth_prev() - 0.1).abs() < 1e-4);
        assert_eq!(s.x(), 52.0);
        assert!((s.x() - s.x_prev() - 0.15).abs() < 1e-4);
        assert_eq!((s.depth_integral(), s.pitch_integral()), (3.0, -1.0));
    }

    #[test]
    fn a_measurement_equal_to_the_prediction_changes_nothing() {
        let p = prior();
        let m = Measurement {
            x: p.x(),
            depth: p.depth(),
            pitch: 1.0,
            pitch_rate: 0.5,
        };
        assert_eq!(VehicleState::measured(&p, &m), Ok(p));
    }

    #[test]
    fn non_finite_input_is_an_error() {
        let m = Measurement {
            x: 0.0,
            depth: f32::NAN,
            pitch: 0.0,
            pitch_rate: 0.0,
        };
        assert_eq!(
            VehicleState::measured(&prior(), &m),
            Err(SimError::NonFiniteState)
        );
        assert_eq!(
            prior().with_integrals(f32::INFINITY, 0.0),
            Err(SimError::NonFiniteState)
        );
    }
}
