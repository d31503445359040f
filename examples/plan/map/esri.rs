//! Esri ASCII grids (`.asc`, GEBCO's "Esri ASCII" download): a header of
//! `ncols`, `nrows`, `xllcorner`/`xllcenter`, `yllcorner`/`yllcenter`,
//! `cellsize` (or `dx` and `dy`) and an optional `NODATA_value`, then
//! `nrows` rows of `ncols` values, the northern row first. Coordinates are
//! taken as WGS84 degrees (checked to look like them).

use std::ops::Range;
use std::path::Path;

use super::grid::{Georef, Source};
use crate::fail::Fail;

pub struct EsriAscii {
    georef: Georef,
    /// Every value, row-major, north row first; nodata as NaN.
    z: Vec<f32>,
}

/// The header's keys, as read.
#[derive(Default)]
struct Header {
    ncols: Option<usize>,
    nrows: Option<usize>,
    x: Option<(f64, bool)>,
    y: Option<(f64, bool)>,
    dx: Option<f64>,
    dy: Option<f64>,
    nodata: Option<f64>,
}

impl EsriAscii {
    pub fn open(path: &Path) -> Result<Self, Fail> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| {
            Fail::input(format!(
                "{name}: not a grid: neither GeoTIFF, NetCDF nor Esri ASCII text ({e})"
            ))
        })?;
        let mut h = Header::default();
        let mut lines = text.lines().enumerate().peekable();
        // Header lines start with a letter; the data with a number.
        while let Some((n, line)) = lines.next_if(|(_, l)| {
            l.trim().is_empty()
                || l.trim_start()
                    .starts_with(|c: char| c.is_ascii_alphabetic())
        }) {
            let mut it = line.split_whitespace();
            let (Some(key), Some(v), None) = (it.next(), it.next(), it.next()) else {
                if line.trim().is_empty() {
                    continue;
                }
                return Err(header_error(&name, n, line));
            };
            let num: f64 = v.parse().map_err(|_| header_error(&name, n, line))?;
            let whole = || (num >= 1.0 && num.fract() == 0.0).then_some(num as usize);
            match key.to_ascii_lowercase().as_str() {
                "ncols" => h.ncols = Some(whole().ok_or_else(|| header_error(&name, n, line))?),
                "nrows" => h.nrows = Some(whole().ok_or_else(|| header_error(&name, n, line))?),
                "xllcorner" => h.x = Some((num, true)),
                "xllcenter" => h.x = Some((num, false)),
                "yllcorner" => h.y = Some((num, true)),
                "yllcenter" => h.y = Some((num, false)),
                "cellsize" => (h.dx, h.dy) = (Some(num), Some(num)),
                "dx" => h.dx = Some(num),
                "dy" => h.dy = Some(num),
                "nodata_value" => h.nodata = Some(num),
                _ => {
                    return Err(Fail::input(format!(
                        "{name}:{}: unknown Esri ASCII header key '{key}'",
                        n + 1
                    )));
                }
            }
        }
        let missing = |k: &str| Fail::input(format!("{name}: Esri ASCII header lacks {k}"));
        let cols = h.ncols.ok_or_else(|| missing("ncols"))?;
        let rows = h.nrows.ok_or_else(|| missing("nrows"))?;
        let (x, x_corner) = h.x.ok_or_else(|| missing("xllcorner or xllcenter"))?;
        let (y, y_corner) = h.y.ok_or_else(|| missing("yllcorner or yllcenter"))?;
        let dx = h.dx.ok_or_else(|| missing("cellsize"))?;
        let dy = h.dy.ok_or_else(|| missing("cellsize"))?;
        // Node centres: the lower-left corner is half a cell off the centre.
        let lon0 = if x_corner { x + dx / 2.0 } else { x };
        let lat_south = if y_corner { y + dy / 2.0 } else { y };
        let georef = Georef {
            cols,
            rows,
            lon0,
            lat0: lat_south + dy * (rows as f64 - 1.0),
            dlon: dx,
            dlat: -dy,
        };
        georef.validate(&name)?;
        let mut z = Vec::with_capacity(cols * rows);
        for (n, line) in lines {
            for v in line.split_whitespace() {
                let num: f64 = v.parse().map_err(|_| {
                    Fail::input(format!("{name}:{}: value '{v}' is not a number", n + 1))
                })?;
                // Nodata is an exact value of the file.
                #[allow(clippy::float_cmp)]
                let nodata = h.nodata.is_some_and(|nd| num == nd) || !num.is_finite();
                z.push(if nodata { f32::NAN } else { num as f32 });
            }
        }
        if z.len() != cols * rows {
            return Err(Fail::input(format!(
                "{name}: {} values for ncols x nrows = {cols} x {rows} = {}",
                z.len(),
                cols * rows
            )));
        }
        Ok(Self { georef, z })
    }
}

fn header_error(name: &str, n: usize, line: &str) -> Fail {
    Fail::input(format!(
        "{name}:{}: not an Esri ASCII header line ('{}'), nor a GeoTIFF or NetCDF file",
        n + 1,
        line.trim()
    ))
}

impl Source for EsriAscii {
    fn georef(&self) -> &Georef {
        &self.georef
    }
    fn window(&mut self, rows: Range<usize>, cols: Range<usize>) -> Result<Vec<f32>, Fail> {
        let w = self.georef.cols;
        Ok(rows
            .flat_map(|r| self.z[r * w + cols.start..r * w + cols.end].iter().copied())
            .collect())
    }
}
