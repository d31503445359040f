//! Reading the tool's inputs: profile and waypoint CSVs, the vehicle TOML.

use std::path::Path;

use auvnav::{
    AutopilotConfig, ConfigError, Mission, PidGains, TfKind, TransferFunction, VehicleConfig,
};
use serde::Deserialize;

use crate::fail::Fail;

/// Plant order capacity of the host tool.
pub const ORDER: usize = 8;
/// Profile capacity of the host tool (samples).
pub const SAMPLES: usize = 20_000;
/// Waypoint capacity of the host tool.
pub const WAYPOINTS: usize = 256;
/// Most tracks the host tool optimizes jointly in horizon mode.
pub const MAX_HORIZON: usize = 8;

/// The bundled default line (spec/cli.md): Monterey Canyon 1.
pub const BUNDLED_PROFILE: &str = include_str!("../../data/bathymetry/us_monterey_canyon_1.csv");
pub const BUNDLED_WAYPOINTS: &str =
    include_str!("../../data/bathymetry/us_monterey_canyon_1.waypoints.csv");

/// Reads a whole text file, or fails with its name.
pub fn read(path: &Path) -> Result<String, Fail> {
    std::fs::read_to_string(path)
        .map_err(|e| Fail::input(format!("{}: cannot read: {e}", path.display())))
}

/// Parses a CSV whose header names at least `columns` (in any order, more
/// allowed); returns those columns, row by row, each with its 1-based line
/// number in the file as an editor shows it (blank lines are skipped but
/// counted).
fn csv(text: &str, name: &str, columns: &[&str]) -> Result<Vec<(usize, Vec<f32>)>, Fail> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (header_index, header) = lines
        .next()
        .ok_or_else(|| Fail::input(format!("{name}: empty file")))?;
    let header: Vec<&str> = header
        .trim_start_matches('\u{feff}')
        .split(',')
        .map(str::trim)
        .collect();
    let index: Vec<usize> = columns
        .iter()
        .map(|c| {
            header.iter().position(|h| h == c).ok_or_else(|| {
                Fail::input(format!(
                    "{name}:{}: header must name column '{c}' (expected {})",
                    header_index + 1,
                    columns.join(",")
                ))
            })
        })
        .collect::<Result<_, _>>()?;
    let mut rows = Vec::new();
    for (n, line) in lines {
        let lineno = n + 1;
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != header.len() {
            return Err(Fail::input(format!(
                "{name}:{lineno}: expected {} fields, found {}",
                header.len(),
                fields.len()
            )));
        }
        let mut row = Vec::with_capacity(index.len());
        for (&i, col) in index.iter().zip(columns) {
            let f = fields[i];
            let v: f32 = f.parse().map_err(|_| {
                Fail::input(format!("{name}:{lineno}: {col} '{f}' is not a number"))
            })?;
            if !v.is_finite() {
                return Err(Fail::input(format!(
                    "{name}:{lineno}: {col} '{f}' is not finite"
                )));
            }
            row.push(v);
        }
        rows.push((lineno, row));
    }
    Ok(rows)
}

/// Profile CSV (`x_m,bottom_depth_m`): positions and depths, with `x`
/// strictly increasing (checked here to name the line).
pub fn profile(text: &str, name: &str) -> Result<(Vec<f32>, Vec<f32>), Fail> {
    let rows = csv(text, name, &["x_m", "bottom_depth_m"])?;
    if rows.len() < 2 {
        return Err(Fail::input(format!(
            "{name}: a profile needs at least 2 samples, found {}",
            rows.len()
        )));
    }
    increasing(&rows, name, "x_m")?;
    let x: Vec<f32> = rows.iter().map(|r| r.1[0]).collect();
    let b: Vec<f32> = rows.iter().map(|r| r.1[1]).collect();
    elevations(&b, name)?;
    Ok((x, b))
}

/// Waypoints CSV (`wp,x_m`, more columns ignored): positions.
pub fn waypoints(text: &str, name: &str) -> Result<Vec<f32>, Fail> {
    let rows = csv(text, name, &["x_m"]).map_err(|e| {
        // A survey line in lat/lon only: say how to plan it.
        let header = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
        let cols: Vec<&str> = header.split(',').map(str::trim).collect();
        if cols.contains(&"lat") && cols.contains(&"lon") && !cols.contains(&"x_m") {
            Fail::input(format!(
                "{name}: waypoints in lat,lon without x_m: cut the profile under the line from a \
                 map with --grid GRID --line {name} (or plan profile --grid GRID --line {name})"
            ))
        } else {
            e
        }
    })?;
    if rows.len() < 2 {
        return Err(Fail::input(format!(
            "{name}: need at least 2 waypoints (one track), found {}",
            rows.len()
        )));
    }
    increasing(&rows, name, "x_m")?;
    Ok(rows.iter().map(|r| r.1[0]).collect())
}

