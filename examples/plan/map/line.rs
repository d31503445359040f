//! Survey lines in latitude/longitude: a CSV with header `wp,lat,lon`
//! (WGS84 degrees; more columns allowed) or a GeoJSON `LineString` (a bare
//! geometry, a Feature, or a FeatureCollection holding exactly one), whose
//! coordinates are `[lon, lat]` (RFC 7946 order).

use std::path::Path;

use serde_json::Value;

use crate::fail::Fail;

/// A waypoint of the line, WGS84 degrees.
#[derive(Clone, Copy, Debug)]
pub struct LatLon {
    pub lat: f64,
    pub lon: f64,
}

/// Reads the line's waypoints, by extension (`.json`/`.geojson`) or by a
/// leading `{`.
pub fn read(path: &Path) -> Result<Vec<LatLon>, Fail> {
    let name = path.display().to_string();
    let text = crate::input::read(path)?;
    let pts = if text.trim_start().starts_with('{') {
        geojson(&text, &name)?
    } else {
        csv(&text, &name)?
    };
    if pts.len() < 2 {
        return Err(Fail::input(format!(
            "{name}: a line needs at least 2 waypoints, found {}",
            pts.len()
        )));
    }
    for (i, w) in pts.windows(2).enumerate() {
        #[allow(clippy::float_cmp)] // the very same point, not a near one
        let same = w[0].lat == w[1].lat && w[0].lon == w[1].lon;
        if same {
            return Err(Fail::input(format!(
                "{name}: waypoints {i} and {} are the same point: a track must have a length",
                i + 1
            )));
        }
    }
    Ok(pts)
}

fn check(name: &str, at: &str, lat: f64, lon: f64) -> Result<LatLon, Fail> {
    if !(-90.0..=90.0).contains(&lat) || !(-180.0..=360.0).contains(&lon) {
        return Err(Fail::input(format!(
            "{name}:{at}: lat {lat}, lon {lon} are not WGS84 degrees (lat in [-90, 90], lon in \
             [-180, 360]); is the line projected, or are lat and lon swapped?"
        )));
    }
    Ok(LatLon { lat, lon })
}

fn csv(text: &str, name: &str) -> Result<Vec<LatLon>, Fail> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (hn, header) = lines
        .next()
        .ok_or_else(|| Fail::input(format!("{name}: empty file")))?;
    let header: Vec<&str> = header
        .trim_start_matches('\u{feff}')
        .split(',')
        .map(str::trim)
        .collect();
    let col =
        |c: &str| {
            header.iter().position(|h| h.eq_ignore_ascii_case(c)).ok_or_else(|| {
            Fail::input(format!(
                "{name}:{}: a line's header must name column '{c}' (expected wp,lat,lon, WGS84 \
                 degrees, or a GeoJSON LineString)",
                hn + 1
            ))
        })
        };
    let (ilat, ilon) = (col("lat")?, col("lon")?);
    let mut out = Vec::new();
    for (n, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != header.len() {
            return Err(Fail::input(format!(
                "{name}:{}: expected {} fields, found {}",
                n + 1,
                header.len(),
                f.len()
            )));
        }
        let num = |i: usize, c: &str| -> Result<f64, Fail> {
            f[i].parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    Fail::input(format!(
                        "{name}:{}: {c} '{}' is not a finite number",
                        n + 1,
                        f[i]
                    ))
                })
        };
        out.push(check(
            name,
            &(n + 1).to_string(),
            num(ilat, "lat")?,
            num(ilon, "lon")?,
        )?);
    }
    Ok(out)
}

fn geojson(text: &str, name: &str) -> Result<Vec<LatLon>, Fail> {
    let v: Value = serde_json::from_str(text)
        .map_err(|e| Fail::input(format!("{name}:{}: not valid JSON: {e}", e.line())))?;
    let bad = |what: &str| Fail::input(format!("{name}: {what}"));
    let geometry = match v.get("type").and_then(Value::as_str) {
        Some("LineString") => &v,
        Some("Feature") => v
            .get("geometry")
            .ok_or_else(|| bad("a Feature without geometry"))?,
        Some("FeatureCollection") => {
            let lines: Vec<&Value> = v
                .get("features")
                .and_then(Value::as_array)
                .map(|f| {
                    f.iter()
                        .filter_map(|f| f.get("geometry"))
                        .filter(|g| g.get("type").and_then(Value::as_str) == Some("LineString"))
                        .collect()
                })
                .unwrap_or_default();
            match lines.as_slice() {
                [one] => *one,
                _ => {
                    return Err(bad(&format!(
                        "a FeatureCollection with {} LineStrings; the line must be exactly one",
                        lines.len()
                    )));
                }
            }
        }
        _ => {
            return Err(bad(
                "GeoJSON must be a LineString, or a Feature or FeatureCollection of one",
            ));
        }
    };
    if geometry.get("type").and_then(Value::as_str) != Some("LineString") {
        return Err(bad("the geometry is not a LineString"));
    }
    let coords = geometry
        .get("coordinates")
        .and_then(Value::as_array)
        .ok_or_else(|| bad("LineString without coordinates"))?;
    coords
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let at = format!(" coordinate {i}");
            match c.as_array().map(Vec::as_slice) {
                Some([lon, lat, ..]) => match (lon.as_f64(), lat.as_f64()) {
                    (Some(lon), Some(lat)) => check(name, &at, lat, lon),
                    _ => Err(bad(&format!("coordinate {i} is not [lon, lat] numbers"))),
                },
                _ => Err(bad(&format!("coordinate {i} is not a [lon, lat] position"))),
            }
        })
        .collect()
}
