//! Command-line arguments of `plan` (spec/cli.md).

use std::ffi::OsString;
use std::path::PathBuf;

use crate::fail::Fail;
use crate::input::MAX_HORIZON;

/// Optimizer choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Bfgs,
    Gd,
}

/// Planning mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Horizon,
    Track,
}

/// Parsed command line.
#[derive(Debug)]
pub struct Args {
    pub profile: Option<PathBuf>,
    pub waypoints: Option<PathBuf>,
    pub config: Option<PathBuf>,
    /// Raw `--depths` text; parsed once the number of tracks is known.
    pub depths: Option<String>,
    pub method: Method,
    pub mode: Mode,
    pub horizon: Option<usize>,
    pub unconstrained: bool,
    pub json: bool,
    pub trajectory: Option<PathBuf>,
    pub plot: Option<PathBuf>,
    /// `--grid GRID --line LINE`: the profile cut from a map.
    pub grid: Option<PathBuf>,
    pub line: Option<PathBuf>,
    /// `--spacing DS` (m) of the cut, with `--grid`.
    pub spacing: Option<f64>,
    /// `--geojson OUT.geojson`: the plan on the chart.
    pub geojson: Option<PathBuf>,
}

/// `plan --help`: the whole interface of spec/cli.md with every default.
pub const USAGE: &str = "\
usage: plan [--profile PROFILE.csv --waypoints WAYPOINTS.csv | --grid GRID --line LINE
             [--spacing DS]] [--config VEHICLE.toml]
            [--depths z1,...,zM] [--method bfgs|gd] [--mode horizon|track] [--horizon K]
            [--unconstrained] [--json] [--trajectory OUT.csv] [--plot OUT.svg]
            [--geojson OUT.geojson]
       plan profile --grid GRID --line LINE [--spacing DS] --out-profile P.csv
                    --out-waypoints W.csv      (plan profile --help for details)

Plans the reference depth of each track of a survey line over a bottom profile
(or, with --depths, evaluates given depths). With no --profile/--waypoints it
plans the bundled line us_monterey_canyon_1 with the defaults below.

Options (each at most once; --flag VALUE or --flag=VALUE):
  --profile PROFILE.csv      bottom profile, header x_m,bottom_depth_m: along-track
                             distance (m, strictly increasing) and bottom depth
                             (m, positive down). Goes with --waypoints.
  --waypoints WAYPOINTS.csv  header wp,x_m (more columns allowed, ignored); waypoint 0
                             starts the line, M = waypoints - 1 tracks; every
                             waypoint within the profile. Goes with --profile.
  --grid GRID                bathymetry grid, elevation positive up, WGS84 lat/lon:
                             GeoTIFF, Esri ASCII or classic NetCDF. Goes with --line;
                             replaces --profile/--waypoints (the profile is cut as
                             by plan profile)
  --line LINE                survey line: CSV wp,lat,lon (WGS84 degrees) or a GeoJSON
                             LineString. Goes with --grid.
  --spacing DS               largest sample spacing of the cut, m (default: a quarter
                             of the grid cell). Only with --grid.
  --config VEHICLE.toml      vehicle and mission settings (keys below); default:
                             the C-AUV #4 of model.md section 9
  --depths z1,...,zM         evaluate exactly these reference depths (m, one per
                             track, within depth_limits); no optimization, method
                             \"fixed\". Not with --mode, --method, --horizon, --unconstrained.
  --mode horizon|track       horizon (default): optimize the next K tracks jointly and
                             commit the first; track: each track alone, as the paper
  --method bfgs|gd           optimizer: bfgs (default, Armijo backtracking) or gd
                             (gradient descent, constant rate)
  --horizon K                tracks optimized jointly in horizon mode, 1 to 8 (default:
                             all remaining, at most 8). Not with --mode track.
  --unconstrained            optimize J alone, ignoring min_altitude (safety is still
                             evaluated and reported)
  --json                     one JSON object on stdout instead of the table
  --trajectory OUT.csv       write every simulated sample: x_m,depth_m,bottom_m,
                             target_m,pitch_deg,elevator_deg,reference_m
  --plot OUT.svg             draw the flight, the h_r and h_a envelopes, the waypoints
                             and J against iteration
  --geojson OUT.geojson      write the plan as RFC 7946 GeoJSON ([lon, lat]): a Point
                             per waypoint (wp, x_m, bottom_depth_m, track,
                             reference_depth_m, predicted_min_altitude_m,
                             certified_min_altitude_m, safe, status) and the flown
                             trajectory as a LineString [lon, lat, -depth] (depth_m,
                             x_m). Needs lat/lon: --grid/--line, or --waypoints
                             with lat,lon columns.
  -h, --help                 print this help

