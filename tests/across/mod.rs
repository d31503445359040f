//! Shared by the tests that sample the worlds a certificate claims
//! (`tests/certified.rs`, `tests/between.rs`): one open-loop flight of a
//! plan in a world, a world's bottom, the fixtures' lines, a line planned
//! call by call, the `plan` tool's line, and the check that each
//! certified altitude is at most the flown one.
#![allow(dead_code)]
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]
#![allow(clippy::arithmetic_side_effects, clippy::cast_precision_loss)]

use auvnav::{
    PidGains, Plan, Planner, Profile, Scenario, TfKind, TrackScore, TransferFunction, Uncertainty,
    Vehicle, VehicleConfig, VehicleState, Waypoints, World,
};

use crate::common::csv_column;
use crate::tool;

/// The least altitude of each track of `depths` flown open loop from
/// `start` in `world` over `bottom`.
pub fn fly(
    sc: &Scenario<'_, 3>,
    world: &World,
    bottom: &Profile<8192>,
    start: &VehicleState<3>,
    depths: &[f32],
) -> Vec<f32> {
    let scw = sc.in_world(world, bottom.view()).unwrap();
    let mut s = vec![TrackScore::default(); depths.len()];
    match scw.simulate(start, 0, depths, &mut s, |_| {}) {
        Ok(_) => s.iter().map(TrackScore::min_altitude).collect(),
        Err(_) => vec![f32::NEG_INFINITY; depths.len()],
    }
}

/// Fixture `name` of `tests/fixtures/horizon/`: its map's samples (x and
/// bottom depth, m), the map and its waypoints.
pub fn fixture_line(name: &str) -> (Vec<f32>, Vec<f32>, Profile<4096>, Waypoints<16>) {
    let rel = format!("tests/fixtures/horizon/{name}");
    let (x, b) = (
        csv_column(&format!("{rel}.csv"), 0),
        csv_column(&format!("{rel}.csv"), 1),
    );
    let map = Profile::<4096>::new(&x, &b).unwrap();
    let wps = Waypoints::<16>::new(&csv_column(&format!("{rel}.waypoints.csv"), 1)).unwrap();
    (x, b, map, wps)
}

