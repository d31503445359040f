//! `--geojson OUT.geojson`: the plan for a chart or a mission planner, an
//! RFC 7946 FeatureCollection in WGS84 `[lon, lat]` (QGIS, mission
//! planners read it as is):
//!
//! - one `Point` per waypoint, properties `kind = "waypoint"`, `wp`,
//!   `x_m`, `bottom_depth_m`, and for the track it starts (`null` at the
//!   last waypoint) `track`, `reference_depth_m`, `predicted_min_altitude_m`,
//!   `certified_min_altitude_m`, `safe`, `status`;
//! - one `LineString` of the flown trajectory, `kind = "trajectory"`, its
//!   positions `[lon, lat, -depth]` (RFC 7946's third value is the height,
//!   so a depth is negative), with `depth_m` and `x_m` arrays beside them,
//!   and the plan's `profile`, `vehicle`, `reference_altitude_m`,
//!   `min_altitude_limit_m`, `safe`.

use std::path::Path;

use serde_json::{Value, json};

use super::Cut;
use crate::fail::Fail;
use crate::report::{Report, TrajRow, num};

/// At most this many trajectory positions (the flight is sampled every
/// `U0·Ts`; a few thousand points draw it on any chart).
const MAX_POINTS: usize = 1000;

fn round(v: f64, digits: i32) -> Value {
    let p = 10f64.powi(digits);
    json!((v * p).round() / p)
}

/// The FeatureCollection of the plan over the line `cut`, the waypoints at
/// along-track `wx`, the flight `rows`; `bottom(x)` is the profile's depth.
pub fn plan(
    report: &Report,
    cut: &Cut,
    wx: &[f32],
    rows: &[TrajRow],
    bottom: &dyn Fn(f32) -> Option<f32>,
) -> Value {
    let mut features = Vec::new();
    for (i, &x) in wx.iter().enumerate() {
        let p = cut.position(f64::from(x));
        let t = report.tracks.get(i);
        features.push(json!({
            "type": "Feature",
            "geometry": {"type": "Point", "coordinates": [round(p.lon, 8), round(p.lat, 8)]},
            "properties": {
                "kind": "waypoint",
                "wp": i,
                "x_m": num(x),
                "bottom_depth_m": bottom(x).map_or(Value::Null, |b| round(f64::from(b), 3)),
                "track": t.map(|_| i + 1),
                "reference_depth_m": t.map(|t| num(t.depth)),
                "predicted_min_altitude_m": t.map(|t| num(t.min_altitude)),
                "certified_min_altitude_m": t.map(|t| num(t.certified_min_altitude)),
                "safe": t.map(|t| t.safe),
                "status": t.map(|t| t.status),
            }
        }));
    }
    let (x0, x1) = (wx[0], wx[wx.len() - 1]);
    let flown: Vec<&TrajRow> = rows.iter().filter(|r| r.x >= x0 && r.x <= x1).collect();
    let stride = flown.len().div_ceil(MAX_POINTS).max(1);
    let last = flown.len().saturating_sub(1);
    let pick: Vec<&&TrajRow> = flown
        .iter()
        .enumerate()
        .filter(|(k, _)| k % stride == 0 || *k == last)
        .map(|(_, r)| r)
        .collect();
    let coords: Vec<Value> = pick
        .iter()
        .map(|r| {
            let p = cut.position(f64::from(r.x));
            json!([
                round(p.lon, 8),
                round(p.lat, 8),
                round(-f64::from(r.depth), 2)
            ])
        })
        .collect();
    features.push(json!({
        "type": "Feature",
        "geometry": {"type": "LineString", "coordinates": coords},
        "properties": {
            "kind": "trajectory",
            "x_m": pick.iter().map(|r| round(f64::from(r.x), 2)).collect::<Vec<_>>(),
            "depth_m": pick.iter().map(|r| round(f64::from(r.depth), 2)).collect::<Vec<_>>(),
            "profile": report.profile,
            "vehicle": report.vehicle,
            "reference_altitude_m": num(report.reference_altitude),
            "min_altitude_limit_m": num(report.min_altitude_limit),
            "method": report.method,
            "mode": report.mode,
            "safe": report.safe(),
        }
    }));
    json!({"type": "FeatureCollection", "features": features})
}

/// Writes the plan's GeoJSON to `path`, one feature a line.
pub fn write(path: &Path, v: &Value) -> Result<(), Fail> {
    let features: Vec<String> = v["features"]
        .as_array()
        .map(|f| f.iter().map(Value::to_string).collect())
        .unwrap_or_default();
    let text = format!(
        "{{\"type\": \"FeatureCollection\", \"features\": [\n{}\n]}}\n",
        features.join(",\n")
    );
    std::fs::write(path, text)
        .map_err(|e| Fail::input(format!("{}: cannot write: {e}", path.display())))
}
