//! The planner: the next waypoint's reference depth, optimized by flying
//! the vehicle's closed loop over the mapped bottom, verified safe or
//! explicitly flagged (model contract §10).
//!
//! ```text
//! state at X_{n-1}, waypoints, bottom ─► search box (reachable depths)
//!   ─► start: coarse scan, a beam over the tracks (or the previous call's plan)
//!   ─► BFGS: SQP on Σ J, every segment's least altitude ≥ the target
//!      (GD: Φ(ζ) = Σ J + μ Σ V)                  ζ = (z_n .. z_{n+h-1})
//!   ─► verify z_n by simulation ─► safe? ─ no ─► closest safe depth, or the safest
//!   ─► certify z_n with a continuation to the line's end in every declared world
//!        (the horizon, then the climb; else a search from the last certified one)
//!   ─► commit: optimal | constrained | infeasible, and the optimizer's stop
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
//! not the best scanned value. A horizon of two tracks or more under BFGS
//! is scanned as a beam: each track's grid, over the depths reachable from
//! its parent's end state, from the end states of the two best paths so
//! far (by summed `J + μ V`, one path per grid point), so that a depth
//! which leaves a later track no safe depth loses. In horizon mode later calls start from the
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
//! no scanned depth is safe the track's candidate is the safest scanned
//! depth. Otherwise BFGS (without a penalty) optimizes from the scan's
//! parabola vertex (from the best scanned depth where a neighbour of it
//! lies on a plateau: a parabola through a plateau's point models
//! nothing), and an unsafe optimum falls back to the boundary by the same
//! search.
//!
//! **Constraint, a horizon, under BFGS: SQP.** Each track is cut into
//! segments of about 100 m (`sim/watch.rs`); each segment's least altitude,
//! with its exact gradient from the same tangent pass, is one linearized
//! constraint `h_seg + ∇h_seg·Δz >= target` of a quadratic program whose
//! metric is BFGS's (first the Gauss–Newton matrix of `Σ J`, then Powell's
//! damped update on the Lagrangian), and the step is accepted by Armijo
//! backtracking on the ℓ1 merit `Σ J + ρ Σ_tracks max(0, target − h_min)`
//! (`optim::sqp`, `optim::qp`). The target is the certified altitude
//! `h_a + m_s` plus the boundary tolerance on the first track, and that plus
//! a quarter of the penalty margin `m_p` on the later ones (the next calls
//! start from their depths, and from a measured state a plan on the
//! boundary would not hold). So the committed depth lands on the certified
//! boundary where the constraint is active, in a handful of iterations
//! (about 5 cold, 0–1 warm on the Monterey lines), from any start: the
//! starting point only picks the basin. A coordinate whose gradient is
//! exactly zero (a plateau, contract §10) is scanned once, the tracks
//! before it flown once for all its points; the SQP restarts from the
//! best point (at most twice) when its gain in `J` covers its shortfall
//! priced at a tenth of the merit weight `ρ`, and keeps the restart only
//! if it ends better; a later call that continues the plan does not scan
//! it again. Under declared uncertainty the targets are raised track by
//! track by the certification gap (`gaps.rs`), so that the optimum is the
//! certified one.
//!
//! **Constraint, a horizon, under GD** (the paper's baseline). `h >= h_a`
//! enters the optimization as a quadratic penalty: `Φ = Σ J + μ Σ V` with
//! `V = ½ ∫ max(0, h_a + m_p − h)² dx` (the violation of
//! [`crate::TrackScore`], taken against `h_a` plus the penalty margin
//! `m_p`), whose exact gradient comes from the same tangent pass. `J`
//! ranges from 1e2 to 1e8 m³ between a shallow bay and a canyon wall, so
//! no single `μ` fits: the sequential penalty method (N&W §17.1) re-solves
//! from the last optimum with `μ` a hundred times larger while that
//! optimum still violates, for at most `penalty_stages` stages.
//!
//! **Verification.** The candidate depth is **verified by simulation** on
//! its track: below `h_a + m_s` (the safety margin, covering f32 vs f64
//! differences in altitude) the planner takes the safe depth closest to
//! the optimum (among the scanned depths, then by the boundary search), or
//! the safest depth it found.
//!
//! **Certification and commitment** (`commit.rs`, `certify/`). In
//! horizon mode the depth is committed only with a continuation to the end
//! of the line certified in every declared world (model contract §11,
//! §12), so the flown line is safe whatever the horizon, the iteration cap
//! or the budget, and [`PlanStatus::Infeasible`] comes from the first call
//! that finds no certified continuation. A later call keeps the previous
//! call's continuation, whose certificate it knows (the worlds start
//! where that call predicted), unless its candidate lowers the line's `J`
//! by more than 0.1 %; the worlds' states are flown on only when a
//! certificate needs them. The statuses: optimal (certified,
//! the constraint not active), constrained (certified, on the boundary),
//! infeasible; why the optimizer stopped is [`OptimizerStop`], apart.
//! Track-wise mode (the paper's) certifies the committed track alone and
//! promises nothing beyond it. With `constrained = false` (the paper's bare
//! objective) there is no penalty and no fallback; the certificate is
//! still flown and reported (an uncertified track is infeasible).
//!
//! | file | concern |
//! |---|---|
//! | `config.rs` | [`PlannerConfig`], [`Method`], [`Mode`], [`PlanConfigError`] |
//! | `status.rs` | [`PlanStatus`], [`OptimizerStop`], [`PlanError`] |
//! | `answer.rs` | [`Plan`], the small answer |
//! | `planner.rs` | [`Planner`]: the caller-owned planner and its entry point |
//! | `budget.rs`, `within.rs` | a call within a flight budget: the split, the fallback |
//! | `resumable.rs` | [`Resumable`]: one call as bounded steps |
//! | `candidate.rs` | one call's candidate, step by step |
//! | `commit.rs` | what is committed: the certified continuation (§11) |
//! | `carry.rs` | a track flown at a depth the planner did not choose: the worlds carried through it |
//! | `search.rs` | the continuation search from a certified anchor (§11) |
//! | `gaps.rs` | the SQP's targets raised by the certification gap (§12) |
//! | `certify/` | certificates over the declared worlds (§12), [`certify_line`]; one world's flight (`flight.rs`); the floors between a line of worlds' levels (`valley.rs`); the worlds' states between calls (`states.rs`) |
//! | `flights.rs` | the call's plain flights, counted |
//! | `solve.rs` | the optimizer runs: the SQP (BFGS), penalty stages (GD), plateau escape |
//! | `scan.rs` | the search box and the coarse scan (the starting point) |
//! | `objective.rs` | the optimizers' objective: `Σ J` with the segments' constraints (SQP), `Φ = Σ J + μ Σ V` (GD) |
//! | `single.rs` | the constrained single track's decision from its scan |
//! | `fallback.rs` | the closest safe depth, the safe-set boundary |

mod ahead;
mod answer;
mod bottom;
mod budget;
mod candidate;
mod carry;
mod certify;
mod chosen;
mod commit;
mod config;
mod dive;
mod edge;
mod fallback;
mod flights;
mod gaps;
mod jump;
mod kink;
mod knife;
mod lift;
mod looks;
mod objective;
mod planner;
mod plateau;
mod polish;
mod probe;
mod raise;
mod restart;
mod resumable;
mod scan;
mod search;
mod single;
mod sink;
mod solve;
mod status;
mod stride;
mod wider;
mod within;

pub use answer::Plan;
pub use certify::certify_line;
pub use config::{MAX_SCAN, Method, Mode, PlanConfigError, PlannerConfig};
pub use planner::{MAX_TRACKS, Planner};
pub use resumable::{Resumable, Step};
pub use status::{OptimizerStop, PlanError, PlanStatus};