/// The vehicle of fixture `name` as the `plan` tool reads it from
/// `NAME.toml` (the library's defaults for the keys it leaves out, the
/// C-AUV4 plant without a `[plant]` table): the vehicle, the declared
/// uncertainty, `(h_r, h_a)` (m) and its `initial_depth` if it sets one
/// (m).
pub fn fixture_vehicle(name: &str) -> (Vehicle<3>, Uncertainty, (f32, f32), Option<f32>) {
    let path = format!(
        "{}/tests/fixtures/horizon/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let t: toml::Table = std::fs::read_to_string(&path).unwrap().parse().unwrap();
    let num = |t: &toml::Table, k: &str| t.get(k).map(|v| v.as_float().unwrap() as f32);
    let nums = |v: &toml::Value| -> Vec<f32> {
        let a = v.as_array().unwrap();
        a.iter().map(|x| x.as_float().unwrap() as f32).collect()
    };
    let pid = |k: &str, d: PidGains| {
        t.get(k)
            .and_then(toml::Value::as_table)
            .map_or(d, |g| PidGains {
                kp: num(g, "kp").unwrap_or(d.kp),
                ki: num(g, "ki").unwrap_or(d.ki),
                kd: num(g, "kd").unwrap_or(d.kd),
            })
    };
    let mut cfg = VehicleConfig::default();
    cfg.speed = num(&t, "speed").unwrap_or(cfg.speed);
    cfg.sample_time = num(&t, "sample_time").unwrap_or(cfg.sample_time);
    let ap = &mut cfg.autopilot;
    ap.pitch_limit = num(&t, "pitch_limit").unwrap_or(ap.pitch_limit);
    ap.elevator_limit = num(&t, "elevator_limit").unwrap_or(ap.elevator_limit);
    ap.depth_pid = pid("depth_pid", ap.depth_pid);
    ap.pitch_pid = pid("pitch_pid", ap.pitch_pid);
    let plant = t.get("plant").map_or(TransferFunction::C_AUV4, |p| {
        assert_eq!(p["kind"].as_str(), Some("pitch"));
        TransferFunction::new(TfKind::Pitch, &nums(&p["num"]), &nums(&p["den"])).unwrap()
    });
    let bound = |k: &str| num(&t, k).unwrap_or(0.0);
    let u = Uncertainty::new(
        bound("horizontal_uncertainty"),
        bound("nav_drift"),
        bound("vertical_uncertainty"),
        bound("speed_uncertainty"),
        bound("flight_path_offset"),
        bound("vertical_current"),
    )
    .unwrap();
    let altitudes = (
        num(&t, "reference_altitude").unwrap(),
        num(&t, "min_altitude").unwrap(),
    );
    let vehicle = Vehicle::new(&cfg, plant).unwrap();
    (vehicle, u, altitudes, num(&t, "initial_depth"))
}

/// Flies `depths` from `start` in `world` over `bottom` and asserts that
/// each track's certified altitude (`certified`, m) is at most its least
/// altitude there (1 mm allowed); `what` names the plan. Returns the
/// tracks checked.
pub fn certified_bounds(
    sc: &Scenario<'_, 3>,
    (world, bottom): (&World, &Profile<8192>),
    start: &VehicleState<3>,
    (depths, certified): (&[f32], &[f32]),
    what: &str,
) -> usize {
    let least = fly(sc, world, bottom, start, depths);
    for (t, (&h, &c)) in least.iter().zip(certified).enumerate() {
        assert!(
            c <= h + 1e-3,
            "{what} track {}: certified {c} m, flies {h} m in {world:?}",
            t + 1
        );
    }
    least.len().min(certified.len())
}

/// [`certified_bounds`] in the `2 half + 1` worlds `world(s)`, `s` evenly
/// from −1 to 1 across a declared bound; returns the tracks checked.
pub fn certified_across(
    sc: &Scenario<'_, 3>,
    (bottom, start): (&Profile<8192>, &VehicleState<3>),
    plan: (&[f32], &[f32]),
    what: &str,
    (half, world): (u32, impl Fn(f32) -> World),
) -> usize {
    (0..=2 * half)
        .map(|k| {
            let w = world(k as f32 / half as f32 - 1.0);
            certified_bounds(sc, (&w, bottom), start, plan, what)
        })
        .sum()
}

/// The `plan` tool's line for fixture `name` with `args`: each track's
/// depth and certified altitude (m).
pub fn tool_line(name: &str, args: &[&str]) -> (Vec<f32>, Vec<f32>) {
    let plan = tool::json_of_fixture(name, args);
    let tracks = plan["tracks"].as_array().unwrap();
    let value = |k: &str| -> Vec<f32> {
        tracks
            .iter()
            .map(|t| t[k].as_f64().unwrap() as f32)
            .collect()
    };
    (value("depth"), value("certified_min_altitude"))
}

/// A linear congruential generator (Knuth's MMIX constants).
pub struct Lcg(pub u64);
impl Lcg {
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    /// Uniform in [−1, 1).
    pub fn sym(&mut self) -> f32 {
        2.0 * self.unit() - 1.0
    }
}

/// A world's bottom: `b(x + s(x)) + v(x)` on a 2 m grid, `s` and `v` sums
/// of three random sinusoids scaled into their bounds (or, for `corner`,
/// the constant extremes).
pub fn world_bottom(
    map: &Profile<4096>,
    u: &Uncertainty,
    x0: f32,
    rng: &mut Lcg,
    corner: Option<(f32, f32)>,
) -> Profile<8192> {
    let (a, b) = (map.start(), map.end());
    let n = (((b - a) / 2.0) as usize).min(8000);
    let waves: Vec<(f32, f32, f32)> = (0..3)
        .map(|_| {
            (
                rng.sym(),
                200.0 + 800.0 * rng.unit(),
                std::f32::consts::TAU * rng.unit(),
            )
        })
        .collect();
    let shape = |x: f32, k: usize| -> f32 {
        let s: f32 = waves
            .iter()
            .map(|&(amp, len, ph)| amp * (std::f32::consts::TAU * x / len + ph + k as f32).sin())
            .sum();
        (s / 3.0).clamp(-1.0, 1.0)
    };
    let xs: Vec<f32> = (0..=n).map(|i| a + (b - a) * i as f32 / n as f32).collect();
    let bs: Vec<f32> = xs
        .iter()
        .map(|&x| {
            let (fs, fv) = corner.unwrap_or((shape(x, 0), shape(x, 7)));
            let s = fs * u.offset_at(x, x0);
            let v = fv * u.vertical();
            map.depth_at((x + s).clamp(a, b)).unwrap() + v
        })
        .collect();
    Profile::new(&xs, &bs).unwrap()
}

/// The line planned track by track from `start`, each call from the
/// state the one before predicted, until a call fails (a start in the
/// rock): each track's plan.
pub fn plan_line<const K: usize>(
    planner: &mut Planner<K>,
    sc: &Scenario<'_, 3>,
    start: &VehicleState<3>,
) -> Vec<Plan<3>> {
    let mut plans: Vec<Plan<3>> = Vec::new();
    for n in 0..sc.waypoints().tracks() {
        let st = plans.last().map_or(*start, |p| p.next_state);
        let Ok(p) = planner.plan(sc, &st, n) else {
            break;
        };
        plans.push(p);
    }
    plans
}
