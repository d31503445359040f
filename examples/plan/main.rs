//! `plan`: the host planning tool (spec/cli.md).
//!
//! Plans (or, with `--depths`, evaluates) the reference depths of a survey
//! line over a bathymetry profile, and reports each track's score, safety
//! and the optimizer's effort. With no arguments it does the main job on
//! the bundled Monterey Canyon line.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]
#![allow(clippy::arithmetic_side_effects, clippy::panic)]

mod args;
mod fail;
mod fly;
mod input;
mod map;
mod plot;
mod progress;
mod report;
mod source;

use std::process::ExitCode;

use auvnav::{
    Method, Mode, PlanError, Planner, PlannerConfig, Profile, Scenario, TrackScore, Vehicle,
    Waypoints, lower_envelope,
};

use args::Args;
use fail::Fail;
use input::{MAX_HORIZON, SAMPLES, WAYPOINTS};

/// Room for the certification bottom: the map's samples and two window
/// crossings per sample.
const ENVELOPE: usize = 3 * SAMPLES + 1;
use report::{Report, TrackReport, TrajRow};
use source::{LineInput, LineSource};

fn main() -> ExitCode {
    // Subcommands by their first argument; anything else is the planner.
    let mut argv = std::env::args_os().skip(1).peekable();
    let result = match argv.peek().and_then(|a| a.to_str()) {
        Some("profile") => {
            argv.next();
            map::profile_command(argv)
        }
        Some("fly") => fly::main(std::env::args().skip(2)),
        _ => run(Args::parse_os(argv)),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Fail::Help) => {
            println!("{}", args::USAGE);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn run(args: Result<Args, Fail>) -> Result<(), Fail> {
    let args = args?;
    // What the report calls the profile and the vehicle.
    let source = LineSource {
        profile: args.profile.as_deref(),
        waypoints: args.waypoints.as_deref(),
        grid: args.grid.as_deref(),
        line: args.line.as_deref(),
        spacing: args.spacing,
    };
    let profile_label = source.label();
    let vehicle_label = args.config.as_ref().map_or_else(
        || "C-AUV #4 (default)".to_string(),
        |p| p.display().to_string(),
    );
    let LineInput {
        profile_text,
        profile_name,
        wp_text,
        wp_name,
        mut cut,
    } = source.read()?;
    let config_text = match &args.config {
        Some(p) => Some((input::read(p)?, p.display().to_string())),
        None => None,
    };
    let cfg = input::config(config_text.as_ref().map(|(t, n)| (t.as_str(), n.as_str())))?;
    let cfg_name = config_text.as_ref().map_or("", |(_, n)| n.as_str());

    let (px, pb) = input::profile(&profile_text, &profile_name)?;
    let profile = Profile::<SAMPLES>::new(&px, &pb)
        .map_err(|e| Fail::input(format!("{profile_name}: {e}")))?;
    let wx = input::waypoints(&wp_text, &wp_name)?;
    if (args.geojson.is_some() || args.plot.is_some()) && cut.is_none() {
        // The line on the map from waypoints with lat,lon columns: needed
        // by --geojson, a map inset for --plot.
        match input::waypoint_positions(&wp_text, &wp_name, &wx) {
            Ok(c) => cut = Some(c),
            Err(e) if args.geojson.is_some() => return Err(e),
            Err(_) => {}
        }
    }
    let waypoints =
        Waypoints::<WAYPOINTS>::new(&wx).map_err(|e| Fail::input(format!("{wp_name}: {e}")))?;
    let vehicle = Vehicle::new(&cfg.vehicle, cfg.plant)
        .map_err(|e| Fail::input(format!("{}{e}", input::prefix(cfg_name))))?;
    let uncertainty = (cfg.uncertainty.declared())
        .map_err(|e| Fail::input(format!("{}{e}", input::prefix(cfg_name))))?;
    let mission = cfg.mission.with_uncertainty(uncertainty);
    // The certification bottom: the map's lower envelope under the map
    // uncertainty (the map itself when none is declared).
    let x0 = wx.first().copied().unwrap_or(0.0);
    let envelope = Box::new(
        lower_envelope::<ENVELOPE>(profile.view(), &uncertainty, x0)
            .map_err(|e| Fail::input(format!("{profile_name}: certification bottom: {e}")))?,
    );
    let scenario = Scenario::new(&vehicle, &profile, &waypoints, mission)
        .and_then(|sc| sc.with_certification_bottom(envelope.view()))
        .map_err(|e| {
            Fail::input(format!(
                "{wp_name}: {e} [{:.1}, {:.1}] m",
                profile.start(),
                profile.end()
            ))
        })?;
    let initial_depth = cfg
        .initial_depth
        .unwrap_or_else(|| scenario.default_initial_depth());
    for w in sanity(&cfg, cfg_name, &profile, &profile_name, &wx)? {
        eprintln!("warning: {w}");
    }

    let tracks = waypoints.tracks();
    let report_base = match &args.depths {
        Some(text) => {
            let depths = args::parse_depths(text, tracks)?;
            let [lo, hi] = cfg.mission.depth_limits();
            if let Some((i, z)) = depths
                .iter()
                .enumerate()
                .find(|&(_, &z)| !(lo..=hi).contains(&z))
            {
                return Err(Fail::input(format!(
                    "--depths: value {} ({z} m) is outside depth_limits [{lo}, {hi}] m{}",
                    i + 1,
                    if cfg_name.is_empty() {
                        " (the default)".to_string()
                    } else {
                        format!(" of {cfg_name}")
                    }
                )));
            }
            Plan {
                method: "fixed",
                mode: "fixed",
                depths,
                optimizer: vec![Effort::fixed(); tracks],
            }
        }
        None => plan_line(&args, &cfg, &scenario, initial_depth)?,
    };

    // The flight the reported depths produce, scored track by track.
    let start = scenario.start_state(initial_depth);
    let mut scores = vec![TrackScore::default(); tracks];
    let mut rows = Vec::new();
    let record = args.trajectory.is_some() || args.plot.is_some() || args.geojson.is_some();
    let h_r = cfg.mission.reference_altitude();
    scenario
        .simulate(&start, 0, &report_base.depths, &mut scores, |s| {
            if record {
                let bottom = profile.depth_at(s.x).ok();
                rows.push(TrajRow {
                    x: s.x,
                    depth: s.depth,
                    bottom,
                    target: bottom.map(|b| b - h_r),
                    pitch: s.pitch,
                    elevator: s.command.map(|c| c.elevator),
                    reference: s.reference.map(|(_, r)| r),
                });
            }
        })
        .map_err(|e| Fail::input(format!("simulation failed: {e}")))?;

    let h_a = cfg.mission.min_altitude();
    // Fixed depths are certified here: flown open loop in every declared
    // world over the certification bottom (the planner certifies its own).
    let fixed_cert = certify_open_loop(&scenario, &start, &report_base.depths)?;
    let declared = !uncertainty.is_none();
    let report = Report {
        profile: profile_label,
        vehicle: vehicle_label,
        reference_altitude: h_r,
        min_altitude_limit: h_a,
        method: report_base.method,
        mode: report_base.mode,
        uncertainty: cfg.uncertainty,
        tracks: scores
            .iter()
            .zip(&report_base.depths)
            .zip(&report_base.optimizer)
            .zip(&fixed_cert)
            .map(|(((s, &depth), eff), &fixed)| {
                let (certified_min_altitude, safe, status) = match eff.certified {
                    Some(planned) => no_better_than_the_line(planned, fixed, eff.status),
                    None => (fixed.0, fixed.1, eff.status),
                };
                let safe = safe && !eff.after_crash;
                // With nothing declared, the line's nominal flight's least
                // altitude, as spec/cli.md says: after a predicted
                // collision the planner's flight starts from the climb's
                // state, and the tool certifies the fixed depths after it
                // over the certification bottom, both a little off the
                // line's flight (`check_certified.py --seed 2567
                // --bounds-kind motion`, `synthetic_008`, track mode:
                // 0.10 m).
                let certified_min_altitude = if declared {
                    certified_min_altitude
                } else {
                    s.min_altitude()
                };
                TrackReport {
                    x_start: s.x_start(),
                    x_end: s.x_end(),
                    depth,
                    j: s.j(),
                    rms: s.rms(),
                    min_altitude: s.min_altitude(),
                    certified_min_altitude,
                    safe,
                    iterations: eff.iterations,
                    evaluations: eff.evaluations,
                    status,
                    optimizer: eff.optimizer,
                    continuation: eff.continuation.clone(),
                    j_history: eff.j_history.clone(),
                }
            })
            .collect(),
    };
    if let Some(path) = &args.trajectory {
        report::write_trajectory(path, &rows)?;
    }
    if let Some(path) = &args.plot {
        plot::draw(
            path,
            &plot::Figure {
                title: format!(
                    "{} — {} / {}, total J {:.3e} m³, min altitude {:.1} m",
                    short_name(&report.profile),
                    report.method,
                    report.mode,
                    report.total_j(),
                    report.min_altitude()
                ),
                profile_x: profile.positions(),
                profile_b: profile.depths(),
                waypoints: waypoints.positions(),
                reference_altitude: h_r,
                min_altitude: h_a,
                rows: &rows,
                report: &report,
                map: cut.as_ref().map(|c| {
                    let ll = |p: &map::line::LatLon| (p.lon, p.lat);
                    (
                        c.at.iter().map(ll).collect(),
                        c.waypoints.iter().map(|w| ll(&w.1)).collect(),
                    )
                }),
            },
        )?;
    }
    if let (Some(path), Some(c)) = (&args.geojson, &cut) {
        let bottom = |x: f32| profile.depth_at(x).ok();
        map::geojson::write(path, &map::geojson::plan(&report, c, &wx, &rows, &bottom))?;
    }
    if args.json {
        println!("{}", report.json());
    } else {
        print!("{}", report.table());
    }
    Ok(())
}

/// A profile's name for a title: the file stems, not the whole paths
/// (`monterey_1 on monterey_gebco`, `us_monterey_canyon_1 (bundled)`).
fn short_name(label: &str) -> String {
    label
        .split(" on ")
        .map(|p| {
            std::path::Path::new(p)
                .file_stem()
                .map_or_else(|| p.to_string(), |s| s.to_string_lossy().into_owned())
        })
        .collect::<Vec<_>>()
        .join(" on ")
}

/// Inputs that are valid numbers but cannot describe a real flight
/// (spec/cli.md, Errors). Errors, since no plan could mean anything:
/// - `reference_altitude` larger than the water depth at waypoint 0 (the
///   default start depth `b(X_0) - h_r` is above the surface, and the
///   target depth there is too);
/// - `initial_depth` above the surface (< 0) or at or below the bottom at
///   waypoint 0.
///
/// Warnings (the plan is still made, and reported unsafe where it is):
/// - an `initial_depth` that starts below `h_a` above the bottom;
/// - water shallower than `min_altitude` somewhere on the line (no depth
///   is safe there; a line that touches land lands here too);
///
/// Elevation-like (mostly negative) profiles and a `depth_limits` that is
/// not a pair are rejected when the inputs are parsed (`input.rs`), and
/// `--depths` outside `depth_limits` in `run`.
fn sanity(
    cfg: &input::Config,
    cfg_name: &str,
    profile: &Profile<SAMPLES>,
    profile_name: &str,
    wx: &[f32],
) -> Result<Vec<String>, Fail> {
    let cfg_where = if cfg_name.is_empty() {
        "the default".to_string()
    } else {
        format!("{cfg_name}:")
    };
    let h_r = cfg.mission.reference_altitude();
    let h_a = cfg.mission.min_altitude();
    let (x0, xm) = (wx[0], wx[wx.len() - 1]);
    let b0 = profile
        .depth_at(x0)
        .map_err(|e| Fail::input(format!("{profile_name}: waypoint 0 (x = {x0} m): {e}")))?;
    let mut warnings = Vec::new();
    if h_r > b0 {
        return Err(Fail::input(format!(
            "{cfg_where} reference_altitude = {h_r} m is larger than the water depth {b0} m at \
             waypoint 0 (x = {x0} m) of {profile_name}: the start depth b(X0) - h_r = {} m would \
             be above the surface; set a smaller reference_altitude (and min_altitude)",
            b0 - h_r
        )));
    }
    if let Some(d) = cfg.initial_depth {
        if d < 0.0 {
            return Err(Fail::input(format!(
                "{cfg_where} initial_depth = {d} m is above the surface (depths are positive down)"
            )));
        }
        if d >= b0 {
            return Err(Fail::input(format!(
                "{cfg_where} initial_depth = {d} m is at or below the bottom ({b0} m) at waypoint 0 \
                 (x = {x0} m) of {profile_name}"
            )));
        }
        if b0 - d < h_a {
            warnings.push(format!(
                "{cfg_where} initial_depth = {d} m starts {} m above the bottom at waypoint 0, \
                 below min_altitude = {h_a} m",
                b0 - d
            ));
        }
    }
    // The bottom over the line: the samples inside [X_0, X_M] and the ends.
    let ends = [(x0, b0), (xm, profile.depth_at(xm).unwrap_or(b0))];
    let shallow: Vec<(f32, f32)> = profile
        .positions()
        .iter()
        .zip(profile.depths())
        .map(|(&x, &b)| (x, b))
        .filter(|&(x, _)| x > x0 && x < xm)
        .chain(ends)
        .filter(|&(_, b)| b < h_a)
        .collect();
    if let Some(&(xl, bl)) = shallow.iter().min_by(|a, b| a.1.total_cmp(&b.1)) {
        let from = shallow.iter().map(|p| p.0).fold(f32::INFINITY, f32::min);
        let to = shallow
            .iter()
            .map(|p| p.0)
            .fold(f32::NEG_INFINITY, f32::max);
        let span = if from < to {
            format!("between x = {from} and {to} m")
        } else {
            format!("at x = {from} m")
        };
        warnings.push(format!(
            "{profile_name}: the water is shallower than min_altitude = {h_a} m {span} (least \
             depth {bl} m at x = {xl} m): no depth is safe there"
        ));
    }
    Ok(warnings)
}

/// A planned track's certificate as reported: the planner's (`planned`:
/// least altitude, m, and safe), no better than the line's open-loop one
/// from the start (`line`), with the track's `status`. The two agree while
/// the planner's worlds are carried from the start (through a climb too:
/// `Planner::carry`); a planner whose worlds started again from a later
/// state would not carry the spread the declared worlds had built up by
/// then, and spec/cli.md's promise is for the line flown open loop from
/// the start state. (With nothing declared the report gives the line's
/// nominal `min_altitude` instead, and only `safe` comes from here: a
/// knife edge's other switch.) A track the line does not certify is not
/// safe: `infeasible`.
fn no_better_than_the_line(
    (planned, planned_safe): (f32, bool),
    (line, line_safe): (f32, bool),
    status: &'static str,
) -> (f32, bool, &'static str) {
    let certified = planned.min(line);
    let safe = planned_safe && line_safe;
    let status = if planned_safe && !safe {
        "infeasible"
    } else {
        status
    };
    (certified, safe, status)
}

/// Each track's least altitude over the declared worlds and whether it is
/// at least `h_a`, for `depths` flown open loop from `start` (model
/// contract §12: the corner worlds over the certification bottom).
fn certify_open_loop(
    sc: &Scenario<'_, { input::ORDER }>,
    start: &auvnav::VehicleState<{ input::ORDER }>,
    depths: &[f32],
) -> Result<Vec<(f32, bool)>, Fail> {
    let h_a = sc.mission().min_altitude();
    let bottom = sc.certification_bottom().unwrap_or(sc.profile());
    let mut least = vec![0.0; depths.len()];
    auvnav::plan::certify_line(sc, bottom, start, (0, depths), &mut least)
        .map_err(|e| Fail::input(format!("certification: {e}")))?;
    Ok(least.into_iter().map(|m| (m, m >= h_a)).collect())
}

/// Plans the whole line track by track, each from the state in which the
/// vehicle reaches its first waypoint.
fn plan_line(
    args: &Args,
    cfg: &input::Config,
    scenario: &Scenario<'_, { input::ORDER }>,
    initial_depth: f32,
) -> Result<Plan, Fail> {
    let pc = PlannerConfig {
        method: match args.method {
            args::Method::Bfgs => Method::Bfgs,
            args::Method::Gd => Method::GradientDescent,
        },
        mode: match args.mode {
            args::Mode::Horizon => Mode::Horizon,
            args::Mode::Track => Mode::TrackWise,
        },
        horizon: args.horizon.unwrap_or(usize::MAX),
        constrained: !args.unconstrained,
        ..cfg.optimizer.apply(PlannerConfig::default())
    };
    let mut planner = Planner::<MAX_HORIZON, { input::ORDER }>::new(pc)
        .map_err(|e| Fail::input(format!("config: {e}")))?;
    let mut state = scenario.start_state(initial_depth);
    let tracks = scenario.waypoints().tracks();
    let mut depths = Vec::with_capacity(tracks);
    let mut optimizer = Vec::with_capacity(tracks);
    let progress = progress::Progress::new("plan");
    for n in 0..tracks {
        progress.step("planning track", n + 1, tracks);
        let p = match planner.plan(scenario, &state, n) {
            Ok(p) => p,
            // An infeasible line may fly into the rock before the end: a
            // track that starts below the bottom has no start to plan
            // from. It is flown at the shallowest allowed depth (the
            // climb) and reported infeasible, and planning goes on from
            // where the climb leaves the vehicle (above the bottom again,
            // or the next track climbs too).
            Err(PlanError::StartBelowBottom) if n > 0 => {
                let shallow = scenario.mission().depth_limits()[0];
                depths.push(shallow);
                optimizer.push(Effort {
                    status: "infeasible",
                    after_crash: true,
                    ..Effort::fixed()
                });
                // (The planner's worlds fly the climb too: the next
                // track's certificates keep their spread from the start.)
                match planner.carry(scenario, &state, n, shallow) {
                    Ok(next) => {
                        state = next;
                        continue;
                    }
                    Err(_) => {
                        for _ in n + 1..tracks {
                            depths.push(shallow);
                            optimizer.push(Effort {
                                status: "infeasible",
                                after_crash: true,
                                ..Effort::fixed()
                            });
                        }
                        break;
                    }
                }
            }
            Err(e) => return Err(Fail::input(format!("planning track {}: {e}", n + 1))),
        };
        depths.push(p.depth);
        optimizer.push(Effort {
            iterations: p.iterations,
            evaluations: p.evaluations,
            status: p.status.as_str(),
            optimizer: p.optimizer.as_str(),
            certified: Some((p.certified_min_altitude, p.safe)),
            continuation: (args.mode == args::Mode::Horizon && !args.unconstrained)
                .then(|| planner.continuation().to_vec()),
            j_history: planner.history().to_vec(),
            after_crash: false,
        });
        state = p.next_state;
    }
    Ok(Plan {
        method: match args.method {
            args::Method::Bfgs => "bfgs",
            args::Method::Gd => "gd",
        },
        mode: match args.mode {
            args::Mode::Horizon => "horizon",
            args::Mode::Track => "track",
        },
        depths,
        optimizer,
    })
}

/// The depths to fly and how they were found.
struct Plan {
    method: &'static str,
    mode: &'static str,
    depths: Vec<f32>,
    optimizer: Vec<Effort>,
}

/// One track's optimizer effort and what the planner certified.
#[derive(Clone)]
struct Effort {
    iterations: u32,
    evaluations: u32,
    status: &'static str,
    optimizer: &'static str,
    /// Certified minimum altitude (m) and safety, as the planner reported
    /// them (`None`: fixed depths, certified by the tool).
    certified: Option<(f32, bool)>,
    continuation: Option<Vec<f32>>,
    j_history: Vec<f32>,
    /// Past a predicted collision: no state to certify from.
    after_crash: bool,
}

impl Effort {
    fn fixed() -> Self {
        Self {
            iterations: 0,
            evaluations: 0,
            status: "fixed",
            optimizer: "none",
            certified: None,
            continuation: None,
            j_history: Vec::new(),
            after_crash: false,
        }
    }
}
