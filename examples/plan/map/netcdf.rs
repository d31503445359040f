//! Classic NetCDF grids (CDF-1, CDF-2, CDF-5; GEBCO's NetCDF download once
//! converted, GMT grids, `gdal_translate -of netCDF -co FORMAT=NC`), read
//! with the `netcdf3` crate. The grid is the first 2-D variable over a
//! latitude and a longitude dimension (`lat`/`latitude`/`y`,
//! `lon`/`longitude`/`x`) with 1-D coordinate variables of the same names;
//! `scale_factor`, `add_offset`, `_FillValue` and `missing_value` are
//! honoured, and `positive = "down"` turns depths into elevations.
//!
//! `netcdf3` reads a variable whole (it cannot read a slab of one), so the
//! values are decoded once at open; a NetCDF-4 file is refused before this
//! (see `grid::open`).

use std::ops::Range;
use std::path::Path;

use netcdf3::{DataVector, FileReader, Variable};

use super::grid::{Georef, Source};
use crate::fail::Fail;

pub struct NetCdf {
    georef: Georef,
    z: Vec<f32>,
}

const LAT: [&str; 3] = ["lat", "latitude", "y"];
const LON: [&str; 3] = ["lon", "longitude", "x"];

fn floats(v: DataVector) -> Vec<f64> {
    match v {
        DataVector::I8(v) => v.into_iter().map(f64::from).collect(),
        DataVector::U8(v) => v.into_iter().map(f64::from).collect(),
        DataVector::I16(v) => v.into_iter().map(f64::from).collect(),
        DataVector::I32(v) => v.into_iter().map(f64::from).collect(),
        DataVector::F32(v) => v.into_iter().map(f64::from).collect(),
        DataVector::F64(v) => v,
    }
}

/// A numeric attribute's first value.
fn attr(v: &Variable, key: &str) -> Option<f64> {
    let a = v.get_attr(key)?;
    a.get_f64()
        .and_then(|s| s.first().copied())
        .or_else(|| a.get_f32().and_then(|s| s.first().map(|&x| f64::from(x))))
        .or_else(|| a.get_i32().and_then(|s| s.first().map(|&x| f64::from(x))))
        .or_else(|| a.get_i16().and_then(|s| s.first().map(|&x| f64::from(x))))
}

impl NetCdf {
    pub fn open(path: &Path) -> Result<Self, Fail> {
        let name = path.display().to_string();
        let fail = |e: String| Fail::input(format!("{name}: NetCDF: {e}"));
        let mut f = FileReader::open(path).map_err(|e| fail(format!("cannot read: {e:?}")))?;
        let is = |n: &str, set: &[&str]| set.contains(&n.to_ascii_lowercase().as_str());
        let (var_name, dims, fill, scale, offset, down) = {
            let var = f
                .data_set()
                .get_vars()
                .into_iter()
                .find(|v| {
                    let d = v.dim_names();
                    d.len() == 2 && is(&d[0], &LAT) && is(&d[1], &LON)
                })
                .ok_or_else(|| {
                    fail(
                        "no 2-D variable over (lat, lon) dimensions (named lat/latitude/y and \
                          lon/longitude/x)"
                            .into(),
                    )
                })?;
            let down = var
                .get_attr_as_string("positive")
                .is_some_and(|s| s.trim_matches(char::from(0)).eq_ignore_ascii_case("down"));
            (
                var.name().to_string(),
                var.dim_names(),
                [attr(var, "_FillValue"), attr(var, "missing_value")],
                attr(var, "scale_factor").unwrap_or(1.0),
                attr(var, "add_offset").unwrap_or(0.0),
                down,
            )
        };
        let coord = |f: &mut FileReader, d: &str| -> Result<(f64, f64, usize), Fail> {
            let v = f
                .read_var(d)
                .map_err(|e| fail(format!("no coordinate variable '{d}': {e:?}")))?;
            regular(&floats(v)).ok_or_else(|| {
                fail(format!(
                    "coordinate '{d}' is not evenly spaced (a regular grid is needed)"
                ))
            })
        };
        let (lat0, dlat, rows) = coord(&mut f, &dims[0])?;
        let (lon0, dlon, cols) = coord(&mut f, &dims[1])?;
        let mut z = floats(
            f.read_var(&var_name)
                .map_err(|e| fail(format!("cannot read '{var_name}': {e:?}")))?,
        );
        let mut georef = Georef {
            cols,
            rows,
            lon0,
            lat0,
            dlon,
            dlat,
        };
        let mut flip = false;
        if georef.dlon < 0.0 {
            // East to west columns: read them west to east.
            georef.lon0 += dlon * (cols as f64 - 1.0);
            georef.dlon = -dlon;
            flip = true;
        }
        georef.validate(&name)?;
        for v in &mut z {
            // Fill values are exact values of the file, in its type.
            #[allow(clippy::float_cmp)]
            let nodata = fill
                .iter()
                .flatten()
                .any(|f| *v == *f || *v as f32 == *f as f32)
                || !v.is_finite();
            *v = if nodata {
                f64::NAN
            } else {
                (*v * scale + offset) * if down { -1.0 } else { 1.0 }
            };
        }
        let mut z: Vec<f32> = z.into_iter().map(|v| v as f32).collect();
        if flip {
            z.chunks_mut(cols).for_each(<[f32]>::reverse);
        }
        Ok(Self { georef, z })
    }
}

/// First value, step and count of an evenly spaced coordinate.
fn regular(v: &[f64]) -> Option<(f64, f64, usize)> {
    let (&first, &last) = (v.first()?, v.last()?);
    let n = v.len();
    if n < 2 {
        return None;
    }
    let step = (last - first) / (n as f64 - 1.0);
    let even = v
        .iter()
        .enumerate()
        .all(|(k, &x)| (x - (first + step * k as f64)).abs() <= 1e-6 * step.abs().max(1e-9) * 1e3);
    (even && step != 0.0).then_some((first, step, n))
}

impl Source for NetCdf {
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
