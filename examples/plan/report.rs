//! What the tool prints: the JSON object of spec/cli.md, a table, and the
//! trajectory CSV.

use std::io::Write;
use std::path::Path;

use serde_json::{Value, json};

use crate::fail::Fail;

/// One track's line of the report.
#[derive(Clone, Debug)]
pub struct TrackReport {
    pub x_start: f32,
    pub x_end: f32,
    pub depth: f32,
    pub j: f32,
    pub rms: f32,
    pub min_altitude: f32,
    /// Least altitude over the declared worlds, m.
    pub certified_min_altitude: f32,
    /// Certified safe (model contract §11, §12).
    pub safe: bool,
    pub iterations: u32,
    pub evaluations: u32,
    pub status: &'static str,
    pub optimizer: &'static str,
    /// Horizon mode: the later tracks' depths this track's safety rests on.
    pub continuation: Option<Vec<f32>>,
    pub j_history: Vec<f32>,
}

/// The whole report.
pub struct Report {
    /// The profile: its path as given, or `us_monterey_canyon_1 (bundled)`.
    pub profile: String,
    /// The vehicle: the config's path as given, or `C-AUV #4 (default)`.
    pub vehicle: String,
    /// `h_r`, m.
    pub reference_altitude: f32,
    /// `h_a`, m (the limit; `min_altitude` is the least altitude flown).
    pub min_altitude_limit: f32,
    pub method: &'static str,
    pub mode: &'static str,
    pub tracks: Vec<TrackReport>,
    /// The declared uncertainty (model.md section 12), as the config keys.
    pub uncertainty: crate::input::Uncertainty,
}

impl crate::input::Uncertainty {
    /// The config keys, values and units.
    pub fn keys(&self) -> [(&'static str, f32, &'static str); 6] {
        [
            ("horizontal_uncertainty", self.horizontal, " m"),
            ("nav_drift", self.drift, " m/m"),
            ("vertical_uncertainty", self.vertical, " m"),
            ("speed_uncertainty", self.speed, ""),
            ("flight_path_offset", self.flight_path_offset_deg, " deg"),
            ("vertical_current", self.vertical_current, " m/s"),
        ]
    }

    /// One line for the table's header.
    pub fn describe(&self) -> String {
        if self.keys().iter().all(|k| k.1 == 0.0) {
            return "declared uncertainty: none (certified against the nominal model and map)"
                .into();
        }
        let keys: Vec<String> = self
            .keys()
            .iter()
            .map(|(k, v, u)| format!("{k} {v}{u}"))
            .collect();
        format!("declared uncertainty: {}", keys.join(", "))
    }
}

impl Report {
    pub fn total_j(&self) -> f32 {
        self.tracks.iter().map(|t| t.j).sum()
    }
    pub fn min_altitude(&self) -> f32 {
        self.tracks
            .iter()
            .map(|t| t.min_altitude)
            .fold(f32::INFINITY, f32::min)
    }
    pub fn safe(&self) -> bool {
        self.tracks.iter().all(|t| t.safe)
    }

