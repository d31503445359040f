//! What one step and one scored piece linearize to: the interface between
//! the simulation loop and a tangent pass ([`super::tangent`]).

use crate::model::{Command, Vehicle};

/// How the per-step cascade and kinematics linearize, for a tangent pass.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepLin {
    /// Index of the active track among the simulated ones.
    pub slot: usize,
    pub command: Command,
    /// `sin`, `cos` of the flight path `θ̄ − α`.
    pub sin: f32,
    pub cos: f32,
    /// `U Ts`, m.
    pub step: f32,
}

/// Where one end of a scored piece lies.
#[derive(Clone, Copy, Debug)]
pub(crate) enum EndAt {
    /// At the segment's first sample (`b'` there).
    Start { slope: f32 },
    /// At the segment's second sample.
    End { slope: f32 },
    /// At a fixed waypoint, fraction `t` of the way along the segment.
    Clip { t: f32 },
}

/// One end of a scored piece: where (and its along-track position `x`),
/// and its `e = d_t − d` and `p = max(0, h_a − h)` (m).
#[derive(Clone, Copy, Debug)]
pub(crate) struct End {
    pub at: EndAt,
    pub x: f32,
    pub e: f32,
    pub p: f32,
}

/// A scored piece of a segment: its length (m), the segment's `Δx`, `Δd`
/// (m) and its two ends.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PieceLin {
    pub len: f32,
    pub dx: f32,
    pub dd: f32,
    pub lo: End,
    pub hi: End,
}

/// A piece of the fast path in parts: `Δx`, `Δd` (m) and its two ends,
/// samples on one bottom segment inside the track (`lo` at its start,
/// `hi` at its end), so that a pass reads the parts it needs and builds
/// the piece whole only where it needs it.
#[derive(Clone, Copy)]
pub(crate) struct FastPiece {
    pub dx: f32,
    pub dd: f32,
    pub lo: End,
    pub hi: End,
}

impl FastPiece {
    /// The piece whole (its length is its `Δx`).
    #[inline(always)]
    pub fn whole(&self) -> PieceLin {
        PieceLin {
            len: self.dx,
            dx: self.dx,
            dd: self.dd,
            lo: self.lo,
            hi: self.hi,
        }
    }
}

/// Receives the linearization of a run as it happens.
pub(crate) trait Sensitivity<const N: usize> {
    /// Whether the fast path's loop takes two steps a pass (see
    /// `Scenario::fast_run`): for a loop small enough that the register
    /// copies it saves outweigh the flash of a second copy.
    const TWO_STEPS: bool = false;
    /// After step `k` has moved the state to sample `k + 1`.
    fn step(&mut self, vehicle: &Vehicle<N>, lin: &StepLin);
    /// After a piece of the newest segment was scored into track `slot`.
    fn piece(&mut self, slot: usize, lin: &PieceLin);
    /// Step `k` and then the piece it flew, scored wholly into its own
    /// track `slot` (the fast path): as [`Sensitivity::step`] then
    /// [`Sensitivity::piece`] (of the piece whole), which a tangent pass
    /// may do in one pass over its columns.
    #[inline(always)]
    fn step_piece(&mut self, vehicle: &Vehicle<N>, lin: &StepLin, slot: usize, piece: FastPiece) {
        self.step(vehicle, lin);
        self.piece(slot, &piece.whole());
    }
}

/// The plain simulation's hook: does nothing, and compiles to nothing.
pub(crate) struct NoSensitivity;

impl<const N: usize> Sensitivity<N> for NoSensitivity {
    const TWO_STEPS: bool = true;
    #[inline(always)]
    fn step(&mut self, _: &Vehicle<N>, _: &StepLin) {}
    #[inline(always)]
    fn piece(&mut self, _: usize, _: &PieceLin) {}
    #[inline(always)]
    fn step_piece(&mut self, _: &Vehicle<N>, _: &StepLin, _: usize, _: FastPiece) {}
}
