//! `plan fly` (spec/cli.md, "Flying a mission"): flies a line in closed
//! loop, `--runs` times, in a world that is not the planner's model, with
//! each guidance, and reports what the true vehicle met.
//!
//! Each flight `i` draws its world from `(seed, i)` and flies every
//! guidance through that same world with the same sensor noise (paired),
//! so the numbers do not depend on the thread count (rayon over flights).

mod guide;
mod plot;
mod sonar;
mod world;

use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use auvnav::{
    Mode, PlannerConfig, Profile, Scenario, TrackScore, Uncertainty, Vehicle, Waypoints,
    lower_envelope,
};
use rayon::prelude::*;

use crate::fail::Fail;
use crate::input::{self, MAX_HORIZON, ORDER, SAMPLES, WAYPOINTS};
use guide::{Kind, Line, Record};
use world::{Flight, Map, Rng, WorldSpec};

pub const USAGE: &str = "\
plan fly [--profile P.csv --waypoints W.csv | --grid GRID --line LINE [--spacing DS]]
         [--config VEHICLE.toml]
         [--world WORLD.toml] [--guidance G1,G2,...] [--runs N] [--seed S]
         [--horizon K] [--json] [--plot OUT.svg]

Flies the line in closed loop N times (default 1, seed default 1) in the
world of WORLD.toml (default: the planner's model exactly) with each
guidance (default all): horizon, certified, track, bottom-follow,
min-altitude, constant. certified uses the config's declared uncertainty;
horizon the same planner with none declared. --plot draws flight 0 of
each guidance over its true bottom (below h_a in red, DVL lock lost in
grey). --grid/--line cut the line from a bathymetry grid as `plan profile`
does (see plan --help). An option given twice is an error.";

struct Args {
    profile: Option<PathBuf>,
    waypoints: Option<PathBuf>,
    grid: Option<PathBuf>,
    line: Option<PathBuf>,
    spacing: Option<f64>,
    config: Option<PathBuf>,
    world: Option<PathBuf>,
    guidance: Vec<Kind>,
    runs: usize,
    seed: u64,
    horizon: Option<usize>,
    json: bool,
    plot: Option<PathBuf>,
}

fn parse(mut it: impl Iterator<Item = String>) -> Result<Args, Fail> {
    let mut a = Args {
        profile: None,
        waypoints: None,
        grid: None,
        line: None,
        spacing: None,
        config: None,
        world: None,
        guidance: Kind::ALL.to_vec(),
        runs: 1,
        seed: 1,
        horizon: None,
        json: false,
        plot: None,
    };
    let mut seen = std::collections::HashSet::new();
    while let Some(flag) = it.next() {
        if flag.starts_with("--") && !seen.insert(flag.clone()) {
            return Err(Fail::usage(format!("{flag} is given twice")));
        }
        let mut value = || {
            it.next()
                .ok_or_else(|| Fail::usage(format!("{flag} needs a value")))
        };
        match flag.as_str() {
            "--help" | "-h" => return Err(Fail::Help),
            "--profile" => a.profile = Some(value()?.into()),
            "--waypoints" => a.waypoints = Some(value()?.into()),
            "--grid" => a.grid = Some(value()?.into()),
            "--line" => a.line = Some(value()?.into()),
            "--spacing" => {
                let v = value()?;
                let ds = v.parse::<f64>().ok().filter(|d| d.is_finite() && *d > 0.0);
                a.spacing = Some(ds.ok_or_else(|| {
                    Fail::usage(format!("--spacing: `{v}` is not a positive distance in m"))
                })?);
            }
            "--config" => a.config = Some(value()?.into()),
            "--world" => a.world = Some(value()?.into()),
            "--plot" => a.plot = Some(value()?.into()),
            "--json" => a.json = true,
            "--guidance" => {
                a.guidance = value()?
                    .split(',')
                    .map(|g| {
                        Kind::parse(g.trim()).ok_or_else(|| {
                            Fail::usage(format!("--guidance: unknown guidance `{g}`"))
                        })
                    })
                    .collect::<Result<_, _>>()?;
            }
            "--runs" | "--seed" | "--horizon" => {
                let v = value()?;
                let n: u64 = v
                    .parse()
                    .map_err(|_| Fail::usage(format!("{flag}: `{v}` is not a whole number")))?;
                match flag.as_str() {
                    "--runs" if n >= 1 => a.runs = n as usize,
                    "--seed" => a.seed = n,
                    "--horizon" if n >= 1 => a.horizon = Some(n as usize),
                    _ => return Err(Fail::usage(format!("{flag} must be at least 1"))),
                }
            }
            f => {
                return Err(Fail::usage(format!(
                    "fly: unknown option `{f}` (see plan fly --help)"
                )));
            }
        }
    }
    check(a)
}

/// The options that go together or exclude each other.
fn check(a: Args) -> Result<Args, Fail> {
    if a.profile.is_some() != a.waypoints.is_some() {
        return Err(Fail::usage("--profile and --waypoints go together".into()));
    }
    if a.grid.is_some() != a.line.is_some() {
        return Err(Fail::usage("--grid and --line go together".into()));
    }
    if a.grid.is_some() && a.profile.is_some() {
        return Err(Fail::usage(
            "--grid/--line replace --profile/--waypoints: give one or the other".into(),
        ));
    }
    if a.spacing.is_some() && a.grid.is_none() {
        return Err(Fail::usage("--spacing needs --grid and --line".into()));
    }
    Ok(a)
}

/// `plan fly ...`.
pub fn main(args: impl Iterator<Item = String>) -> Result<(), Fail> {
    let a = match parse(args) {
        Err(Fail::Help) => {
            println!("{USAGE}");
            return Ok(());
        }
        r => r?,
    };
    let Inputs {
        cfg,
        spec,
        px,
        pb,
        wx,
        profile_name,
        wp_name,
    } = load(&a)?;
    let profile = Box::new(
        Profile::<SAMPLES>::new(&px, &pb)
            .map_err(|e| Fail::input(format!("{profile_name}: {e}")))?,
    );
    let waypoints =
        Waypoints::<WAYPOINTS>::new(&wx).map_err(|e| Fail::input(format!("{wp_name}: {e}")))?;
    let vehicle = Vehicle::new(&cfg.vehicle, cfg.plant).map_err(|e| Fail::input(format!("{e}")))?;
    let declared = (cfg.uncertainty.declared()).map_err(|e| Fail::input(format!("config: {e}")))?;
    let x0 = wx[0];
    let envelope = Box::new(
        lower_envelope::<{ 3 * SAMPLES + 1 }>(profile.view(), &declared, x0)
            .map_err(|e| Fail::input(format!("{profile_name}: certification bottom: {e}")))?,
    );
    let fail = |e: auvnav::SimError| Fail::input(format!("{wp_name}: {e}"));
    let nominal_mission = cfg.mission.with_uncertainty(Uncertainty::NONE);
    let nominal = Scenario::new(&vehicle, &*profile, &waypoints, nominal_mission).map_err(fail)?;
    let declared_sc = Scenario::new(
        &vehicle,
        &*profile,
        &waypoints,
        cfg.mission.with_uncertainty(declared),
    )
    .and_then(|s| s.with_certification_bottom(envelope.view()))
    .map_err(fail)?;
    let initial_depth = cfg
        .initial_depth
        .unwrap_or_else(|| nominal.default_initial_depth());
    let planner = PlannerConfig {
        mode: Mode::Horizon,
        horizon: a.horizon.unwrap_or(usize::MAX),
        ..cfg.optimizer.apply(PlannerConfig::default())
    };
    let track_plan = plan_track_wise(&nominal, planner, initial_depth)?;
    let constant = deepest_constant(&nominal, initial_depth)?;
    let line = Line {
        nominal,
        declared: declared_sc,
        planner,
        map: Map {
            x: px.iter().map(|&v| f64::from(v)).collect(),
            b: pb.iter().map(|&v| f64::from(v)).collect(),
        },
        wp: wx.iter().map(|&v| f64::from(v)).collect(),
        initial_depth,
        track_plan,
        constant,
    };
    let flights = fly_all(&line, &spec, &a)?;
    if let Some(path) = &a.plot {
        draw(path, &line, &a, &flights, &profile_name)?;
    }
    println!("{}", report(&line, &a, &flights, a.json));
    Ok(())
}

/// What the files say.
struct Inputs {
    cfg: input::Config,
    spec: WorldSpec,
    px: Vec<f32>,
    pb: Vec<f32>,
    wx: Vec<f32>,
    profile_name: String,
    wp_name: String,
}

/// Reads the profile, waypoints, config and world (input.rs's loaders).
fn load(a: &Args) -> Result<Inputs, Fail> {
    let crate::source::LineInput {
        profile_text,
        profile_name,
        wp_text,
        wp_name,
        ..
    } = crate::source::LineSource {
        profile: a.profile.as_deref(),
        waypoints: a.waypoints.as_deref(),
        grid: a.grid.as_deref(),
        line: a.line.as_deref(),
        spacing: a.spacing,
    }
    .read()?;
    let config_text = match &a.config {
        Some(p) => Some((input::read(p)?, p.display().to_string())),
        None => None,
    };
    let cfg = input::config(config_text.as_ref().map(|(t, n)| (t.as_str(), n.as_str())))?;
    let spec = match &a.world {
        Some(p) => WorldSpec::parse(&input::read(p)?, &p.display().to_string())?,
        None => WorldSpec::nominal(),
    };
    let (px, pb) = input::profile(&profile_text, &profile_name)?;
    let wx = input::waypoints(&wp_text, &wp_name)?;
    Ok(Inputs {
        cfg,
        spec,
        px,
        pb,
        wx,
        profile_name,
        wp_name,
    })
}

/// `--plot`: flight 0 of each guidance.
fn draw(
    path: &std::path::Path,
    line: &Line<'_>,
    a: &Args,
    flights: &[Vec<Record>],
    profile_name: &str,
) -> Result<(), Fail> {
    let Some(first) = flights.first() else {
        return Ok(());
    };
    let tracks: Vec<plot::Track<'_>> = a
        .guidance
        .iter()
        .zip(first)
        .map(|(&k, r)| plot::Track {
            name: k.name(),
            sonar: k.sonar(),
            path: &r.path,
        })
        .collect();
    let title = format!(
        "{profile_name}: flight 0 of seed {} ({}), true bottom, h_a = {} m",
        a.seed,
        a.world
            .as_ref()
            .map_or("nominal world".into(), |p| p.display().to_string()),
        line.nominal.mission().min_altitude()
    );
    plot::draw(
        path,
        &title,
        f64::from(line.nominal.mission().min_altitude()),
        (&line.map.x, &line.map.b),
        &tracks,
    )?;
    Ok(())
}

/// The paper's track-wise plan over the map, each track from the state
/// the previous one predicts.
fn plan_track_wise(sc: &Scenario<'_, ORDER>, pc: PlannerConfig, d0: f32) -> Result<Vec<f32>, Fail> {
    let mut planner = Box::new(
        auvnav::Planner::<MAX_HORIZON, ORDER>::new(PlannerConfig {
            mode: Mode::TrackWise,
            ..pc
        })
        .map_err(|e| Fail::input(format!("config: {e}")))?,
    );
    let mut state = sc.start_state(d0);
    let mut depths = Vec::new();
    for n in 0..sc.waypoints().tracks() {
        match planner.plan(sc, &state, n) {
            Ok(p) => {
                depths.push(p.depth);
                state = p.next_state;
            }
            Err(_) => depths.push(sc.mission().depth_limits()[0]),
        }
    }
    Ok(depths)
}

/// The deepest constant reference depth whose flight over the map stays at
/// least `h_a` above it on every track (bisection to 1 cm).
fn deepest_constant(sc: &Scenario<'_, ORDER>, d0: f32) -> Result<f32, Fail> {
    let tracks = sc.waypoints().tracks();
    let start = sc.start_state(d0);
    let h_a = sc.mission().min_altitude();
    let safe = |z: f32| {
        let mut s = vec![TrackScore::default(); tracks];
        sc.simulate(&start, 0, &vec![z; tracks], &mut s, |_| {})
            .is_ok()
            && s.iter().all(|t| t.min_altitude() >= h_a)
    };
    let [mut lo, hi] = sc.mission().depth_limits();
    let mut hi = hi.min(sc.profile().depths().iter().copied().fold(0.0, f32::max));
    if !safe(lo) {
        return Ok(lo);
    }
    while hi - lo > 0.01 {
        let mid = 0.5 * (lo + hi);
        if safe(mid) { lo = mid } else { hi = mid }
    }
    Ok(lo)
}

/// Every flight, in parallel; each flight's guidances in order.
fn fly_all(line: &Line<'_>, spec: &WorldSpec, a: &Args) -> Result<Vec<Vec<Record>>, Fail> {
    let done = AtomicUsize::new(0);
    let t0 = Instant::now();
    let x_end = *line.wp.last().unwrap_or(&0.0);
    let out: Result<Vec<Vec<Record>>, String> = (0..a.runs)
        .into_par_iter()
        .map(|i| {
            let mut rng = Rng::new(a.seed, i as u64);
            let world = Flight::draw(spec, &mut rng, line.wp[0], x_end);
            let noise = (rng.next(), i as u64);
            let recs = a
                .guidance
                .iter()
                .map(|&k| guide::fly(line, &world, k, noise, i == 0 && a.plot.is_some()))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| format!("flight {i}: {e}"));
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            if t0.elapsed().as_secs_f64() > 1.0 {
                eprint!(
                    "\rflown {n}/{} ({:.0} s)",
                    a.runs,
                    t0.elapsed().as_secs_f64()
                );
            }
            recs
        })
        .collect();
    if t0.elapsed().as_secs_f64() > 1.0 {
        eprintln!();
    }
    out.map_err(Fail::input)
}