VEHICLE.toml (every key optional, default shown; an unknown key is an error):
  speed = 1.5                  # U0, m/s, > 0
  sample_time = 0.1            # Ts, s, > 0
  pitch_limit = 25.0           # theta_max, deg
  elevator_limit = 25.0        # delta_max, deg
  reference_altitude = 80.0    # h_r, m; at most the water depth at waypoint 0
  min_altitude = 60.0          # h_a, m, 0 < h_a <= h_r
  initial_depth = ...          # d0 at waypoint 0, m; default b(X0) - h_r;
                               # between the surface (0) and the bottom
  depth_limits = [0.0, 6000.0] # allowed reference depths, m: exactly [min, max]
  # Declared uncertainty (model.md section 12), each finite and >= 0, default 0
  # (0 = nominal model and map). 'safe' is certified in every world of the
  # declared set: the map's lower envelope, the vehicle's corner worlds.
  horizontal_uncertainty = 0.0 # e_h, m: map/navigation offset at waypoint 0
  nav_drift = 0.0              # r, m per m travelled (0.002 = 2 m per km)
  vertical_uncertainty = 0.0   # e_v, m: vertical map error
  speed_uncertainty = 0.0      # eps_U, fraction of speed, < 1
  flight_path_offset = 0.0     # alpha_max, deg, < pitch_limit
  vertical_current = 0.0       # w_max, m/s
  [depth_pid]                  # depth -> pitch: deg/m, deg/(m s), deg s/m
  kp = 1.5
  ki = 0.0
  kd = 2.0
  [pitch_pid]                  # pitch -> elevator: -, 1/s, s
  kp = 2.0
  ki = 0.1
  kd = 3.0
  [plant]                      # coefficients highest power first
  kind = \"pitch\"               # \"pitch\": theta(s)/delta(s); \"rate\": q(s)/delta(s)
  num = [-0.173]               # kind = \"rate\" default: [-0.173, 0.0]
  den = [1.0, 2.681, 0.546, 0.048]
  [optimizer]
  max_iterations = 200         # per track, >= 1
  gd_rate = 1e-4               # gradient-descent learning rate, > 0
  scan_points = 9              # depths of the starting-point scan

Output: a table (with a header naming the profile, the vehicle, h_r and h_a)
or, with --json, one object: method, mode, tracks[] (track, x_start, x_end,
depth, J, rms, min_altitude, safe, iterations, evaluations, status, J_history),
total_J, min_altitude (least flown), safe, profile, reference_altitude,
min_altitude_limit (h_a), vehicle, uncertainty (the six declared keys above).
Progress (one line per track) goes to stderr once a run takes over a second,
when stderr is a terminal or PLAN_PROGRESS=1 (PLAN_PROGRESS=0: never).

Exit status: 0 on success (also for a plan that cannot be made safe: it is
reported safe = false); 2 for bad input, with one line on stderr naming the
problem and where. Warnings (one line each, starting 'warning:') go to stderr
and the tool continues.";