    /// The JSON object, field for field as spec/cli.md.
    pub fn json(&self) -> Value {
        let tracks: Vec<Value> = self
            .tracks
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let mut v = json!({
                    "track": i + 1,
                    "x_start": num(t.x_start),
                    "x_end": num(t.x_end),
                    "depth": num(t.depth),
                    "J": num(t.j),
                    "rms": num(t.rms),
                    "min_altitude": num(t.min_altitude),
                    "safe": t.safe,
                    "iterations": t.iterations,
                    "evaluations": t.evaluations,
                    "status": t.status,
                    "optimizer": t.optimizer,
                    "certified_min_altitude": num(t.certified_min_altitude),
                    "J_history": t.j_history.iter().map(|&v| num(v)).collect::<Vec<_>>(),
                });
                if let (Some(c), Some(o)) = (&t.continuation, v.as_object_mut()) {
                    o.insert(
                        "continuation".into(),
                        c.iter().map(|&z| num(z)).collect::<Vec<_>>().into(),
                    );
                }
                v
            })
            .collect();
        json!({
            "method": self.method,
            "mode": self.mode,
            "tracks": tracks,
            "total_J": num(self.total_j()),
            "min_altitude": num(self.min_altitude()),
            "safe": self.safe(),
            "profile": self.profile,
            "reference_altitude": num(self.reference_altitude),
            "min_altitude_limit": num(self.min_altitude_limit),
            "vehicle": self.vehicle,
            "uncertainty": self
                .uncertainty
                .keys()
                .iter()
                .map(|(k, v, _)| ((*k).to_string(), num(*v)))
                .collect::<serde_json::Map<_, _>>(),
        })
    }

    /// The human-readable table.
    pub fn table(&self) -> String {
        let mut s = format!(
            "method {}, mode {}\nprofile {}, vehicle {}, h_r {} m, h_a {} m\n{}\n{:>5} {:>9} {:>9} {:>10} {:>14} {:>8} {:>9} {:>9} {:>5} {:>5} {:>5}  {:<12} {}\n",
            self.method,
            self.mode,
            self.profile,
            self.vehicle,
            self.reference_altitude,
            self.min_altitude_limit,
            self.uncertainty.describe(),
            "track",
            "x_start",
            "x_end",
            "depth m",
            "J m^3",
            "rms m",
            "min alt",
            "certified",
            "safe",
            "iter",
            "eval",
            "status",
            "optimizer"
        );
        for (i, t) in self.tracks.iter().enumerate() {
            s += &format!(
                "{:>5} {:>9.1} {:>9.1} {:>10.2} {:>14.1} {:>8.2} {:>9.2} {:>9.2} {:>5} {:>5} {:>5}  {:<12} {}\n",
                i + 1,
                t.x_start,
                t.x_end,
                t.depth,
                t.j,
                t.rms,
                t.min_altitude,
                t.certified_min_altitude,
                if t.safe { "yes" } else { "NO" },
                t.iterations,
                t.evaluations,
                t.status,
                t.optimizer
            );
        }
        s += &format!(
            "total J {:.1} m^3, min altitude {:.2} m, {}\n",
            self.total_j(),
            self.min_altitude(),
            if self.safe() {
                "safe"
            } else {
                "NOT SAFE: the flight goes below the minimum altitude"
            }
        );
        s
    }
}

/// An f32 as the shortest decimal that reads back as the same f32.
pub fn num(v: f32) -> Value {
    v.to_string()
        .parse::<f64>()
        .ok()
        .and_then(serde_json::Number::from_f64)
        .map_or(Value::Null, Value::Number)
}

/// One trajectory row; `None` prints an empty field (no bottom past the
/// profile, no command at the final sample).
pub struct TrajRow {
    pub x: f32,
    pub depth: f32,
    pub bottom: Option<f32>,
    pub target: Option<f32>,
    pub pitch: f32,
    pub elevator: Option<f32>,
    pub reference: Option<f32>,
}

/// Writes the trajectory CSV.
pub fn write_trajectory(path: &Path, rows: &[TrajRow]) -> Result<(), Fail> {
    let fail = |e: std::io::Error| Fail::input(format!("{}: cannot write: {e}", path.display()));
    let f = std::fs::File::create(path).map_err(fail)?;
    let mut w = std::io::BufWriter::new(f);
    let opt = |v: Option<f32>| v.map(|v| v.to_string()).unwrap_or_default();
    writeln!(
        w,
        "x_m,depth_m,bottom_m,target_m,pitch_deg,elevator_deg,reference_m"
    )
    .map_err(fail)?;
    for r in rows {
        writeln!(
            w,
            "{},{},{},{},{},{},{}",
            r.x,
            r.depth,
            opt(r.bottom),
            opt(r.target),
            r.pitch,
            opt(r.elevator),
            opt(r.reference)
        )
        .map_err(fail)?;
    }
    w.flush().map_err(fail)
}
