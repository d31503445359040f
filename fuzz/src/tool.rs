//! The plan tool's parsers (`examples/plan/input.rs` and `args.rs`,
//! compiled into this crate by path).
//!
//! Input format: the first byte picks the parser (modulo 5), the rest is
//! its text (UTF-8 for the files: anything else is what `read_to_string`
//! refuses, so it is skipped):
//!
//! | byte 0 | parser | text |
//! |---|---|---|
//! | 0 | `input::profile` | a profile CSV |
//! | 1 | `input::waypoints` | a waypoints CSV |
//! | 2 | `input::config` | a vehicle TOML |
//! | 3 | `args::Args::parse_os` | the arguments (any bytes), separated by NUL bytes |
//! | 4 | `args::parse_depths` | byte 1: the number of tracks; then `--depths` |
//!
//! Checked: no panic; an error prints as one line; an `Ok` holds only
//! finite values and what the library then accepts (a parsed profile or
//! waypoint list within the tool's capacity is valid for `Profile::new` /
//! `Waypoints::new`; a parsed config builds a valid `Mission`, and its
//! vehicle and planner settings are either accepted or rejected with a
//! typed error); parsed arguments satisfy the documented rules.

use std::ffi::OsString;
use std::os::unix::ffi::OsStringExt;

use auvnav::{Planner, PlannerConfig, Profile, Vehicle, Waypoints};

use crate::args::{self, Args};
use crate::fail::Fail;
use crate::input::{self, MAX_HORIZON, ORDER, SAMPLES, WAYPOINTS};

/// What one execution did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Not UTF-8 (or empty).
    Skipped,
    /// The parser (0..=4) rejected the input with a one-line message.
    Error(u8),
    /// The parser accepted it.
    Accepted(u8),
}

/// Runs one input.
pub fn run(data: &[u8]) -> Outcome {
    let Some((&which, rest)) = data.split_first() else {
        return Outcome::Skipped;
    };
    let which = which % 5;
    let (tracks, rest) = match (which, rest.split_first()) {
        (4, Some((&t, r))) => (usize::from(t), r),
        (4, None) => return Outcome::Skipped,
        _ => (0, rest),
    };
    let result = if which == 3 {
        // Arguments as the OS passes them: any bytes but NUL.
        Args::parse_os(
            rest.split(|&b| b == 0)
                .map(|a| OsString::from_vec(a.to_vec())),
        )
        .map(|a| check_args(&a))
    } else {
        let Ok(text) = std::str::from_utf8(rest) else {
            return Outcome::Skipped;
        };
        match which {
            0 => input::profile(text, "p.csv").map(|(x, b)| check_profile(&x, &b)),
            1 => input::waypoints(text, "w.csv").map(|w| check_waypoints(&w)),
            2 => input::config(Some((text, "v.toml"))).map(|c| check_config(&c)),
            _ => args::parse_depths(text, tracks).map(|d| check_depths(&d, tracks)),
        }
    };
    match result {
        Ok(()) => Outcome::Accepted(which),
        Err(e) => {
            check_message(&e);
            Outcome::Error(which)
        }
    }
}

fn check_message(e: &Fail) {
    // `--help` is not an error: its text is the whole interface.
    if matches!(e, Fail::Help) {
        return;
    }
    let line = e.to_string();
    assert!(
        !line.contains('\n') && !line.is_empty(),
        "error message is not one line: {line:?}"
    );
}

fn check_profile(x: &[f32], b: &[f32]) {
    assert_eq!(x.len(), b.len());
    assert!(x.len() >= 2, "profile of {} samples", x.len());
    assert!(
        x.iter().chain(b).all(|v| v.is_finite()),
        "non-finite profile"
    );
    assert!(
        x.windows(2).all(|w| w[0] < w[1]),
        "profile x not increasing: {x:?}"
    );
    if x.len() <= SAMPLES
        && let Err(e) = Profile::<SAMPLES>::new(x, b)
    {
        panic!("parsed profile rejected by the library: {e}");
    }
}

fn check_waypoints(w: &[f32]) {
    assert!(w.len() >= 2);
    assert!(w.iter().all(|v| v.is_finite()), "non-finite waypoints");
    assert!(
        w.windows(2).all(|p| p[0] < p[1]),
        "waypoints not increasing: {w:?}"
    );
    if w.len() <= WAYPOINTS
        && let Err(e) = Waypoints::<WAYPOINTS>::new(w)
    {
        panic!("parsed waypoints rejected by the library: {e}");
    }
}

fn check_config(c: &input::Config) {
    let v = &c.vehicle;
    let ap = &v.autopilot;
    let values = [
        v.speed,
        v.sample_time,
        ap.pitch_limit,
        ap.elevator_limit,
        ap.depth_pid.kp,
        ap.depth_pid.ki,
        ap.depth_pid.kd,
        ap.pitch_pid.kp,
        ap.pitch_pid.ki,
        ap.pitch_pid.kd,
        c.mission.reference_altitude(),
        c.mission.min_altitude(),
        c.mission.depth_limits()[0],
        c.mission.depth_limits()[1],
        c.initial_depth.unwrap_or(0.0),
        c.optimizer.gd_rate.unwrap_or(1.0),
    ];
    assert!(
        values.iter().all(|v| v.is_finite()),
        "non-finite config value: {values:?}"
    );
    assert!(
        c.plant
            .numerator()
            .iter()
            .chain(c.plant.denominator())
            .all(|v| v.is_finite()),
        "non-finite plant"
    );
    // The mission was validated when parsed; re-validating agrees.
    let m = auvnav::Mission::new(
        c.mission.reference_altitude(),
        c.mission.min_altitude(),
        c.mission.depth_limits(),
    );
    assert_eq!(m, Ok(c.mission));
    assert!(c.optimizer.max_iterations >= 1);
    // What the tool does next: typed errors or values, never a panic.
    let _ = Vehicle::<ORDER>::new(&c.vehicle, c.plant);
    let pc = c.optimizer.apply(PlannerConfig::default());
    let _ = Planner::<MAX_HORIZON>::new(pc);
}

fn check_args(a: &Args) {
    assert_eq!(
        a.profile.is_some(),
        a.waypoints.is_some(),
        "--profile without --waypoints accepted: {a:?}"
    );
    if let Some(h) = a.horizon {
        assert!((1..=MAX_HORIZON).contains(&h), "--horizon {h} accepted");
    }
}

fn check_depths(d: &[f32], tracks: usize) {
    assert_eq!(d.len(), tracks);
    assert!(d.iter().all(|v| v.is_finite()), "non-finite depths {d:?}");
}
