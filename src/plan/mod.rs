//! The planner: the next waypoint's reference depth, optimized by flying
//! the vehicle's closed loop over the mapped bottom, verified safe or
//! explicitly flagged (model contract §10).
//!
//! ```text
//! state at X_{n-1}, waypoints, bottom ─► search box (reachable depths)
//!   ─► start: coarse scan, track by track (or the previous call's plan)
//!   ─► BFGS or GD on  Φ(ζ) = Σ J + μ Σ V          ζ = (z_n .. z_{n+h-1})
//!   ─► verify z_n by simulation ─► safe? ─ no ─► closest safe depth (safe_fallback)
//!                                              or the safest one (infeasible)
//! ```
//!
//! **Modes.** Receding horizon (the default) optimizes the next `h <= K`
//! tracks jointly, commits the first depth, and keeps the rest to
//! warm-start the next call; track-wise (the paper's method) optimizes `z_n`
//! for track `n` alone.
//!
//! **Search box.** Over a track of length `L` the vehicle cannot change
//! depth by more than `L sin θ` (θ a little over the pitch limit: the pitch
//! overshoots its reference by a few degrees). A reference further away
//! than that, plus the depth error that saturates the pitch reference
//! (`θmax / Kpd`), keeps the pitch reference saturated over the whole track:
//! the flight, and `J`, no longer change (model contract §10's plateaus).
//! So `z_j` is searched within `d ± (Σ L sin θ + 3 θmax/Kpd + 20 m)` of the
//! current depth `d`, intersected with `depth_limits`: nothing outside
//! gives a different flight, and the optimizer is never started on the
//! plateau.
//!
//! **Starting point.** A coarse scan of `scan_points` depths over the box
//! (`track_scan_points` for a constrained single track),
//! track by track from the state the best of the previous track leaves:
//! the search starts in the best basin found, never on a plateau that is
//! not the best scanned value. In horizon mode later calls start from the
//! previous call's plan, and only the newly visible track is scanned.
//!
//! **Constraint, one track** (track-wise mode, and the last track of a
//! horizon). The scan also gives each scanned depth's minimum altitude.
//! When the scan's best depth is unsafe, or safe but with its parabola
//! pointing to an unsafe neighbour, the optimum of `J` lies beyond the safe
//! set, and the constrained optimum on its boundary next to it: a root
//! search on the minimum altitude between the nearest safe and unsafe
//! scanned depths (a unit-slope step, secants, regula falsi) finds it from
//! the safe side in one to four plain flights, and a finite difference of `J` there (the search's
//! previous safe depth, or one more flight) confirms that `J` does not
//! decrease into the safe set; if it does, BFGS optimizes from there. When
//! no scanned depth is safe the track is [`PlanStatus::Infeasible`] and the
//! safest scanned depth is returned. Otherwise BFGS (without a penalty)
//! optimizes from the scan's parabola vertex, and an unsafe optimum falls
//! back to the boundary by the same search ([`PlanStatus::SafeFallback`]).
//!
//! **Constraint, a horizon.** `h >= h_a` enters the optimization as a
//! quadratic penalty: `Φ = Σ J + μ Σ V` with `V = ½ ∫ max(0, h_a + m_p − h)² dx`
//! (the violation of [`crate::TrackScore`], taken against `h_a` plus the
//! penalty margin `m_p`), whose exact gradient comes from the same tangent
//! pass. `J` ranges from 1e2 to 1e8 m³ between a shallow bay and a canyon
//! wall, so no single `μ` fits: the sequential penalty method (N&W §17.1)
//! re-solves from the last optimum with `μ` a hundred times larger while
//! that optimum still violates, for at most `penalty_stages` stages.
//!
//! **Verification.** The committed depth is **verified by simulation**: it
//! is reported safe only when the track's minimum altitude is at least
//! `h_a + m_s` (the safety margin, covering f32 vs f64 differences in
//! altitude). If not, the planner looks for the safe depth closest to the
//! optimum (among the scanned depths, then by the boundary search) and
//! returns it flagged [`PlanStatus::SafeFallback`]; if no depth in the box
//! is safe, it returns the safest depth it found, flagged
//! [`PlanStatus::Infeasible`] with its predicted minimum altitude.
//! With `constrained = false` (the paper's bare objective) there is no
//! penalty and no fallback; safety is still verified and reported.
//!
//! | file | concern |
//! |---|---|
//! | `config.rs` | [`PlannerConfig`], [`Method`], [`Mode`], [`PlanConfigError`] |
//! | `status.rs` | [`PlanStatus`], [`PlanError`] |
//! | `answer.rs` | [`Plan`], the small answer |
//! | `planner.rs` | [`Planner`]: one call, step by step |
//! | `flights.rs` | the call's plain flights, counted |
//! | `solve.rs` | the optimizer runs: penalty stages, plateau escape |
//! | `scan.rs` | the search box and the coarse scan (the starting point) |
//! | `objective.rs` | `Φ = Σ J + μ Σ V` for the optimizer |
//! | `single.rs` | the constrained single track's decision from its scan |
//! | `fallback.rs` | the closest safe depth, the safe-set boundary |

mod answer;
mod candidate;
mod certify;
mod commit;
mod config;
mod fallback;
mod flights;
mod objective;
mod planner;
mod scan;
mod single;
mod solve;
mod status;

pub use answer::Plan;
pub use config::{MAX_SCAN, Method, Mode, PlanConfigError, PlannerConfig};
pub use planner::{MAX_TRACKS, Planner};
pub use status::{OptimizerStop, PlanError, PlanStatus};
