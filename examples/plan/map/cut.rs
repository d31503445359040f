//! Cutting the profile under a line: along-track distance by Karney's
//! geodesics on the WGS84 ellipsoid (`geographiclib-rs`), every waypoint
//! on a sample, samples at most `ds` apart (default a quarter of the grid
//! cell), depth = −(bilinear elevation of the grid).

use geographiclib_rs::{DirectGeodesic, Geodesic, InverseGeodesic};

use super::grid::{Georef, Miss, Source, Window};
use super::line::LatLon;
use crate::fail::Fail;

/// The profile under a line and where each sample is.
#[derive(Clone, Debug)]
pub struct Cut {
    /// Along-track geodesic distance from waypoint 0, m.
    pub x: Vec<f64>,
    /// Bottom depth, m, positive down.
    pub depth: Vec<f64>,
    /// Each sample's position.
    pub at: Vec<LatLon>,
    /// Each waypoint's sample index and position.
    pub waypoints: Vec<(usize, LatLon)>,
}

/// Length (m) of one cell east-west and north-south at `p`.
fn cell_m(g: &Georef, p: LatLon) -> (f64, f64) {
    let geod = Geodesic::wgs84();
    let lat2 = (p.lat + g.dlat.abs()).min(90.0);
    let lat1 = lat2 - g.dlat.abs();
    let ew: f64 = geod.inverse(p.lat, p.lon, p.lat, p.lon + g.dlon);
    let ns: f64 = geod.inverse(lat1, p.lon, lat2, p.lon);
    (ew, ns)
}

/// The default spacing: a quarter of the smaller cell side at waypoint 0.
pub fn default_spacing(g: &Georef, line: &[LatLon]) -> f64 {
    let (ew, ns) = cell_m(g, line[0]);
    ew.min(ns) / 4.0
}

/// Samples the line every at most `ds` m, each waypoint on a sample.
fn sample(line: &[LatLon], ds: f64) -> (Vec<f64>, Vec<LatLon>, Vec<usize>) {
    let geod = Geodesic::wgs84();
    let (mut x, mut at, mut wp) = (vec![0.0], vec![line[0]], vec![0]);
    let mut x0 = 0.0;
    for w in line.windows(2) {
        let (s12, azi1, _, _): (f64, f64, f64, f64) =
            geod.inverse(w[0].lat, w[0].lon, w[1].lat, w[1].lon);
        let n = (s12 / ds).ceil().max(1.0) as usize;
        for k in 1..=n {
            let s = s12 * k as f64 / n as f64;
            let p = if k == n {
                w[1]
            } else {
                let (lat, lon): (f64, f64) = geod.direct(w[0].lat, w[0].lon, azi1, s);
                LatLon { lat, lon }
            };
            x.push(x0 + s);
            at.push(p);
        }
        x0 += s12;
        // The waypoint's own x is the sum of the geodesic lengths.
        if let Some(last) = x.last_mut() {
            *last = x0;
        }
        wp.push(at.len() - 1);
    }
    (x, at, wp)
}

/// Which track (from waypoint `i` to `i + 1`) sample `k` lies on, and
/// whether it is a waypoint itself.
fn where_(wp: &[usize], k: usize) -> String {
    if let Some(i) = wp.iter().position(|&s| s == k) {
        return format!("waypoint {i}");
    }
    let i = wp.iter().rposition(|&s| s < k).unwrap_or(0);
    format!("the track from waypoint {i} to {}", i + 1)
}