impl Args {
    /// Parses the arguments as the operating system passes them: one that
    /// is not UTF-8 is a usage error (`std::env::args` would panic).
    pub fn parse_os(it: impl Iterator<Item = OsString>) -> Result<Self, Fail> {
        let args = it
            .enumerate()
            .map(|(i, a)| {
                a.into_string().map_err(|a| {
                    Fail::usage(format!(
                        "argument {} ('{}') is not valid UTF-8",
                        i + 1,
                        a.to_string_lossy()
                    ))
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Self::parse(args.into_iter())
    }

    /// Parses `--flag value` and `--flag=value` forms.
    pub fn parse(mut it: impl Iterator<Item = String>) -> Result<Self, Fail> {
        let mut a = Args {
            profile: None,
            waypoints: None,
            config: None,
            depths: None,
            method: Method::Bfgs,
            mode: Mode::Horizon,
            horizon: None,
            unconstrained: false,
            json: false,
            trajectory: None,
            plot: None,
            grid: None,
            line: None,
            spacing: None,
            geojson: None,
        };
        // Every option at most once: a second `--profile` would silently
        // replace the first.
        let mut seen: Vec<String> = Vec::new();
        while let Some(arg) = it.next() {
            let (flag, inline) = match arg.split_once('=') {
                Some((f, v)) if f.starts_with("--") => (f.to_string(), Some(v.to_string())),
                _ => (arg.clone(), None),
            };
            if flag.starts_with('-') && flag != "-h" && flag != "--help" {
                if seen.contains(&flag) {
                    return Err(Fail::usage(format!("{flag} given more than once")));
                }
                seen.push(flag.clone());
            }
            let mut value = |name: &str| -> Result<String, Fail> {
                match inline.clone().or_else(|| it.next()) {
                    Some(v) => Ok(v),
                    None => Err(Fail::usage(format!("{name} needs a value"))),
                }
            };
            match flag.as_str() {
                "--profile" => a.profile = Some(value("--profile")?.into()),
                "--waypoints" => a.waypoints = Some(value("--waypoints")?.into()),
                "--config" => a.config = Some(value("--config")?.into()),
                "--depths" => a.depths = Some(value("--depths")?),
                "--trajectory" => a.trajectory = Some(value("--trajectory")?.into()),
                "--plot" => a.plot = Some(value("--plot")?.into()),
                "--grid" => a.grid = Some(value("--grid")?.into()),
                "--line" => a.line = Some(value("--line")?.into()),
                "--geojson" => a.geojson = Some(value("--geojson")?.into()),
                "--spacing" => a.spacing = Some(crate::map::parse_spacing(&value("--spacing")?)?),
                "--method" => {
                    a.method = match value("--method")?.as_str() {
                        "bfgs" => Method::Bfgs,
                        "gd" => Method::Gd,
                        other => {
                            return Err(Fail::usage(format!(
                                "--method must be bfgs or gd, got '{other}'"
                            )));
                        }
                    }
                }
                "--mode" => {
                    a.mode = match value("--mode")?.as_str() {
                        "horizon" => Mode::Horizon,
                        "track" => Mode::Track,
                        other => {
                            return Err(Fail::usage(format!(
                                "--mode must be horizon or track, got '{other}'"
                            )));
                        }
                    }
                }
                "--horizon" => {
                    let v = value("--horizon")?;
                    match v.trim().parse::<usize>() {
                        Ok(k) if (1..=MAX_HORIZON).contains(&k) => a.horizon = Some(k),
                        _ => {
                            return Err(Fail::usage(format!(
                                "--horizon must be a whole number of tracks from 1 to {}, got '{v}'",
                                MAX_HORIZON
                            )));
                        }
                    }
                }
                "--unconstrained" | "--json" if inline.is_some() => {
                    return Err(Fail::usage(format!("{flag} takes no value")));
                }
                "--unconstrained" => a.unconstrained = true,
                "--json" => a.json = true,
                "-h" | "--help" => return Err(Fail::Help),
                other => return Err(Fail::usage(format!("unknown argument '{other}'"))),
            }
        }
        let given = |f: &str| seen.iter().any(|s| s == f);
        if a.depths.is_some() {
            // `--depths` evaluates fixed depths: no optimizer runs, so these
            // options would be silently ignored.
            for f in ["--mode", "--method", "--horizon", "--unconstrained"] {
                if given(f) {
                    return Err(Fail::usage(format!(
                        "--depths evaluates the given depths without optimizing: it cannot be combined with {f}"
                    )));
                }
            }
        }
        if a.mode == Mode::Track && a.horizon.is_some() {
            return Err(Fail::usage(
                "--horizon applies to --mode horizon only, not to --mode track".into(),
            ));
        }
        a.check_map()?;
        if a.profile.is_some() != a.waypoints.is_some() {
            return Err(Fail::usage(
                "--profile and --waypoints go together (give both, or neither for the bundled line)"
                    .into(),
            ));
        }
        Ok(a)
    }
}

impl Args {
    /// `--grid` with `--line`, instead of `--profile`/`--waypoints`;
    /// `--spacing` only with `--grid`.
    fn check_map(&self) -> Result<(), Fail> {
        if self.grid.is_some() != self.line.is_some() {
            return Err(Fail::usage(
                "--grid and --line go together (the line is cut from the grid)".into(),
            ));
        }
        if self.grid.is_some() && (self.profile.is_some() || self.waypoints.is_some()) {
            return Err(Fail::usage(
                "--grid/--line replace --profile/--waypoints: give one pair, not both".into(),
            ));
        }
        if self.spacing.is_some() && self.grid.is_none() {
            return Err(Fail::usage(
                "--spacing sets the cut of --grid/--line; it does not apply to --profile".into(),
            ));
        }
        Ok(())
    }
}

/// Parses `--depths` for `tracks` tracks.
pub fn parse_depths(text: &str, tracks: usize) -> Result<Vec<f32>, Fail> {
    let mut out = Vec::new();
    for (i, item) in text.split(',').enumerate() {
        let item = item.trim();
        let v: f32 = item.parse().map_err(|_| {
            Fail::input(format!(
                "--depths: value {} ('{item}') is not a number",
                i + 1
            ))
        })?;
        if !v.is_finite() {
            return Err(Fail::input(format!(
                "--depths: value {} ('{item}') is not finite",
                i + 1
            )));
        }
        out.push(v);
    }
    if out.len() != tracks {
        return Err(Fail::input(format!(
            "--depths: got {} depths for {tracks} tracks (one per track)",
            out.len()
        )));
    }
    Ok(out)
}