/// The positions of the waypoints of a CSV with `lat,lon` columns (for
/// `--geojson` over a `--profile`), or an error saying how to get them.
pub fn waypoint_positions(text: &str, name: &str, wx: &[f32]) -> Result<crate::map::Cut, Fail> {
    let rows = csv(text, name, &["lat", "lon"]).map_err(|_| {
        Fail::usage(format!(
            "--geojson needs the waypoints' lat/lon: {name} has no lat,lon columns; give \
             --grid GRID --line LINE, or waypoints with lat,lon columns"
        ))
    })?;
    let pts: Vec<crate::map::line::LatLon> = rows
        .iter()
        .map(|r| crate::map::line::LatLon {
            lat: f64::from(r.1[0]),
            lon: f64::from(r.1[1]),
        })
        .collect();
    let wx: Vec<f64> = wx.iter().map(|&x| f64::from(x)).collect();
    Ok(crate::map::Cut::from_waypoints(&wx, &pts))
}

/// Checks that the first column strictly increases, naming the file line.
fn increasing(rows: &[(usize, Vec<f32>)], name: &str, col: &str) -> Result<(), Fail> {
    for w in rows.windows(2) {
        let ((_, a), (line, b)) = (&w[0], &w[1]);
        if b[0] <= a[0] {
            return Err(Fail::input(format!(
                "{name}:{line}: {col} {} does not increase after {}",
                b[0], a[0]
            )));
        }
    }
    Ok(())
}

