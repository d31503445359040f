//! Flying in a world that is not the model (model contract §12): the true
//! speed `U`, a flight-path offset `α` between pitch and flight path, and a
//! vertical current `w`, constant over a flight. The kinematics become
//!
//! ```text
//! d_{k+1} = d_k − U Ts sin(θ̄ − α) + w Ts,   x_{k+1} = x_k + U Ts cos(θ̄ − α)
//! ```
//!
//! with the autopilot, the plant and the waypoint switching (on the
//! navigated `x`) unchanged. The nominal world (`U = U0`, `α = w = 0`) is
//! the contract's §6 exactly, bit for bit.

use heapless::Vec;

use crate::model::{Uncertainty, Vehicle};
use crate::num::DEG;

/// Most worlds [`World::corners`] returns: 3 speeds × 5 offsets × 5
/// currents (3 × 9 where only one of offset and current is declared).
pub const MAX_WORLDS: usize = 75;

/// Where in its interval a sampled bound lies (−1 and 1 the corners).
const LEVELS: [f32; 5] = [1.0, -1.0, 0.5, -0.5, 0.0];

/// The same, twice as fine, for `α` or `w` declared without the other.
const FINE: [f32; 9] = [1.0, -1.0, 0.5, -0.5, 0.0, 0.75, -0.75, 0.25, -0.25];

/// The one level of a bound not declared.
const NONE: [f32; 1] = [0.0];

/// One world's vehicle: true speed (m/s), flight-path offset `α` (deg,
/// positive: the flight path points below the pitch) and vertical current
/// `w` (m/s, positive down).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct World {
    /// True speed `U`, m/s.
    pub speed: f32,
    /// `α`, deg.
    pub flight_path_offset: f32,
    /// `w`, m/s, positive down.
    pub vertical_current: f32,
}

impl World {
    /// The model's own world: `U = U0`, no offset, no current.
    pub fn nominal<const N: usize>(vehicle: &Vehicle<N>) -> Self {
        Self {
            speed: vehicle.speed(),
            flight_path_offset: 0.0,
            vertical_current: 0.0,
        }
    }

    /// The worlds a certificate flies for `u`: the grid of
    /// `U ∈ U0 {1, 1 − ε_U, 1 + ε_U}`, `α ∈ α_max {±1, ±½, 0}` and
    /// `w ∈ w_max {±1, ±½, 0}`, without repeats where a bound is zero (one
    /// world, the nominal one, when nothing is declared); where only one of
    /// `α` and `w` is declared, that one also at `±¾` and `±¼` (27 worlds at
    /// most, in the places the other leaves). With `w_max` alone declared,
    /// `check_certified.py --seed 2553 --bounds-kind motion` found a world
    /// at `w` = 0.0555 m/s, between the levels 0.0371 and 0.0742, 0.15 m
    /// below the reported certified altitude (the sampled worlds' less the
    /// vehicle margin), and `--seed 2547` one near 0.02 m/s 1.8 m below;
    /// the finer levels catch both; a kink between two levels, the
    /// certificate bounds from its neighbours (`plan/certify/valley.rs`:
    /// the worlds of one speed and one level of `α` make a line along
    /// `w`, and with `α` declared alone those of one speed a line along
    /// `α`). Where the flight
    /// responds linearly to `α` and `w` (inside the autopilot's limits) the
    /// corners alone bound it; the interior levels catch the saturated
    /// stretches where it does not (a smaller current can then leave the
    /// vehicle lower, measured up to 0.6 m on random lines). This is the
    /// certificate's sampled part (the map part is exact, see
    /// [`crate::model::lower_envelope`]); `tests/certified.rs` samples the
    /// interior at random.
    pub fn corners<const N: usize>(
        vehicle: &Vehicle<N>,
        u: &Uncertainty,
    ) -> Vec<World, MAX_WORLDS> {
        let u0 = vehicle.speed();
        let mut out = Vec::new();
        let speeds = [u0, u0 * (1.0 - u.speed()), u0 * (1.0 + u.speed())];
        let n_speed = if u.speed() > 0.0 { 3 } else { 1 };
        let (offset, current) = (u.flight_path_offset() > 0.0, u.vertical_current() > 0.0);
        let levels = |this: bool, other: bool| -> &[f32] {
            match (this, other) {
                (false, _) => &NONE,
                (true, true) => &LEVELS,
                (true, false) => &FINE,
            }
        };
        for &speed in speeds.iter().take(n_speed) {
            for &a in levels(offset, current) {
                for &c in levels(current, offset) {
                    let _ = out.push(World {
                        speed,
                        flight_path_offset: a * u.flight_path_offset(),
                        vertical_current: c * u.vertical_current(),
                    });
                }
            }
        }
        out
    }

    /// The per-sample kinematics at sample time `ts` (s).
    pub(crate) fn kinematics(&self, ts: f32) -> Kinematics {
        Kinematics {
            step: self.speed * ts,
            offset: self.flight_path_offset * DEG,
            sink: self.vertical_current * ts,
        }
    }
}

/// What one step's kinematics need: `U Ts` (m), `α` (rad), `w Ts` (m).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Kinematics {
    pub step: f32,
    pub offset: f32,
    pub sink: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_without_repeats() {
        let v = Vehicle::c_auv4().unwrap();
        assert_eq!(World::corners(&v, &Uncertainty::NONE).len(), 1);
        assert_eq!(
            World::corners(&v, &Uncertainty::NONE)[0],
            World::nominal(&v)
        );
        let u = Uncertainty::new(0.0, 0.0, 0.0, 0.1, 0.0, 0.1).unwrap();
        assert_eq!(World::corners(&v, &u).len(), 27);
        let u = Uncertainty::new(0.0, 0.0, 0.0, 0.0, 1.0, 0.0).unwrap();
        assert_eq!(World::corners(&v, &u).len(), 9);
        let u = Uncertainty::new(0.0, 0.0, 0.0, 0.1, 1.0, 0.1).unwrap();
        assert_eq!(World::corners(&v, &u).len(), MAX_WORLDS);
    }
}
