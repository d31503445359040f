//! The harnesses behind the fuzz targets of `fuzz_targets/`, as a library so
//! that `cargo test` here can replay saved inputs (`regressions/`) through
//! exactly the code the fuzzer runs.
//!
//! - [`planner`]: `Planner::<1>` and `Planner::<3>` on arbitrary lines,
//!   vehicles, missions and settings; every `Ok` plan is checked against
//!   the contract (finite, within the depth limits, `safe` as documented,
//!   the same flight as a plain re-simulation).
//! - [`simulate`]: `Scenario::simulate` and `Scenario::evaluate` with
//!   arbitrary depths and start states; finite output or a typed error, and
//!   the plain and the tangent pass fly the same flight.
//! - [`tool`]: the plan tool's parsers (`examples/plan/`, compiled in by
//!   path, not copied); an `Ok` holds only what the library then accepts.
//!
//! Each harness returns what happened (for the statistics of
//! `tests/replay.rs`) and panics on a contract violation.

pub mod known;
pub mod line;
pub mod planner;
pub mod simulate;
pub mod tool;

// The plan tool's own modules, as the example compiles them.
#[path = "../../examples/plan/args.rs"]
#[allow(dead_code)]
pub mod args;
#[path = "../../examples/plan/fail.rs"]
#[allow(dead_code)]
pub mod fail;
#[path = "../../examples/plan/input.rs"]
#[allow(dead_code)]
pub mod input;
// What args.rs and input.rs reach of the map side (`--spacing`, lat/lon
// waypoint columns) and what that reaches of the report.
#[path = "../../examples/plan/map/mod.rs"]
#[allow(dead_code)]
pub mod map;
#[path = "../../examples/plan/report.rs"]
#[allow(dead_code)]
pub mod report;
