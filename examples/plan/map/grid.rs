//! A regular latitude/longitude grid as the readers give it: where its
//! nodes are, and a window of its values read around a line.
//!
//! Node `(r, c)` (row `r`, column `c`) sits at longitude `lon0 + c·dlon`
//! and latitude `lat0 + r·dlat` (degrees, WGS84); `dlat` is negative for
//! a north-up grid (row 0 north). Values are elevations, m, positive up,
//! NaN where the file says nodata. Depth is −elevation.

use std::ops::Range;

use crate::fail::Fail;

/// Where the grid's nodes are.
#[derive(Clone, Debug)]
pub struct Georef {
    pub cols: usize,
    pub rows: usize,
    /// Longitude of column 0's nodes, deg.
    pub lon0: f64,
    /// Latitude of row 0's nodes, deg.
    pub lat0: f64,
    /// Column step, deg (> 0).
    pub dlon: f64,
    /// Row step, deg (< 0 north-up, > 0 south-up).
    pub dlat: f64,
}

impl Georef {
    /// Checks that the nodes are a geographic (degree) grid.
    pub fn validate(&self, name: &str) -> Result<(), Fail> {
        let lat_end = self.lat0 + self.dlat * (self.rows as f64 - 1.0);
        let lon_end = self.lon0 + self.dlon * (self.cols as f64 - 1.0);
        let finite = [self.lon0, self.lat0, self.dlon, self.dlat, lat_end, lon_end]
            .iter()
            .all(|v| v.is_finite());
        if !finite || self.dlon <= 0.0 || self.dlat == 0.0 || self.cols < 2 || self.rows < 2 {
            return Err(Fail::input(format!(
                "{name}: not a regular grid of at least 2 x 2 nodes with a positive cell size"
            )));
        }
        let lat_ok = |v: f64| (-90.0..=90.0).contains(&v);
        let lon_ok = |v: f64| (-360.0..=360.0).contains(&v);
        if !(lat_ok(self.lat0) && lat_ok(lat_end) && lon_ok(self.lon0) && lon_ok(lon_end)) {
            return Err(Fail::input(format!(
                "{name}: node coordinates (lon {:.6}..{:.6}, lat {:.6}..{:.6}) are not \
                 geographic degrees: the grid must be in WGS84 latitude/longitude \
                 (reproject it, e.g. gdalwarp -t_srs EPSG:4326)",
                self.lon0, lon_end, self.lat0, lat_end
            )));
        }
        Ok(())
    }

    /// Fractional (row, column) of a position, the longitude taken modulo
    /// 360 into the grid's span when that puts it inside.
    pub fn fractional(&self, lat: f64, lon: f64) -> (f64, f64) {
        let span = self.dlon * (self.cols as f64 - 1.0);
        let mut c = (lon - self.lon0) / self.dlon;
        for shift in [360.0, -360.0] {
            let alt = (lon + shift - self.lon0) / self.dlon;
            if !(0.0..=span / self.dlon).contains(&c) && (0.0..=span / self.dlon).contains(&alt) {
                c = alt;
            }
        }
        ((lat - self.lat0) / self.dlat, c)
    }
}

/// What each grid format gives: its georeferencing, then the values of a
/// window of nodes (decoding no more of the file than it must).
pub trait Source {
    fn georef(&self) -> &Georef;
    /// Elevations (m, positive up; NaN = nodata) of the nodes in `rows` ×
    /// `cols`, row-major.
    fn window(&mut self, rows: Range<usize>, cols: Range<usize>) -> Result<Vec<f32>, Fail>;
}

/// A window of nodes read from a grid.
pub struct Window {
    pub rows: Range<usize>,
    pub cols: Range<usize>,
    pub z: Vec<f32>,
}

/// Why a position has no depth.
pub enum Miss {
    Outside,
    Nodata,
}

impl Window {
    /// The node's elevation, if inside the window.
    fn node(&self, r: usize, c: usize) -> Option<f32> {
        if !self.rows.contains(&r) || !self.cols.contains(&c) {
            return None;
        }
        let w = self.cols.len();
        self.z
            .get((r - self.rows.start) * w + (c - self.cols.start))
            .copied()
    }

    /// Bilinear elevation at fractional (row, column) `(fr, fc)` of the
    /// whole grid: the four nodes of the cell holding it (the last cell on
    /// the far edges), all four with data.
    pub fn bilinear(&self, g: &Georef, fr: f64, fc: f64) -> Result<f64, Miss> {
        let inside = |f: f64, n: usize| f >= -1e-9 && f <= (n as f64 - 1.0) + 1e-9;
        if !inside(fr, g.rows) || !inside(fc, g.cols) {
            return Err(Miss::Outside);
        }
        let r = (fr.max(0.0).floor() as usize).min(g.rows - 2);
        let c = (fc.max(0.0).floor() as usize).min(g.cols - 2);
        let (t, u) = (
            (fr - r as f64).clamp(0.0, 1.0),
            (fc - c as f64).clamp(0.0, 1.0),
        );
        let mut z = [0.0f64; 4];
        for (k, (dr, dc)) in [(0, 0), (0, 1), (1, 0), (1, 1)].into_iter().enumerate() {
            let v = self.node(r + dr, c + dc).ok_or(Miss::Outside)?;
            if v.is_nan() {
                return Err(Miss::Nodata);
            }
            z[k] = f64::from(v);
        }
        Ok((1.0 - t) * ((1.0 - u) * z[0] + u * z[1]) + t * ((1.0 - u) * z[2] + u * z[3]))
    }
}

/// Opens a grid by its contents: GeoTIFF (`II*\0`/`MM\0*`, BigTIFF too),
/// classic NetCDF (`CDF\x01`, `\x02`, `\x05`), NetCDF-4/HDF5 (refused with
/// the conversion to use), else an Esri ASCII grid.
pub fn open(path: &std::path::Path) -> Result<Box<dyn Source>, Fail> {
    use std::io::Read;
    let name = path.display().to_string();
    let mut magic = [0u8; 8];
    let n = std::fs::File::open(path)
        .and_then(|mut f| f.read(&mut magic))
        .map_err(|e| Fail::input(format!("{name}: cannot read: {e}")))?;
    let magic = &magic[..n];
    if magic.starts_with(b"II") || magic.starts_with(b"MM") {
        return Ok(Box::new(super::geotiff::GeoTiff::open(path)?));
    }
    if magic.starts_with(b"CDF") {
        return Ok(Box::new(super::netcdf::NetCdf::open(path)?));
    }
    if magic.starts_with(b"\x89HDF") {
        return Err(Fail::input(format!(
            "{name}: a NetCDF-4 (HDF5) file; only classic NetCDF is read: convert it with \
             `nccopy -k classic {name} out.nc` or `gdal_translate -of netCDF -co FORMAT=NC {name} out.nc`"
        )));
    }
    Ok(Box::new(super::esri::EsriAscii::open(path)?))
}
