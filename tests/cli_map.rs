//! `plan profile`, `--grid/--line` and `--geojson` (spec/cli.md, "From a
//! map"): profiles cut from GeoTIFF, Esri ASCII and classic NetCDF grids
//! agree with an independent cut (tools/reference/cut_profile.py, Python
//! geographiclib and its own bilinear over the source grid) to 0.5 m in
//! depth and 0.1 % in distance; the plan's GeoJSON is RFC 7946; a line
//! that leaves the grid or meets nodata or land is an error naming the
//! waypoint.
//!
//! Fixtures: tests/fixtures/grids (tools/reference/make_grids.py) and
//! their goldens tests/fixtures/grids/golden (cut_profile.py). Run `cargo
//! build --example plan` first when filtering (`cargo test --test
//! cli_map`).

// Test code: a failed unwrap or index is a failed test.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![allow(clippy::arithmetic_side_effects, clippy::float_cmp)]

mod tool;

use tool::run;

use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;

fn fixture(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(rel)
        .display()
        .to_string()
}

fn tmp_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("auvnav-cli-map-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn tmp(name: &str) -> String {
    tmp_dir().join(name).display().to_string()
}

fn ok(args: &[&str]) -> Output {
    let o = run(args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// Runs and checks the one-line, exit-2 contract; returns stderr.
fn bad(args: &[&str], must_mention: &[&str]) -> String {
    let o = run(args);
    let err = String::from_utf8(o.stderr).unwrap();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err:?}");
    for m in must_mention {
        assert!(
            err.to_lowercase().contains(&m.to_lowercase()),
            "{args:?}: {err:?} should mention {m:?}"
        );
    }
    err
}

/// The numeric columns of a CSV, by header name.
fn columns(path: &str) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let n = lines.next().unwrap().split(',').count();
    let mut cols = vec![Vec::new(); n];
    for l in lines.filter(|l| !l.trim().is_empty()) {
        for (c, v) in cols.iter_mut().zip(l.split(',')) {
            c.push(v.trim().parse().unwrap());
        }
    }
    cols
}

/// `plan profile` of `grid` along `line`: (profile, waypoints) columns.
fn profile(grid: &str, line: &str, extra: &[&str]) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let tag = format!(
        "{}-{}-{}",
        Path::new(grid).file_name().unwrap().to_string_lossy(),
        Path::new(line).file_name().unwrap().to_string_lossy(),
        extra.join("")
    );
    let (p, w) = (tmp(&format!("{tag}.p.csv")), tmp(&format!("{tag}.w.csv")));
    let mut args = vec![
        "profile",
        "--grid",
        grid,
        "--line",
        line,
        "--out-profile",
        &p,
        "--out-waypoints",
        &w,
    ];
    args.extend(extra);
    ok(&args);
    (columns(&p), columns(&w))
}

/// The tool's cut against the golden cut: same samples, x within 0.1 %
/// of the distance, depth within `tol` m; waypoints on the same x.
fn agrees(grid: &str, line: &str, golden: &str, tol: f64) {
    let (p, w) = profile(&fixture(grid), &fixture(line), &[]);
    let g = columns(&fixture(&format!("grids/golden/{golden}.csv")));
    let gw = columns(&fixture(&format!("grids/golden/{golden}.waypoints.csv")));
    assert_eq!(p[0].len(), g[0].len(), "{grid}: sample count");
    let mut worst = (0.0f64, 0.0f64);
    for k in 0..g[0].len() {
        let (dx, db) = ((p[0][k] - g[0][k]).abs(), (p[1][k] - g[1][k]).abs());
        assert!(
            dx <= 1e-3 * g[0][k].max(1.0),
            "{grid}: x[{k}] {} vs {}",
            p[0][k],
            g[0][k]
        );
        assert!(
            db <= tol,
            "{grid}: depth at x = {} m: {} vs {}",
            g[0][k],
            p[1][k],
            g[1][k]
        );
        worst = (worst.0.max(dx), worst.1.max(db));
    }
    assert_eq!(w[1].len(), gw[1].len());
    for (x, gx) in w[1].iter().zip(&gw[1]) {
        assert!(
            (x - gx).abs() <= 1e-3 * gx.max(1.0),
            "{grid}: waypoint {x} vs {gx}"
        );
        assert!(
            p[0].contains(x),
            "{grid}: waypoint x = {x} m is not a sample"
        );
    }
    eprintln!(
        "{grid} along {line}: worst |dx| {:.4} m, |d depth| {:.4} m",
        worst.0, worst.1
    );
}

