//! Shared by the host integration tests: loads the committed f64 fixtures
//! (written by `tools/reference/make_fixtures.py`) and builds library
//! objects from their configuration dictionaries.
#![allow(dead_code)]
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![allow(clippy::arithmetic_side_effects)]

use auvnav::{
    AutopilotConfig, Mission, PidGains, Profile, Scenario, TfKind, TransferFunction, Uncertainty,
    Vehicle, VehicleConfig, Waypoints, lower_envelope,
};
use serde_json::Value;

/// Plant order capacity used by the tests (the fixtures go up to 4).
pub const N: usize = 4;
/// Profile capacity used by the tests.
pub const S: usize = 4096;
/// Waypoint capacity used by the tests.
pub const W: usize = 16;

pub fn fixture(name: &str) -> Value {
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_json::from_str(&text).unwrap()
}

pub fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

pub fn fs(v: &Value) -> Vec<f32> {
    v.as_array().unwrap().iter().map(|x| f(x) as f32).collect()
}

pub fn f64s(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(f).collect()
}

pub fn kind(v: &Value) -> TfKind {
    match v.as_str().unwrap() {
        "pitch" => TfKind::Pitch,
        "rate" => TfKind::Rate,
        k => panic!("plant kind {k}"),
    }
}

pub fn plant(p: &Value) -> TransferFunction<N> {
    TransferFunction::new(kind(&p["kind"]), &fs(&p["num"]), &fs(&p["den"])).unwrap()
}

pub fn pid(v: &Value) -> PidGains {
    PidGains {
        kp: f(&v["kp"]) as f32,
        ki: f(&v["ki"]) as f32,
        kd: f(&v["kd"]) as f32,
    }
}

/// Vehicle, mission and initial depth from a fixture's `vehicle` dict
/// (every key of the tool's TOML present).
pub fn vehicle(v: &Value) -> (Vehicle<N>, Mission, f32) {
    let cfg = VehicleConfig {
        speed: f(&v["speed"]) as f32,
        sample_time: f(&v["sample_time"]) as f32,
        autopilot: AutopilotConfig {
            depth_pid: pid(&v["depth_pid"]),
            pitch_pid: pid(&v["pitch_pid"]),
            pitch_limit: f(&v["pitch_limit"]) as f32,
            elevator_limit: f(&v["elevator_limit"]) as f32,
        },
    };
    let lim = fs(&v["depth_limits"]);
    let mission = Mission::new(
        f(&v["reference_altitude"]) as f32,
        f(&v["min_altitude"]) as f32,
        [lim[0], lim[1]],
    )
    .unwrap();
    (
        Vehicle::new(&cfg, plant(&v["plant"])).unwrap(),
        mission,
        f(&v["initial_depth"]) as f32,
    )
}

/// Column `col` of a CSV file under the crate (`rel`, from the manifest
/// directory), its header skipped.
pub fn csv_column(rel: &str, col: usize) -> Vec<f32> {
    let path = format!("{}/{rel}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').nth(col).unwrap().trim().parse().unwrap())
        .collect()
}

/// Reads a bundled profile CSV (`x_m,bottom_depth_m`).
pub fn real_profile(name: &str) -> (Vec<f32>, Vec<f32>) {
    let rel = format!("data/bathymetry/{name}.csv");
    (csv_column(&rel, 0), csv_column(&rel, 1))
}

/// Reads a bundled waypoint CSV (`wp,x_m,...`).
pub fn real_waypoints(name: &str) -> Vec<f32> {
    csv_column(&format!("data/bathymetry/{name}.waypoints.csv"), 1)
}

/// A fixture case's profile: a real profile's name or an inline `{x, b}`.
pub fn profile(v: &Value) -> Profile<S> {
    let (x, b) = match v {
        Value::String(name) => real_profile(name),
        Value::Object(o) => (fs(&o["x"]), fs(&o["b"])),
        _ => panic!("profile {v}"),
    };
    Profile::new(&x, &b).unwrap()
}

/// `|got - want| <= rel * |want|`, with the pair in the message.
pub fn rel_err(got: f64, want: f64) -> f64 {
    (got - want).abs() / want.abs().max(f64::MIN_POSITIVE)
}

/// `f` on the line `map`, `wps` (`h_r`, `h_a`, m; depth limits 0–6000 m)
/// under the declared uncertainty `u`, certified over the map's lower
/// envelope from the line's start. (A closure: the scenario borrows the
/// envelope made here.)
pub fn with_declared<R>(
    vehicle: &Vehicle<3>,
    (map, wps): (&Profile<S>, &Waypoints<W>),
    (h_r, h_a): (f32, f32),
    u: Uncertainty,
    f: impl FnOnce(&Scenario<'_, 3>) -> R,
) -> R {
    let env = lower_envelope::<{ 3 * S }>(map.view(), &u, wps.positions()[0]).unwrap();
    let mission = Mission::new(h_r, h_a, [0.0, 6000.0])
        .unwrap()
        .with_uncertainty(u);
    let sc = Scenario::new(vehicle, map, wps, mission)
        .unwrap()
        .with_certification_bottom(env.view())
        .unwrap();
    f(&sc)
}
