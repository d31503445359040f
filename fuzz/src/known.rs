//! Library issues the fuzz targets found, each with a switch that makes
//! the harnesses tolerate it (and only it), so that while an issue is open
//! the fuzzer keeps looking for new ones instead of finding it again. Each
//! has a test in the main crate's `tests/fuzz_regressions.rs` (ignored
//! while the issue is open).
//!
//! All were fixed (7f04130, 735d48d, f6ac315): every switch is off, and
//! the targets check these cases like any other. A newly found issue gets
//! its switch here, `true` until the library is fixed.

/// Whether a check that an open issue (`open`) would fail on absurd
/// magnitudes applies to an input whose magnitudes are `physical` or not.
pub fn applies(open: bool, physical: bool) -> bool {
    physical || !open
}

/// `Vehicle::new` accepted a speed and a sample time whose product `U0 Ts`
/// underflows to 0 m; a simulation then never advanced and ran
/// `u32::MAX` steps (minutes) before `StepLimit`. (Fixed: a step under
/// 0.1 mm is `ConfigError::OutOfRange`.) While `true`, such vehicles are
/// skipped; while `false` they are flown, and must fail fast.
pub const ZERO_STEP_VEHICLE: bool = false;

/// The planner's scan grid `lo + (hi − lo) k / (n − 1)` was not clamped
/// to `[lo, hi]`: rounding could put a scanned depth just outside the
/// search box, hence outside the mission's depth limits, and the planner
/// could return it (a fallback or an infeasible plan). (Fixed: clamped.)
/// While `true`, a depth outside the limits by no more than rounding
/// (4 ulp of the limits' magnitude) is accepted.
pub const SCAN_GRID_ROUNDING: bool = false;

/// `Planner::plan` reported a start state that is not finite or not on
/// the track as `PlanError::Sim(SimError::Diverged)` (every scanned flight
/// failed, and the scan gave up with `Diverged`), where its docs promise
/// the simulation's error (`NonFiniteState`, `StateOffTrack`). (Fixed.)
/// While `true`, `Diverged` is accepted there too.
pub const START_ERROR_AS_DIVERGED: bool = false;

/// Finite but absurd magnitudes (a bottom at 10¹³ m or more, a start depth
/// of 3·10¹⁸ m, a reference depth or depth limit of ±10³⁸ m, a penalty
/// weight of 10³⁰) overflowed to ±∞ or NaN in outputs that came back with
/// `Ok`: `J` and the violation (fixed in 7f04130: `SimError::Diverged`);
/// `TrackScore::rms` / `Plan::rms` (`2 J` overflowed), `Plan::grad_norm`,
/// and the autopilot's telemetry terms handed to the observer (fixed in
/// 735d48d); the integrators of the end state, `I_d = −∞` with the plan
/// `converged` and `safe` (fixed in f6ac315: `Diverged`). While `true`,
/// finiteness is checked only on inputs of physical magnitude
/// ([`crate::line::Line::physical`]).
pub const ABSURD_OVERFLOW: bool = false;