#[test]
fn geotiff_agrees_with_the_independent_cut() {
    agrees(
        "grids/monterey_gebco.tif",
        "lines/monterey_1.csv",
        "monterey_1",
        0.5,
    );
    agrees(
        "grids/monterey_gebco.tif",
        "lines/monterey_2.csv",
        "monterey_2",
        0.5,
    );
}

#[test]
fn esri_ascii_agrees_with_the_independent_cut() {
    agrees(
        "grids/monterey_gebco.asc",
        "lines/monterey_1.csv",
        "monterey_1",
        0.5,
    );
    agrees(
        "grids/monterey_gebco.asc",
        "lines/monterey_2.csv",
        "monterey_2",
        0.5,
    );
}

#[test]
fn classic_netcdf_agrees_with_the_independent_cut() {
    agrees(
        "grids/monterey_gebco.nc",
        "lines/monterey_1.csv",
        "monterey_1",
        0.5,
    );
    agrees(
        "grids/monterey_gebco.nc",
        "lines/monterey_2.csv",
        "monterey_2",
        0.5,
    );
}

#[test]
fn geojson_line_is_the_same_line() {
    agrees(
        "grids/monterey_gebco.tif",
        "lines/monterey_1.geojson",
        "monterey_1",
        0.5,
    );
}

/// PixelIsPoint, float32, 16 × 16 tiles, a plane: bilinear is exact, so
/// the cut is the plane at each golden sample's position.
#[test]
fn pixel_is_point_tiled_plane_is_exact() {
    agrees("grids/plane_point.tif", "lines/plane.csv", "plane", 0.01);
    let g = columns(&fixture("grids/golden/plane.csv"));
    for ((b, lat), lon) in g[1].iter().zip(&g[2]).zip(&g[3]) {
        let plane = -(-3000.0 + 20.0 * lon - 30.0 * lat);
        assert!((b - plane).abs() < 0.01, "golden off the plane");
    }
}

/// A 21600 × 21600 GEBCO-style tile with only the tiles under the line
/// stored (the others point past the end of the file): it is read by
/// decoding only the tiles the line needs.
#[test]
fn gebco_tile_is_read_by_window() {
    let path = fixture("grids/plane_gebco_tile.tif");
    let size = std::fs::metadata(&path).unwrap().len();
    assert!(
        size < 21_600 * 21_600 * 2 / 1000,
        "{size} bytes: not sparse"
    );
    agrees(
        "grids/plane_gebco_tile.tif",
        "lines/plane_tile.csv",
        "plane_tile",
        0.5,
    );
    // The tiles that are not stored cannot be decoded: a line over them
    // fails on that chunk, so the line above read none of them.
    let far = tmp_dir().join("far.csv");
    std::fs::write(&far, "wp,lat,lon\n0,10.0,-100.0\n1,10.01,-100.0\n").unwrap();
    let (p, w) = (tmp("far.p.csv"), tmp("far.w.csv"));
    let far = far.display().to_string();
    bad(
        &[
            "profile",
            "--grid",
            &path,
            "--line",
            &far,
            "--out-profile",
            &p,
            "--out-waypoints",
            &w,
        ],
        &["GeoTIFF chunk"],
    );
}

#[test]
fn spacing_is_at_most_a_quarter_cell_or_the_given_one() {
    let (g, l) = (
        fixture("grids/monterey_gebco.tif"),
        fixture("lines/monterey_1.csv"),
    );
    // 15" cells: about 372 m east-west at 36.7 N, 463 m north-south.
    for (extra, most) in [(vec![], 372.5 / 4.0), (vec!["--spacing", "10"], 10.0)] {
        let (p, w) = profile(&g, &l, &extra);
        let steps = p[0].windows(2).map(|s| s[1] - s[0]);
        assert!(
            steps.clone().all(|d| d > 0.0 && d <= most + 1e-3),
            "{extra:?}"
        );
        assert!(
            steps.fold(0.0f64, f64::max) > 0.8 * most,
            "{extra:?}: too dense"
        );
        for x in &w[1] {
            assert!(p[0].contains(x), "waypoint not on a sample");
        }
    }
}