/// The report: cli.md's JSON object (with more fields) or a table.
fn report(line: &Line<'_>, a: &Args, flights: &[Vec<Record>], json: bool) -> String {
    let ts = f64::from(line.nominal.vehicle().sample_time());
    let h_a = f64::from(line.nominal.mission().min_altitude());
    let mut rows = Vec::new();
    for (g, &kind) in a.guidance.iter().enumerate() {
        let recs: Vec<&Record> = flights.iter().map(|f| &f[g]).collect();
        let n = recs.len() as f64;
        let pings: u64 = recs.iter().map(|r| r.pings).sum();
        let est: Vec<[f64; 3]> = recs.iter().flat_map(|r| r.est.iter().copied()).collect();
        let max_abs = |k: usize| est.iter().map(|e| e[k].abs()).fold(0.0, f64::max);
        let rms = |k: usize| {
            (est.iter().map(|e| e[k] * e[k]).sum::<f64>() / est.len().max(1) as f64).sqrt()
        };
        let first = recs.first();
        rows.push(serde_json::json!({
            "name": kind.name(),
            "flights": recs.len(),
            "collisions": recs.iter().filter(|r| r.collided).count(),
            "below_min_altitude": recs.iter().filter(|r| r.min_altitude < h_a).count(),
            "worst_min_altitude": recs.iter().map(|r| r.min_altitude).fold(f64::INFINITY, f64::min),
            "mean_min_altitude": recs.iter().map(|r| r.min_altitude).sum::<f64>() / n,
            "mean_rms_altitude_error": recs.iter().map(|r| (r.sum_sq / r.samples as f64).sqrt()).sum::<f64>() / n,
            "mean_altitude": recs.iter().map(|r| r.sum_alt / r.samples as f64).sum::<f64>() / n,
            "time_below_min_altitude_s": recs.iter().map(|r| r.below_steps as f64 * ts).sum::<f64>() / n,
            "max_time_below_min_altitude_s": recs.iter().map(|r| r.below_steps as f64 * ts).fold(0.0, f64::max),
            "bottom_lock_fraction": kind.sonar().then(|| recs.iter().map(|r| r.lock_steps).sum::<u64>() as f64 / pings.max(1) as f64),
            "first_flight_worst_at_x": first.map(|r| r.min_at),
            "first_flight_track_min_altitude": first.map(|r| r.track_min.clone()),
            "first_flight_predicted_min_altitude": first.map(|r| r.predicted.clone()),
            "estimator": (!est.is_empty()).then(|| serde_json::json!({
                "replans": est.len(),
                "depth_error_rms_m": rms(0), "depth_error_max_m": max_abs(0),
                "pitch_error_rms_deg": rms(1), "pitch_error_max_deg": max_abs(1),
                "predicted_min_altitude_error_rms_m": rms(2),
                "predicted_min_altitude_error_max_m": max_abs(2),
            })),
        }));
    }
    if json {
        let o = serde_json::json!({
            "runs": a.runs, "seed": a.seed,
            "track_plan": line.track_plan, "constant_depth": line.constant,
            "guidance": rows,
        });
        return o.to_string();
    }
    let mut s = format!(
        "{} flights, seed {}; h_r {} m, h_a {} m; constant depth {:.1} m\n{:<14} {:>6} {:>6} {:>8} {:>8} {:>8} {:>8} {:>8}\n",
        a.runs,
        a.seed,
        line.nominal.mission().reference_altitude(),
        h_a,
        line.constant,
        "guidance",
        "coll",
        "<h_a",
        "worst",
        "RMS",
        "mean",
        "t<h_a",
        "lock"
    );
    for r in &rows {
        s += &format!(
            "{:<14} {:>6} {:>6} {:>8.2} {:>8.2} {:>8.2} {:>8.1} {:>8}\n",
            r["name"].as_str().unwrap_or(""),
            r["collisions"],
            r["below_min_altitude"],
            r["worst_min_altitude"].as_f64().unwrap_or(f64::NAN),
            r["mean_rms_altitude_error"].as_f64().unwrap_or(f64::NAN),
            r["mean_altitude"].as_f64().unwrap_or(f64::NAN),
            r["time_below_min_altitude_s"].as_f64().unwrap_or(f64::NAN),
            r["bottom_lock_fraction"]
                .as_f64()
                .map_or("-".into(), |v| format!("{v:.3}")),
        );
    }
    s.trim_end().to_string()
}
