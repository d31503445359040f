//! What the simulation carries from sample to sample ([`VehicleState`])
//! and what it hands to an observer at each sample ([`Sample`]).

use nalgebra::SVector;

use crate::model::Command;
use crate::num::Comp;

/// The vehicle's state at one sample: `(η, d, d_prev, x, I_d, I_θ)` of the
/// contract, plus the previous sample's position `x_prev`, which scoring
/// needs for the piece of a track flown before its first sample.
///
/// Depth and position are kept compensated (see `num::Comp`), so chaining
/// states track after track loses nothing to f32 rounding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VehicleState<const N: usize> {
    pub(crate) eta: SVector<f32, N>,
    pub(crate) depth: Comp,
    pub(crate) depth_prev: Comp,
    pub(crate) x: Comp,
    pub(crate) x_prev: Comp,
    pub(crate) depth_integral: f32,
    pub(crate) pitch_integral: f32,
}

#[cfg(feature = "defmt")]
impl<const N: usize> defmt::Format for VehicleState<N> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "VehicleState {{ x: {} m, depth: {} m, eta: {}, I_d: {}, I_theta: {} }}",
            self.x.value(),
            self.depth.value(),
            self.eta.as_slice(),
            self.depth_integral,
            self.pitch_integral
        );
    }
}

impl<const N: usize> VehicleState<N> {
    /// Trimmed level flight at `depth` (m) and position `x` (m): `η = 0`,
    /// integrators zero, `d_prev = d` (contract §7).
    pub fn trimmed(depth: f32, x: f32) -> Self {
        Self {
            eta: SVector::zeros(),
            depth: Comp::new(depth),
            depth_prev: Comp::new(depth),
            x: Comp::new(x),
            x_prev: Comp::new(x),
            depth_integral: 0.0,
            pitch_integral: 0.0,
        }
    }

    /// A state from measurements: plant state `η`, depth and previous
    /// depth (m), position and previous position (m), integrators `I_d`
    /// (m s) and `I_θ` (deg s).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        eta: [f32; N],
        depth: f32,
        depth_prev: f32,
        x: f32,
        x_prev: f32,
        depth_integral: f32,
        pitch_integral: f32,
    ) -> Self {
        Self {
            eta: SVector::from(eta),
            depth: Comp::new(depth),
            depth_prev: Comp::new(depth_prev),
            x: Comp::new(x),
            x_prev: Comp::new(x_prev),
            depth_integral,
            pitch_integral,
        }
    }

    /// Plant state `η` (see [`crate::Plant::pitch`]).
    pub fn eta(&self) -> [f32; N] {
        self.eta.into()
    }
    /// Depth `d`, m, positive down.
    pub fn depth(&self) -> f32 {
        self.depth.value()
    }
    /// Depth at the previous sample, m.
    pub fn depth_prev(&self) -> f32 {
        self.depth_prev.value()
    }
    /// Along-track position `x`, m.
    pub fn x(&self) -> f32 {
        self.x.value()
    }
    /// Along-track position at the previous sample, m.
    pub fn x_prev(&self) -> f32 {
        self.x_prev.value()
    }
    /// Depth-loop integral `I_d`, m s.
    pub fn depth_integral(&self) -> f32 {
        self.depth_integral
    }
    /// Pitch-loop integral `I_θ`, deg s.
    pub fn pitch_integral(&self) -> f32 {
        self.pitch_integral
    }

    pub(super) fn is_finite(&self) -> bool {
        self.eta.iter().all(|v| v.is_finite())
            && [
                self.depth(),
                self.depth_prev(),
                self.x(),
                self.x_prev(),
                self.depth_integral,
                self.pitch_integral,
            ]
            .iter()
            .all(|v| v.is_finite())
    }
}

/// One simulated sample, as handed to an observer.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Along-track position, m.
    pub x: f32,
    /// Depth, m, positive down.
    pub depth: f32,
    /// Pitch `θ = C η`, deg, positive nose-up.
    pub pitch: f32,
    /// Pitch rate `q = C A η`, deg/s.
    pub pitch_rate: f32,
    /// Active track (0-based) and reference depth `r_k` (m); `None` at the
    /// final sample, past the last waypoint, where no command is computed.
    pub reference: Option<(usize, f32)>,
    /// The autopilot's command at this sample; `None` at the final sample.
    pub command: Option<Command>,
}