fn refs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

#[test]
fn map_errors_name_the_waypoint() {
    let out = [
        "--out-profile",
        &tmp("e.p.csv"),
        "--out-waypoints",
        &tmp("e.w.csv"),
    ];
    let cut = |grid: &str, line: &str| {
        let mut a = vec!["profile", "--grid", grid, "--line", line];
        a.extend(out);
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let (tif, plane) = (
        fixture("grids/monterey_gebco.tif"),
        fixture("grids/plane_point.tif"),
    );
    let a = cut(&tif, &fixture("lines/monterey_leaves.csv"));
    bad(
        &refs(&a),
        &["track from waypoint 0 to 1", "leaves the grid"],
    );
    let a = cut(&plane, &fixture("lines/plane_nodata.csv"));
    bad(&refs(&a), &["track from waypoint 0 to 1", "nodata"]);
    let a = cut(&plane, &fixture("lines/plane_land.csv"));
    bad(&refs(&a), &["waypoint 1", "land"]);
    // The same through the planner.
    bad(
        &["--grid", &plane, "--line", &fixture("lines/plane_land.csv")],
        &["waypoint 1", "land"],
    );
}

#[test]
fn bad_grids_and_lines() {
    let d = tmp_dir();
    let write = |n: &str, b: &[u8]| {
        let p = d.join(n);
        std::fs::write(&p, b).unwrap();
        p.display().to_string()
    };
    let line = fixture("lines/monterey_1.csv");
    let out = [
        "--out-profile",
        &tmp("b.p.csv"),
        "--out-waypoints",
        &tmp("b.w.csv"),
    ];
    let go = |grid: &str, line: &str, must: &[&str]| {
        let mut a = vec!["profile", "--grid", grid, "--line", line];
        a.extend(out);
        bad(&a, must);
    };
    let nc4 = write("g4.nc", b"\x89HDF\r\n\x1a\n\0\0\0\0\0\0\0\0");
    go(
        &nc4,
        &line,
        &[
            "NetCDF-4",
            "nccopy -k classic",
            "gdal_translate -of netCDF -co FORMAT=NC",
        ],
    );
    let utm = write(
        "utm.asc",
        b"ncols 2\nnrows 2\nxllcorner 517395\nyllcorner 4653795\ncellsize 10\n-1 -2\n-3 -4\n",
    );
    go(&utm, &line, &["WGS84", "latitude/longitude"]);
    let short = write(
        "short.asc",
        b"ncols 3\nnrows 2\nxllcorner -122\nyllcorner 36\ncellsize 0.01\n-1 -2 -3\n-3 -4\n",
    );
    go(&short, &line, &["5 values", "3 x 2"]);
    go(&write("junk.asc", b"hello world\n"), &line, &["junk.asc:1"]);
    let tif = fixture("grids/monterey_gebco.tif");
    go(
        &tif,
        &write("noll.csv", b"wp,x_m\n0,0\n1,100\n"),
        &["noll.csv:1", "'lat'"],
    );
    go(
        &tif,
        &write("swap.csv", b"wp,lat,lon\n0,-122.0,36.7\n1,-122.1,36.7\n"),
        &["swap.csv:2", "swapped"],
    );
    go(
        &tif,
        &write("blank.csv", b"wp,lat,lon\n0,36.71,-122.0\n\n1,36.7,x\n"),
        &["blank.csv:4", "lon 'x'"],
    );
    go(
        &tif,
        &write("poly.geojson", br#"{"type":"Polygon","coordinates":[]}"#),
        &["LineString"],
    );
    go(
        &tif,
        &write("one.csv", b"wp,lat,lon\n0,36.71,-122.0\n"),
        &["at least 2 waypoints"],
    );
    go(
        &tif,
        &write("dup.csv", b"wp,lat,lon\n0,36.71,-122.0\n1,36.71,-122.0\n"),
        &["same point"],
    );
}

#[test]
fn profile_command_line() {
    let (g, l) = (
        fixture("grids/monterey_gebco.tif"),
        fixture("lines/monterey_1.csv"),
    );
    let o = ok(&["profile", "--help"]);
    let help = String::from_utf8(o.stdout).unwrap();
    for item in [
        "--grid",
        "--line",
        "--spacing",
        "--out-profile",
        "--out-waypoints",
        "quarter",
        "nccopy",
    ] {
        assert!(help.contains(item), "plan profile --help lacks {item}");
    }
    bad(
        &["profile", "--grid", &g, "--grid", &g],
        &["--grid given more than once"],
    );
    bad(
        &["profile", "--grid", &g, "--line", &l],
        &["--out-profile is required"],
    );
    bad(
        &["profile", "--bogus", "1"],
        &["unknown argument '--bogus'"],
    );
    bad(&["profile", "--spacing", "-3"], &["--spacing"]);
    // The planner's own checks on the map options.
    bad(&["--grid", &g], &["--grid and --line go together"]);
    let csv = fixture("grids/golden/monterey_1.csv");
    bad(
        &[
            "--grid",
            &g,
            "--line",
            &l,
            "--profile",
            &csv,
            "--waypoints",
            &csv,
        ],
        &["replace --profile/--waypoints"],
    );
    bad(&["--spacing", "10"], &["--spacing", "--grid"]);
    bad(
        &["--grid", &g, "--line", &l, "--line", &l],
        &["--line given more than once"],
    );
    // A lat/lon waypoint file given as --waypoints says to use --line.
    let p = fixture("grids/golden/monterey_1.csv");
    bad(
        &["--profile", &p, "--waypoints", &l],
        &["--grid GRID --line"],
    );
}

/// `plan --grid G --line L` plans exactly what `--profile/--waypoints`
/// plans over `plan profile`'s files, and names the line and the grid.
#[test]
fn grid_line_plans_like_the_profile_it_cuts() {
    let (g, l) = (
        fixture("grids/monterey_gebco.nc"),
        fixture("lines/monterey_1.csv"),
    );
    let (p, w) = (tmp("plan.p.csv"), tmp("plan.w.csv"));
    ok(&[
        "profile",
        "--grid",
        &g,
        "--line",
        &l,
        "--out-profile",
        &p,
        "--out-waypoints",
        &w,
    ]);
    let depths = ["--depths", "990,840,720,200,100", "--json"];
    let mut a = vec!["--grid", g.as_str(), "--line", l.as_str()];
    a.extend(depths);
    let from_grid: Value = serde_json::from_slice(&ok(&a).stdout).unwrap();
    let mut b = vec!["--profile", p.as_str(), "--waypoints", w.as_str()];
    b.extend(depths);
    let from_csv: Value = serde_json::from_slice(&ok(&b).stdout).unwrap();
    assert_eq!(from_grid["tracks"], from_csv["tracks"]);
    assert_eq!(from_grid["total_J"], from_csv["total_J"]);
    let name = from_grid["profile"].as_str().unwrap();
    assert!(
        name.contains("monterey_1.csv") && name.contains("monterey_gebco.nc"),
        "{name}"
    );
}

fn is_position(v: &Value, dims: usize) -> bool {
    v.as_array()
        .is_some_and(|a| a.len() == dims && a.iter().all(Value::is_f64))
}

/// RFC 7946: a FeatureCollection of Features, positions [lon, lat(, h)],
/// the documented properties.
#[test]
fn geojson_plan_is_rfc7946_with_the_documented_properties() {
    let (g, l) = (
        fixture("grids/monterey_gebco.tif"),
        fixture("lines/monterey_1.csv"),
    );
    let out = tmp("plan.geojson");
    let o = ok(&[
        "--grid",
        &g,
        "--line",
        &l,
        "--mode",
        "track",
        "--json",
        "--geojson",
        &out,
    ]);
    let plan: Value = serde_json::from_slice(&o.stdout).unwrap();
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(v["type"], "FeatureCollection");
    let feats = v["features"].as_array().unwrap();
    let line = columns(&l);
    let wps: Vec<&Value> = feats
        .iter()
        .filter(|f| f["properties"]["kind"] == "waypoint")
        .collect();
    assert_eq!(wps.len(), line[0].len());
    for (i, f) in wps.iter().enumerate() {
        assert_eq!(f["type"], "Feature");
        assert_eq!(f["geometry"]["type"], "Point");
        let c = &f["geometry"]["coordinates"];
        assert!(is_position(c, 2), "{c}");
        // [lon, lat]: the line's lon first.
        assert!((c[0].as_f64().unwrap() - line[2][i]).abs() < 1e-6, "{c}");
        assert!((c[1].as_f64().unwrap() - line[1][i]).abs() < 1e-6, "{c}");
        let p = &f["properties"];
        assert_eq!(p["wp"], i);
        assert!(p["bottom_depth_m"].as_f64().unwrap() > 100.0);
        if let Some(t) = plan["tracks"].as_array().unwrap().get(i) {
            assert_eq!(p["track"], i + 1);
            assert_eq!(p["reference_depth_m"], t["depth"]);
            assert_eq!(p["predicted_min_altitude_m"], t["min_altitude"]);
            assert_eq!(p["certified_min_altitude_m"], t["certified_min_altitude"]);
            assert_eq!(p["safe"], t["safe"]);
            assert_eq!(p["status"], t["status"]);
        } else {
            for k in ["track", "reference_depth_m", "status"] {
                assert!(p[k].is_null(), "last waypoint {k}");
            }
        }
    }
    let traj: Vec<&Value> = feats
        .iter()
        .filter(|f| f["properties"]["kind"] == "trajectory")
        .collect();
    assert_eq!(traj.len(), 1);
    let t = traj[0];
    assert_eq!(t["geometry"]["type"], "LineString");
    let coords = t["geometry"]["coordinates"].as_array().unwrap();
    let depth = t["properties"]["depth_m"].as_array().unwrap();
    assert!(coords.len() >= 100 && coords.len() == depth.len());
    for (c, d) in coords.iter().zip(depth) {
        assert!(is_position(c, 3), "{c}");
        assert!((-122.01..-121.97).contains(&c[0].as_f64().unwrap()), "{c}");
        assert!((36.69..36.72).contains(&c[1].as_f64().unwrap()), "{c}");
        assert_eq!(c[2].as_f64().unwrap(), -d.as_f64().unwrap());
    }
    for k in [
        "profile",
        "vehicle",
        "reference_altitude_m",
        "min_altitude_limit_m",
        "safe",
    ] {
        assert!(!t["properties"][k].is_null(), "trajectory lacks {k}");
    }
}

/// `--geojson` over a profile CSV needs the waypoints' lat/lon.
#[test]
fn geojson_needs_positions() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/bathymetry");
    let (p, w) = (
        data.join("us_monterey_canyon_1.csv").display().to_string(),
        data.join("us_monterey_canyon_1.waypoints.csv")
            .display()
            .to_string(),
    );
    let out = tmp("csv.geojson");
    ok(&[
        "--profile",
        &p,
        "--waypoints",
        &w,
        "--depths",
        "990,900,700,400,250",
        "--geojson",
        &out,
    ]);
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(v["features"].as_array().unwrap().len(), 7);
    let nolatlon = tmp_dir().join("w.csv");
    std::fs::write(&nolatlon, "wp,x_m\n0,0\n1,1000\n").unwrap();
    bad(
        &[
            "--profile",
            &p,
            "--waypoints",
            nolatlon.to_str().unwrap(),
            "--depths",
            "500",
            "--geojson",
            &out,
        ],
        &["--geojson needs the waypoints' lat/lon"],
    );
}

/// Longitudes given in 0..360 are the same places on a −180..180 grid.
#[test]
fn longitudes_wrap() {
    let line = columns(&fixture("lines/monterey_1.csv"));
    let mut text = String::from("wp,lat,lon\n");
    for (i, (lat, lon)) in line[1].iter().zip(&line[2]).enumerate() {
        text += &format!("{i},{lat},{}\n", lon + 360.0);
    }
    let east = tmp_dir().join("east.csv");
    std::fs::write(&east, text).unwrap();
    let (p, _) = profile(
        &fixture("grids/monterey_gebco.asc"),
        east.to_str().unwrap(),
        &[],
    );
    let g = columns(&fixture("grids/golden/monterey_1.csv"));
    assert_eq!(p[1].len(), g[1].len());
    for (b, gb) in p[1].iter().zip(&g[1]) {
        assert!((b - gb).abs() <= 0.5, "{b} vs {gb}");
    }
}
