//! From a map (spec/cli.md, "From a map"): bathymetry grids in (GeoTIFF,
//! Esri ASCII, classic NetCDF), survey lines in latitude/longitude, the
//! profile under a line cut geodesically, and the plan out as GeoJSON.
//!
//! - `grid`: the node layout, the bilinear window, format detection;
//! - `geotiff`, `esri`, `netcdf`: one reader per format;
//! - `line`: `wp,lat,lon` CSV and GeoJSON `LineString` lines;
//! - `cut`: geodesic sampling and the profile;
//! - `geojson`: the plan as a FeatureCollection.

mod cut;
mod esri;
pub mod geojson;
mod geotiff;
mod grid;
pub mod line;
mod netcdf;

use std::ffi::OsString;
use std::path::{Path, PathBuf};

pub use cut::Cut;

use crate::fail::Fail;

/// The profile and waypoint CSV texts of a line over a grid (exactly the
/// files `plan profile` writes, so the `--profile/--waypoints` path reads
/// them), and the cut itself (positions of every sample). `spacing`: the
/// largest sample spacing, m (default a quarter of the grid cell).
pub fn profile_and_waypoints(
    grid: &Path,
    line: &Path,
    spacing: Option<f64>,
) -> Result<(String, String, Cut), Fail> {
    let pts = line::read(line)?;
    let mut src = grid::open(grid)?;
    let ds = match spacing {
        Some(ds) => ds,
        None => cut::default_spacing(src.georef(), &pts),
    };
    let c = cut::cut(src.as_mut(), &grid.display().to_string(), &pts, ds)?;
    let limit = crate::input::SAMPLES;
    if c.x.len() > limit {
        return Err(Fail::input(format!(
            "{}: {} samples at {ds:.2} m spacing exceed the tool's {limit}: give a larger --spacing",
            line.display(),
            c.x.len()
        )));
    }
    Ok((c.profile_csv(), c.waypoints_csv(), c))
}

/// Parses `--spacing DS` (m, finite, > 0).
pub fn parse_spacing(v: &str) -> Result<f64, Fail> {
    v.trim()
        .parse::<f64>()
        .ok()
        .filter(|d| d.is_finite() && *d > 0.0)
        .ok_or_else(|| {
            Fail::usage(format!(
                "--spacing must be a positive distance in m, got '{v}'"
            ))
        })
}

/// `plan profile --help`.
pub const USAGE: &str = "\
usage: plan profile --grid GRID --line LINE [--spacing DS]
                    --out-profile P.csv --out-waypoints W.csv

Cuts the bottom profile under a survey line from a bathymetry grid.
  --grid GRID            GeoTIFF (.tif: geographic WGS84, elevation positive up,
                         GDAL_NODATA honoured, PixelIsArea or PixelIsPoint; only the
                         strips/tiles under the line are decoded), Esri ASCII (.asc)
                         or classic NetCDF (.nc; a NetCDF-4 file must be converted:
                         nccopy -k classic in.nc out.nc). Depth = -elevation.
  --line LINE            CSV with header wp,lat,lon (WGS84 degrees) or a GeoJSON
                         LineString ([lon, lat] coordinates)
  --spacing DS           largest sample spacing, m (default: a quarter of the grid
                         cell at waypoint 0)
  --out-profile P.csv    x_m,bottom_depth_m: geodesic distance along the line (WGS84,
                         Karney) and the bilinear depth, m, positive down
  --out-waypoints W.csv  wp,x_m,lat,lon: every waypoint on a sample
  -h, --help             print this help

A line that leaves the grid, or meets nodata or land, is an error naming the
waypoint or track. Exit status 0 on success, 2 for bad input.";

/// `plan profile ...` (the arguments after `profile`).
pub fn profile_command(args: impl Iterator<Item = OsString>) -> Result<(), Fail> {
    let mut opts: [(&str, Option<String>); 5] = [
        ("--grid", None),
        ("--line", None),
        ("--spacing", None),
        ("--out-profile", None),
        ("--out-waypoints", None),
    ];
    let mut it = args.map(|a| a.to_string_lossy().into_owned());
    while let Some(arg) = it.next() {
        if arg == "-h" || arg == "--help" {
            println!("{USAGE}");
            return Ok(());
        }
        let (flag, inline) = match arg.split_once('=') {
            Some((f, v)) if f.starts_with("--") => (f.to_string(), Some(v.to_string())),
            _ => (arg.clone(), None),
        };
        let slot = opts
            .iter_mut()
            .find(|(f, _)| *f == flag)
            .ok_or_else(|| Fail::usage(format!("plan profile: unknown argument '{arg}'")))?;
        if slot.1.is_some() {
            return Err(Fail::usage(format!(
                "plan profile: {flag} given more than once"
            )));
        }
        let v = inline
            .or_else(|| it.next())
            .ok_or_else(|| Fail::usage(format!("plan profile: {flag} needs a value")))?;
        slot.1 = Some(v);
    }
    let [grid, line, spacing, out_p, out_w] = opts.map(|(f, v)| (f, v));
    let need = |(f, v): (&str, Option<String>)| {
        v.ok_or_else(|| {
            Fail::usage(format!(
                "plan profile: {f} is required (see plan profile --help)"
            ))
        })
    };
    let spacing = spacing.1.as_deref().map(parse_spacing).transpose()?;
    let (grid, line) = (PathBuf::from(need(grid)?), PathBuf::from(need(line)?));
    let (out_p, out_w) = (PathBuf::from(need(out_p)?), PathBuf::from(need(out_w)?));
    let (p, w, c) = profile_and_waypoints(&grid, &line, spacing)?;
    for (path, text) in [(&out_p, p), (&out_w, w)] {
        std::fs::write(path, text)
            .map_err(|e| Fail::input(format!("{}: cannot write: {e}", path.display())))?;
    }
    eprintln!(
        "{}: {} samples, {:.1} m, depth {:.1}..{:.1} m, {} waypoints",
        line.display(),
        c.x.len(),
        c.x.last().copied().unwrap_or(0.0),
        c.depth.iter().copied().fold(f64::INFINITY, f64::min),
        c.depth.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        c.waypoints.len()
    );
    Ok(())
}