/// A profile whose depths are mostly negative is elevations (positive up,
/// as GEBCO and other grids store them), not depths: an error rather than
/// a plan over a line that lies above the sea. A few negative samples (a
/// line that touches land) are left to the shallow-water warning of
/// `main.rs`.
fn elevations(b: &[f32], name: &str) -> Result<(), Fail> {
    let negative = b.iter().filter(|&&v| v < 0.0).count();
    if negative * 2 > b.len() {
        return Err(Fail::input(format!(
            "{name}: {negative} of {} bottom_depth_m values are negative: these look like \
             elevations (positive up, as GEBCO stores them); bottom_depth_m is depth, positive \
             down: negate the column",
            b.len()
        )));
    }
    Ok(())
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct FileConfig {
    speed: Option<f64>,
    sample_time: Option<f64>,
    pitch_limit: Option<f64>,
    elevator_limit: Option<f64>,
    reference_altitude: Option<f64>,
    min_altitude: Option<f64>,
    initial_depth: Option<f64>,
    // A list of any length, so that a wrong length is an error that names
    // the key (a fixed array would also be fine, but this reads better).
    depth_limits: Option<Vec<f64>>,
    horizontal_uncertainty: Option<f64>,
    nav_drift: Option<f64>,
    vertical_uncertainty: Option<f64>,
    speed_uncertainty: Option<f64>,
    flight_path_offset: Option<f64>,
    vertical_current: Option<f64>,
    depth_pid: Option<FilePid>,
    pitch_pid: Option<FilePid>,
    plant: Option<FilePlant>,
    optimizer: Option<FileOptimizer>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct FilePid {
    kp: Option<f64>,
    ki: Option<f64>,
    kd: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct FilePlant {
    kind: Option<String>,
    num: Option<Vec<f64>>,
    den: Option<Vec<f64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct FileOptimizer {
    max_iterations: Option<u32>,
    gd_rate: Option<f64>,
    scan_points: Option<u32>,
}

/// Optimizer settings from `[optimizer]` (every key optional).
#[derive(Clone, Copy, Debug)]
pub struct OptimizerSettings {
    pub max_iterations: u32,
    pub gd_rate: Option<f32>,
    pub scan_points: Option<u32>,
}

impl OptimizerSettings {
    /// The planner settings with these overrides.
    pub fn apply(&self, mut pc: auvnav::PlannerConfig) -> auvnav::PlannerConfig {
        pc.bfgs.max_iterations = self.max_iterations;
        if let Some(r) = self.gd_rate {
            pc.gd_rate = r;
        }
        if let Some(n) = self.scan_points {
            pc.scan_points = n;
        }
        pc
    }
}

/// The declared uncertainty of model.md section 12 (every bound defaults
/// to 0: the nominal model and map), as the config file gives it; the
/// library's own [`auvnav::Uncertainty`] from [`Uncertainty::declared`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Uncertainty {
    /// `e_h`, m: along-track offset between map and navigated position at `X_0`.
    pub horizontal: f32,
    /// `r`, m per m travelled: growth of that offset from `X_0`.
    pub drift: f32,
    /// `e_v`, m: vertical error of the map.
    pub vertical: f32,
    /// `ε_U`, fraction of `U0`: relative error of the true speed (< 1).
    pub speed: f32,
    /// `α_max`, deg: bound on the angle between pitch and flight path (< `θmax`).
    pub flight_path_offset_deg: f32,
    /// `w_max`, m/s: bound on a constant vertical water velocity.
    pub vertical_current: f32,
}

impl Uncertainty {
    /// The library's declared uncertainty (validated again there).
    pub fn declared(&self) -> Result<auvnav::Uncertainty, ConfigError> {
        auvnav::Uncertainty::new(
            self.horizontal,
            self.drift,
            self.vertical,
            self.speed,
            self.flight_path_offset_deg,
            self.vertical_current,
        )
    }
}

/// Everything the config file sets, resolved against the defaults.
pub struct Config {
    pub vehicle: VehicleConfig,
    pub plant: TransferFunction<ORDER>,
    pub mission: Mission,
    /// `None`: the default `b(X_0) - h_r`.
    pub initial_depth: Option<f32>,
    pub optimizer: OptimizerSettings,
    /// Declared uncertainty (model.md section 12).
    pub uncertainty: Uncertainty,
}

/// A finite f32 from an optional f64 key, or the default.
fn num(v: Option<f64>, default: f32, key: &str, name: &str) -> Result<f32, Fail> {
    match v {
        None => Ok(default),
        Some(v) => {
            let f = v as f32;
            if f.is_finite() {
                Ok(f)
            } else {
                Err(Fail::input(format!("{name}: {key} = {v} is not finite")))
            }
        }
    }
}

fn nums(v: &[f64], key: &str, name: &str) -> Result<Vec<f32>, Fail> {
    v.iter().map(|&x| num(Some(x), 0.0, key, name)).collect()
}

/// Parses and validates the vehicle TOML (`None`: all defaults).
pub fn config(text: Option<(&str, &str)>) -> Result<Config, Fail> {
    let (file, name) = match text {
        None => (FileConfig::default(), ""),
        Some((text, name)) => {
            let parsed: FileConfig = toml::from_str(text).map_err(|e| {
                // 1-based line of the span's start: the newlines before it,
                // plus one (`lines().count()` of the text before it missed
                // the line when the span starts a line, as a key does).
                let line = e.span().map(|s| {
                    text.get(..s.start.min(text.len()))
                        .unwrap_or(text)
                        .matches('\n')
                        .count()
                        + 1
                });
                match line {
                    Some(l) => Fail::input(format!("{name}:{l}: {}", e.message().trim())),
                    None => Fail::input(format!("{name}: {}", e.message().trim())),
                }
            })?;
            (parsed, name)
        }
    };
    let d = VehicleConfig::default();
    let dp = d.autopilot.depth_pid;
    let pp = d.autopilot.pitch_pid;
    let fd = file.depth_pid.unwrap_or_default();
    let fp = file.pitch_pid.unwrap_or_default();
    let vehicle = VehicleConfig {
        speed: num(file.speed, d.speed, "speed", name)?,
        sample_time: num(file.sample_time, d.sample_time, "sample_time", name)?,
        autopilot: AutopilotConfig {
            depth_pid: PidGains {
                kp: num(fd.kp, dp.kp, "depth_pid.kp", name)?,
                ki: num(fd.ki, dp.ki, "depth_pid.ki", name)?,
                kd: num(fd.kd, dp.kd, "depth_pid.kd", name)?,
            },
            pitch_pid: PidGains {
                kp: num(fp.kp, pp.kp, "pitch_pid.kp", name)?,
                ki: num(fp.ki, pp.ki, "pitch_pid.ki", name)?,
                kd: num(fp.kd, pp.kd, "pitch_pid.kd", name)?,
            },
            pitch_limit: num(
                file.pitch_limit,
                d.autopilot.pitch_limit,
                "pitch_limit",
                name,
            )?,
            elevator_limit: num(
                file.elevator_limit,
                d.autopilot.elevator_limit,
                "elevator_limit",
                name,
            )?,
        },
    };
    let uncertainty = uncertainty(
        [
            file.horizontal_uncertainty,
            file.nav_drift,
            file.vertical_uncertainty,
            file.speed_uncertainty,
            file.flight_path_offset,
            file.vertical_current,
        ],
        vehicle.autopilot.pitch_limit,
        name,
    )?;
    let plant = plant(file.plant.unwrap_or_default(), name)?;
    let m = Mission::default();
    let limits = match file.depth_limits.as_deref() {
        None => m.depth_limits(),
        Some(&[lo, hi]) => [
            num(Some(lo), 0.0, "depth_limits", name)?,
            num(Some(hi), 0.0, "depth_limits", name)?,
        ],
        Some(other) => {
            return Err(Fail::input(format!(
                "{}depth_limits must be a pair [min, max] of depths in m, got {} values",
                prefix(name),
                other.len()
            )));
        }
    };
    let mission = Mission::new(
        num(
            file.reference_altitude,
            m.reference_altitude(),
            "reference_altitude",
            name,
        )?,
        num(file.min_altitude, m.min_altitude(), "min_altitude", name)?,
        limits,
    )
    .map_err(|e| Fail::input(format!("{}{e}", prefix(name))))?;
    let initial_depth = match file.initial_depth {
        None => None,
        Some(v) => Some(num(Some(v), 0.0, "initial_depth", name)?),
    };
    let opt = file.optimizer.unwrap_or_default();
    let max_iterations = opt.max_iterations.unwrap_or(200);
    if max_iterations == 0 {
        return Err(Fail::input(format!(
            "{}optimizer.max_iterations must be at least 1",
            prefix(name)
        )));
    }
    Ok(Config {
        uncertainty,
        vehicle,
        plant,
        mission,
        initial_depth,
        optimizer: OptimizerSettings {
            max_iterations,
            gd_rate: match opt.gd_rate {
                None => None,
                Some(v) => Some(num(Some(v), 0.0, "optimizer.gd_rate", name)?),
            },
            scan_points: opt.scan_points,
        },
    })
}

/// The six uncertainty keys: each finite and `>= 0`, `speed_uncertainty
/// < 1` (the vehicle moves forward in every world) and `flight_path_offset
/// < pitch_limit`.
/// `keys` in the order of [`Uncertainty`]'s fields.
fn uncertainty(keys: [Option<f64>; 6], pitch_limit: f32, name: &str) -> Result<Uncertainty, Fail> {
    let [eh, r, ev, eu, alpha, w] = keys;
    let bound = |v: Option<f64>, key: &str| -> Result<f32, Fail> {
        let f = num(v, 0.0, key, name)?;
        if f < 0.0 {
            return Err(Fail::input(format!(
                "{}{key} = {f} must be >= 0 (a bound on a magnitude)",
                prefix(name)
            )));
        }
        Ok(f)
    };
    let u = Uncertainty {
        horizontal: bound(eh, "horizontal_uncertainty")?,
        drift: bound(r, "nav_drift")?,
        vertical: bound(ev, "vertical_uncertainty")?,
        speed: bound(eu, "speed_uncertainty")?,
        flight_path_offset_deg: bound(alpha, "flight_path_offset")?,
        vertical_current: bound(w, "vertical_current")?,
    };
    if u.speed >= 1.0 {
        return Err(Fail::input(format!(
            "{}speed_uncertainty = {} must be below 1 (a fraction of speed)",
            prefix(name),
            u.speed
        )));
    }
    if u.flight_path_offset_deg >= pitch_limit {
        return Err(Fail::input(format!(
            "{}flight_path_offset = {} deg must be below pitch_limit = {pitch_limit} deg",
            prefix(name),
            u.flight_path_offset_deg
        )));
    }
    Ok(u)
}

/// `"NAME: "` or nothing for the built-in defaults.
pub fn prefix(name: &str) -> String {
    if name.is_empty() {
        String::new()
    } else {
        format!("{name}: ")
    }
}

fn plant(p: FilePlant, name: &str) -> Result<TransferFunction<ORDER>, Fail> {
    let kind = match p.kind.as_deref() {
        None | Some("pitch") => TfKind::Pitch,
        Some("rate") => TfKind::Rate,
        Some(other) => {
            return Err(Fail::input(format!(
                "{}plant.kind must be \"pitch\" or \"rate\", got \"{other}\"",
                prefix(name)
            )));
        }
    };
    let den = match &p.den {
        Some(v) => nums(v, "plant.den", name)?,
        None => vec![1.0, 2.681, 0.546, 0.048],
    };
    let num_ = match (&p.num, kind) {
        (Some(v), _) => nums(v, "plant.num", name)?,
        (None, TfKind::Pitch) => vec![-0.173],
        (None, TfKind::Rate) => vec![-0.173, 0.0],
    };
    TransferFunction::new(kind, &num_, &den)
        .map_err(|e| Fail::input(format!("{}plant: {e}", prefix(name))))
}
