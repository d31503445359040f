//! GeoTIFF grids (GEBCO's and NOAA's download format), read with the
//! `tiff` crate and georeferenced here from the GeoTIFF tags:
//! `ModelPixelScale` (33550) and `ModelTiepoint` (33922) place the raster,
//! the `GeoKeyDirectory` (34735) says whether it is geographic
//! (`GTModelTypeGeoKey` 1024) and whether a pixel is an area or a point
//! (`GTRasterTypeGeoKey` 1025), `GDAL_NODATA` (42113) gives the nodata
//! value. Only the strips or tiles that hold the window asked for are
//! decoded (`Decoder::read_chunk`), so a 21600 × 21600 GEBCO tile is not
//! read whole for a line a few kilometres long.

use std::fs::File;
use std::io::BufReader;
use std::ops::Range;
use std::path::Path;

use tiff::decoder::{Decoder, DecodingResult};
use tiff::tags::Tag;

use super::grid::{Georef, Source};
use crate::fail::Fail;

pub struct GeoTiff {
    name: String,
    georef: Georef,
    nodata: Option<f64>,
    decoder: Decoder<BufReader<File>>,
}

impl GeoTiff {
    pub fn open(path: &Path) -> Result<Self, Fail> {
        let name = path.display().to_string();
        let fail = |what: &str, e: &dyn std::fmt::Display| {
            Fail::input(format!("{name}: GeoTIFF: {what}: {e}"))
        };
        let file = File::open(path).map_err(|e| fail("cannot open", &e))?;
        let mut d = Decoder::new(BufReader::new(file)).map_err(|e| fail("cannot decode", &e))?;
        let (w, h) = d.dimensions().map_err(|e| fail("dimensions", &e))?;
        let spp = d
            .find_tag_unsigned::<u16>(Tag::SamplesPerPixel)
            .map_err(|e| fail("SamplesPerPixel", &e))?
            .unwrap_or(1);
        if spp != 1 {
            return Err(Fail::input(format!(
                "{name}: GeoTIFF has {spp} samples per pixel; a grid has one (elevation)"
            )));
        }
        let scale = d
            .get_tag_f64_vec(Tag::ModelPixelScaleTag)
            .map_err(|e| fail("no ModelPixelScale tag (33550), so no georeferencing", &e))?;
        let tie = d
            .get_tag_f64_vec(Tag::ModelTiepointTag)
            .map_err(|e| fail("no ModelTiepoint tag (33922), so no georeferencing", &e))?;
        let keys = d
            .get_tag_u16_vec(Tag::GeoKeyDirectoryTag)
            .unwrap_or_default();
        let geokey = |id: u16| {
            keys.get(4..)
                .unwrap_or(&[])
                .chunks_exact(4)
                .find(|k| k[0] == id && k[1] == 0)
                .map(|k| k[3])
        };
        if geokey(1024) == Some(1) {
            return Err(Fail::input(format!(
                "{name}: a projected GeoTIFF (GTModelTypeGeoKey = 1); the grid must be in WGS84 \
                 latitude/longitude: reproject it (gdalwarp -t_srs EPSG:4326)"
            )));
        }
        // PixelIsArea (1, the default): the tie point is a pixel's corner
        // and its node is half a pixel in; PixelIsPoint (2): its centre.
        let half = if geokey(1025) == Some(2) { 0.0 } else { 0.5 };
        let (Some(&[sx, sy]), Some(&[i, j, _, x, y, _])) = (scale.get(..2), tie.get(..6)) else {
            return Err(Fail::input(format!(
                "{name}: GeoTIFF ModelPixelScale needs 3 values and ModelTiepoint 6"
            )));
        };
        let georef = Georef {
            cols: w as usize,
            rows: h as usize,
            lon0: x + (half - i) * sx,
            lat0: y - (half - j) * sy,
            dlon: sx,
            dlat: -sy,
        };
        georef.validate(&name)?;
        let nodata = match d.get_tag_ascii_string(Tag::GdalNodata) {
            Ok(s) => Some(
                s.trim_matches(char::from(0))
                    .trim()
                    .parse::<f64>()
                    .map_err(|_| {
                        Fail::input(format!("{name}: GDAL_NODATA tag '{s}' is not a number"))
                    })?,
            ),
            Err(_) => None,
        };
        Ok(Self {
            name,
            georef,
            nodata,
            decoder: d,
        })
    }
}

/// A decoded chunk's samples as elevations.
fn values(r: DecodingResult) -> Option<Vec<f64>> {
    Some(match r {
        DecodingResult::U8(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I8(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F64(v) => v,
        _ => return None,
    })
}

impl Source for GeoTiff {
    fn georef(&self) -> &Georef {
        &self.georef
    }

    fn window(&mut self, rows: Range<usize>, cols: Range<usize>) -> Result<Vec<f32>, Fail> {
        let (cw, ch) = self.decoder.chunk_dimensions();
        let (cw, ch) = (cw as usize, ch as usize);
        let across = self.georef.cols.div_ceil(cw);
        let width = cols.len();
        let mut out = vec![f32::NAN; rows.len() * width];
        for cr in rows.start / ch..=(rows.end - 1) / ch {
            for cc in cols.start / cw..=(cols.end - 1) / cw {
                let index = cr * across + cc;
                let chunk = self.decoder.read_chunk(index as u32).map_err(|e| {
                    Fail::input(format!("{}: GeoTIFF chunk {index}: {e}", self.name))
                })?;
                let (dw, _) = self.decoder.chunk_data_dimensions(index as u32);
                let v = values(chunk).ok_or_else(|| {
                    Fail::input(format!("{}: GeoTIFF sample type not supported", self.name))
                })?;
                let dw = dw as usize;
                for (k, &z) in v.iter().enumerate() {
                    let (r, c) = (cr * ch + k / dw, cc * cw + k % dw);
                    if rows.contains(&r) && cols.contains(&c) {
                        // Nodata is an exact value of the file, in its
                        // sample type (a float32 file's "-3.4028235e+38").
                        #[allow(clippy::float_cmp)]
                        let nodata = self
                            .nodata
                            .is_some_and(|nd| z == nd || z as f32 == nd as f32)
                            || !z.is_finite();
                        out[(r - rows.start) * width + (c - cols.start)] =
                            if nodata { f32::NAN } else { z as f32 };
                    }
                }
            }
        }
        Ok(out)
    }
}