/// Cuts the profile under `line` from `src`, `ds` m apart at most.
pub fn cut(src: &mut dyn Source, name: &str, line: &[LatLon], ds: f64) -> Result<Cut, Fail> {
    let g = src.georef().clone();
    let (x, at, wp) = sample(line, ds);
    let frac: Vec<(f64, f64)> = at.iter().map(|p| g.fractional(p.lat, p.lon)).collect();
    let lat_end = g.lat0 + g.dlat * (g.rows as f64 - 1.0);
    let lon_end = g.lon0 + g.dlon * (g.cols as f64 - 1.0);
    let leaves = |k: usize| {
        Fail::input(format!(
            "{name}: {} leaves the grid at x = {:.1} m (lat {:.6}, lon {:.6}); its nodes cover \
             lat {:.6}..{:.6}, lon {:.6}..{:.6}",
            where_(&wp, k),
            x[k],
            at[k].lat,
            at[k].lon,
            g.lat0.min(lat_end),
            g.lat0.max(lat_end),
            g.lon0,
            lon_end
        ))
    };
    let inside = |f: f64, n: usize| f >= -1e-9 && f <= n as f64 - 1.0 + 1e-9;
    if let Some(k) = frac
        .iter()
        .position(|&(r, c)| !inside(r, g.rows) || !inside(c, g.cols))
    {
        return Err(leaves(k));
    }
    // The window of nodes the samples need, and only that.
    let span = |f: &dyn Fn(&(f64, f64)) -> f64, n: usize| {
        let lo = frac.iter().map(f).fold(f64::INFINITY, f64::min);
        let hi = frac.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
        let lo = (lo.max(0.0).floor() as usize).min(n - 2);
        lo..(hi.max(0.0).floor() as usize + 2).min(n)
    };
    let (rows, cols) = (span(&|p| p.0, g.rows), span(&|p| p.1, g.cols));
    let z = src.window(rows.clone(), cols.clone())?;
    let win = Window { rows, cols, z };
    let mut depth = Vec::with_capacity(x.len());
    for (k, &(fr, fc)) in frac.iter().enumerate() {
        let at_k = || {
            format!(
                "{} at x = {:.1} m (lat {:.6}, lon {:.6})",
                where_(&wp, k),
                x[k],
                at[k].lat,
                at[k].lon
            )
        };
        let elev = win.bilinear(&g, fr, fc).map_err(|m| match m {
            Miss::Outside => leaves(k),
            Miss::Nodata => Fail::input(format!("{name}: {} meets nodata in the grid", at_k())),
        })?;
        if elev >= 0.0 {
            return Err(Fail::input(format!(
                "{name}: {} meets land (elevation {elev:+.1} m, the grid is elevation positive up)",
                at_k()
            )));
        }
        depth.push(-elev);
    }
    let waypoints = wp.iter().map(|&k| (k, at[k])).collect();
    Ok(Cut {
        x,
        depth,
        at,
        waypoints,
    })
}

impl Cut {
    /// The profile CSV (`x_m,bottom_depth_m`) of spec/cli.md, Inputs.
    pub fn profile_csv(&self) -> String {
        let mut s = String::from("x_m,bottom_depth_m\n");
        for (x, b) in self.x.iter().zip(&self.depth) {
            s.push_str(&format!("{x:.3},{b:.3}\n"));
        }
        s
    }

    /// The waypoints CSV (`wp,x_m,lat,lon`), each `x_m` a sample's.
    pub fn waypoints_csv(&self) -> String {
        let mut s = String::from("wp,x_m,lat,lon\n");
        for (i, (k, p)) in self.waypoints.iter().enumerate() {
            s.push_str(&format!(
                "{i},{:.3},{:.8},{:.8}\n",
                self.x[*k], p.lat, p.lon
            ));
        }
        s
    }

    /// The positions of a line whose waypoints' along-track `x` (m) come
    /// from a waypoint CSV with `lat,lon` columns: each track sampled
    /// geodesically (200 steps) and its distances scaled to the CSV's, so
    /// that a plan over a profile cut elsewhere can still be charted.
    /// No depths (NaN).
    pub fn from_waypoints(wx: &[f64], line: &[LatLon]) -> Self {
        let (mut x, mut at, mut waypoints) = (Vec::new(), Vec::new(), Vec::new());
        for (i, (w, p)) in wx.windows(2).zip(line.windows(2)).enumerate() {
            let (sx, sat, _) = sample(p, f64::INFINITY);
            let (s12, n) = (sx[sx.len() - 1], 200);
            let geod = Geodesic::wgs84();
            let (_, azi1, _, _): (f64, f64, f64, f64) =
                geod.inverse(p[0].lat, p[0].lon, p[1].lat, p[1].lon);
            if i == 0 {
                x.push(w[0]);
                at.push(sat[0]);
                waypoints.push((0, sat[0]));
            }
            for k in 1..=n {
                let f = k as f64 / n as f64;
                let q = if k == n {
                    p[1]
                } else {
                    let (lat, lon): (f64, f64) = geod.direct(p[0].lat, p[0].lon, azi1, s12 * f);
                    LatLon { lat, lon }
                };
                x.push(w[0] + f * (w[1] - w[0]));
                at.push(q);
            }
            waypoints.push((x.len() - 1, p[1]));
        }
        let depth = vec![f64::NAN; x.len()];
        Self {
            x,
            depth,
            at,
            waypoints,
        }
    }

    /// Position at along-track `x` (m), linear between samples.
    pub fn position(&self, x: f64) -> LatLon {
        let k = self
            .x
            .partition_point(|&s| s <= x)
            .clamp(1, self.x.len() - 1);
        let (x0, x1) = (self.x[k - 1], self.x[k]);
        let t = ((x - x0) / (x1 - x0)).clamp(0.0, 1.0);
        let (a, b) = (self.at[k - 1], self.at[k]);
        LatLon {
            lat: a.lat + t * (b.lat - a.lat),
            lon: a.lon + t * (b.lon - a.lon),
        }
    }
}
