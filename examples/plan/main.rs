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
mod input;
mod report;

use std::process::ExitCode;

use auvnav::{Profile, Scenario, TrackScore, Vehicle, Waypoints};

use args::{Args, Mode};
use fail::Fail;
use report::{Report, TrackReport, TrajRow};

/// Profile capacity of the host tool (samples).
const SAMPLES: usize = 20_000;
/// Waypoint capacity of the host tool.
const WAYPOINTS: usize = 256;

fn main() -> ExitCode {
    match run(Args::parse(std::env::args().skip(1))) {
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
    let (profile_text, profile_name, wp_text, wp_name) = match (&args.profile, &args.waypoints) {
        (Some(p), Some(w)) => (
            input::read(p)?,
            p.display().to_string(),
            input::read(w)?,
            w.display().to_string(),
        ),
        _ => (
            input::BUNDLED_PROFILE.to_string(),
            "us_monterey_canyon_1.csv (bundled)".to_string(),
            input::BUNDLED_WAYPOINTS.to_string(),
            "us_monterey_canyon_1.waypoints.csv (bundled)".to_string(),
        ),
    };
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
    let waypoints =
        Waypoints::<WAYPOINTS>::new(&wx).map_err(|e| Fail::input(format!("{wp_name}: {e}")))?;
    let vehicle = Vehicle::new(&cfg.vehicle, cfg.plant)
        .map_err(|e| Fail::input(format!("{}{e}", input::prefix(cfg_name))))?;
    let scenario = Scenario::new(&vehicle, &profile, &waypoints, cfg.mission).map_err(|e| {
        Fail::input(format!(
            "{wp_name}: {e} [{:.1}, {:.1}] m",
            profile.start(),
            profile.end()
        ))
    })?;
    let initial_depth = cfg
        .initial_depth
        .unwrap_or_else(|| scenario.default_initial_depth());

    let tracks = waypoints.tracks();
    let report_base = match &args.depths {
        Some(text) => {
            let depths = args::parse_depths(text, tracks)?;
            Plan {
                method: "fixed",
                mode: "fixed",
                depths,
                optimizer: vec![Effort::fixed(); tracks],
            }
        }
        None => {
            let _ = (args.method, args.mode == Mode::Horizon, args.horizon);
            let _ = (args.unconstrained, cfg.optimizer.max_iterations);
            return Err(Fail::usage(
                "optimization modes are not yet implemented; give --depths z1,...,zM to evaluate a plan"
                    .into(),
            ));
        }
    };
    if args.plot.is_some() {
        return Err(Fail::usage("--plot is not yet implemented".into()));
    }

    // The flight the reported depths produce, scored track by track.
    let start = scenario.start_state(initial_depth);
    let mut scores = vec![TrackScore::default(); tracks];
    let mut rows = Vec::new();
    let record = args.trajectory.is_some();
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
    let report = Report {
        method: report_base.method,
        mode: report_base.mode,
        tracks: scores
            .iter()
            .zip(&report_base.depths)
            .zip(&report_base.optimizer)
            .map(|((s, &depth), eff)| TrackReport {
                x_start: s.x_start(),
                x_end: s.x_end(),
                depth,
                j: s.j(),
                rms: s.rms(),
                min_altitude: s.min_altitude(),
                safe: s.is_safe(h_a),
                iterations: eff.iterations,
                evaluations: eff.evaluations,
                status: eff.status,
                j_history: eff.j_history.clone(),
            })
            .collect(),
    };
    if let Some(path) = &args.trajectory {
        report::write_trajectory(path, &rows)?;
    }
    if args.json {
        println!("{}", report.json());
    } else {
        print!("{}", report.table());
    }
    Ok(())
}

/// The depths to fly and how they were found.
struct Plan {
    method: &'static str,
    mode: &'static str,
    depths: Vec<f32>,
    optimizer: Vec<Effort>,
}

/// One track's optimizer effort.
#[derive(Clone)]
struct Effort {
    iterations: u32,
    evaluations: u32,
    status: &'static str,
    j_history: Vec<f32>,
}

impl Effort {
    fn fixed() -> Self {
        Self {
            iterations: 0,
            evaluations: 0,
            status: "fixed",
            j_history: Vec::new(),
        }
    }
}
