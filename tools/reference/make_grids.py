#!/usr/bin/env python3
"""Writes the map fixtures of `plan profile` / `plan --grid` (spec/cli.md,
"From a map") under tests/fixtures/grids/ and tests/fixtures/lines/.

    python3 tools/reference/make_grids.py [--data ../shared/data/bathymetry]

Real grid (GEBCO_2021, public domain with attribution, see
tests/fixtures/grids/README.md): a crop of the 15 arc-second Monterey
Canyon subset `grids/monterey_gebco2021_15s.npz` of the shared data around
the lines us_monterey_canyon_1 and _2, written three ways, each as GEBCO
distributes it (elevation positive up, = -depth_m of the npz):

- monterey_gebco.tif  int16, PixelIsArea, tie point at the top-left
  corner, strips of 8 rows, GDAL_NODATA "-32767";
- monterey_gebco.asc  Esri ASCII, xllcorner/yllcorner, NODATA_value;
- monterey_gebco.nc   classic NetCDF (CDF-1), variable `elevation`
  (float32, _FillValue) over `lat` (south to north, as GEBCO's NetCDF)
  and `lon`.

Synthetic grids with known answers (elevation = A + B*lon + C*lat, where
bilinear interpolation in lon/lat is exact):

- plane_point.tif  float32, PixelIsPoint (tie point on a node centre),
  16 x 16 tiles, and one nodata node and one land node for the errors;
- plane_gebco_tile.tif  a whole 21600 x 21600 GEBCO-style 15" tile
  (90 x 90 degrees, int16, Deflate, 256 x 256 tiles) of which only the
  tiles under the test line are stored: every other tile's offset points
  past the end of the file, so a reader that decodes the image whole
  fails, one that decodes only the tiles the line needs succeeds.

Lines: the shared waypoints of us_monterey_canyon_1 (wp,lat,lon CSV and a
GeoJSON LineString, [lon, lat]), a line over the plane, a line leaving the
grid, a line into nodata, one onto land.
"""
import argparse
import json
import os
import struct
import zlib

import numpy as np
from scipy.io import netcdf_file

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
GRIDS = os.path.join(ROOT, "tests", "fixtures", "grids")
LINES = os.path.join(ROOT, "tests", "fixtures", "lines")

# The plane (elevation, m): A + B*lon + C*lat.
PLANE = (-3000.0, 20.0, -30.0)
NODATA = -32767

# TIFF field types.
SHORT, LONG, ASCII, DOUBLE = 3, 4, 2, 12


def plane(lon, lat):
    a, b, c = PLANE
    return a + b * np.asarray(lon) + c * np.asarray(lat)


def write_tiff(path, z, lon_tie, lat_tie, dlon, dlat, *, point=False,
               nodata=None, strip_rows=None, tile=None, deflate=False,
               stored=None):
    """Little-endian classic TIFF with the GeoTIFF tags. `z` row 0 north.
    (lon_tie, lat_tie): the top-left corner (PixelIsArea) or the top-left
    node (PixelIsPoint). `stored(chunk_row, chunk_col)`: False leaves the
    chunk out (its offset past the end of the file); `z` may then be a
    function (r0, r1, c0, c1) -> array instead of an array."""
    if callable(z):
        get, (rows, cols), dtype = z, z.shape, z.dtype
    else:
        rows, cols = z.shape
        dtype = z.dtype
        get = lambda r0, r1, c0, c1: z[r0:r1, c0:c1]  # noqa: E731
    if tile:
        cw = ch = tile
    else:
        cw, ch = cols, strip_rows
    across, down = -(-cols // cw), -(-rows // ch)
    chunks, offsets, counts = [], [], []
    pos = 8
    for cr in range(down):
        for cc in range(across):
            if stored is not None and not stored(cr, cc):
                chunks.append(None)
                continue
            r0, c0 = cr * ch, cc * cw
            r1, c1 = min(r0 + ch, rows), min(c0 + cw, cols)
            block = np.asarray(get(r0, r1, c0, c1), dtype=dtype)
            if tile:  # tiles are padded to the full tile size
                full = np.zeros((ch, cw), dtype=dtype)
                full[: r1 - r0, : c1 - c0] = block
                block = full
            data = block.astype(dtype.newbyteorder("<")).tobytes()
            if deflate:
                data = zlib.compress(data, 9)
            chunks.append(data)
    body = bytearray()
    for data in chunks:
        if data is None:
            offsets.append(0xFFFFFF00)
            counts.append(4096)
        else:
            offsets.append(pos + len(body))
            counts.append(len(data))
            body += data
            if len(body) % 2:
                body += b"\0"
    fmt = {np.dtype(np.int16): (16, 2), np.dtype(np.float32): (32, 3)}[np.dtype(dtype)]
    keys = [1, 1, 0, 3,
            1024, 0, 1, 2,                    # GTModelTypeGeoKey: geographic
            1025, 0, 1, 2 if point else 1,    # GTRasterTypeGeoKey
            2048, 0, 1, 4326]                 # GeographicTypeGeoKey: WGS 84
    tags = [
        (256, LONG, [cols]), (257, LONG, [rows]), (258, SHORT, [fmt[0]]),
        (259, SHORT, [8 if deflate else 1]), (262, SHORT, [1]),
        (277, SHORT, [1]), (284, SHORT, [1]), (339, SHORT, [fmt[1]]),
        (33550, DOUBLE, [dlon, dlat, 0.0]),
        (33922, DOUBLE, [0.0, 0.0, 0.0, lon_tie, lat_tie, 0.0]),
        (34735, SHORT, keys),
    ]
    if tile:
        tags += [(322, SHORT, [cw]), (323, SHORT, [ch]),
                 (324, LONG, offsets), (325, LONG, counts)]
    else:
        tags += [(273, LONG, offsets), (278, LONG, [ch]), (279, LONG, counts)]
    if nodata is not None:
        tags.append((42113, ASCII, (str(nodata) + "\0").encode()))
    tags.sort()
    ifd_at = 8 + len(body)
    extra = bytearray()
    entries = bytearray()
    extra_at = ifd_at + 2 + 12 * len(tags) + 4
    for tag, typ, vals in tags:
        if typ == ASCII:
            raw, n = bytes(vals), len(vals)
        else:
            code = {SHORT: "H", LONG: "I", DOUBLE: "d"}[typ]
            raw, n = struct.pack("<%d%s" % (len(vals), code), *vals), len(vals)
        if len(raw) <= 4:
            entries += struct.pack("<HHI", tag, typ, n) + raw.ljust(4, b"\0")
        else:
            entries += struct.pack("<HHII", tag, typ, n, extra_at + len(extra))
            extra += raw
            if len(extra) % 2:
                extra += b"\0"
    out = b"II*\0" + struct.pack("<I", ifd_at) + bytes(body)
    out += struct.pack("<H", len(tags)) + bytes(entries) + b"\0\0\0\0" + bytes(extra)
    with open(path, "wb") as f:
        f.write(out)


def write_asc(path, elev, lon_w, lat_s, cell, nodata):
    rows, cols = elev.shape
    with open(path, "w") as f:
        f.write(f"ncols {cols}\nnrows {rows}\nxllcorner {float(lon_w)!r}\n"
                f"yllcorner {float(lat_s)!r}\ncellsize {float(cell)!r}\nNODATA_value {nodata}\n")
        for row in elev:
            f.write(" ".join(str(nodata) if np.isnan(v) else "%d" % v for v in row) + "\n")


def write_nc(path, elev, lon_c, lat_c):
    """`elev` row 0 north; written south to north like GEBCO's NetCDF."""
    with netcdf_file(path, "w", version=1) as f:
        f.title = "GEBCO_2021 Grid subset (Monterey Canyon), elevation positive up"
        f.createDimension("lat", elev.shape[0])
        f.createDimension("lon", elev.shape[1])
        lat = f.createVariable("lat", "f8", ("lat",))
        lon = f.createVariable("lon", "f8", ("lon",))
        lat[:], lon[:] = lat_c[::-1], lon_c
        lat.units, lon.units = "degrees_north", "degrees_east"
        z = f.createVariable("elevation", "f4", ("lat", "lon"))
        z._FillValue = np.float32(-99999.0)
        z.units = "m"
        z[:] = np.where(np.isnan(elev), -99999.0, elev)[::-1].astype(np.float32)


def write_line(name, pts, geojson=False):
    with open(os.path.join(LINES, name + ".csv"), "w") as f:
        f.write("wp,lat,lon\n")
        for i, (lat, lon) in enumerate(pts):
            f.write(f"{i},{lat:.6f},{lon:.6f}\n")
    if geojson:
        with open(os.path.join(LINES, name + ".geojson"), "w") as f:
            json.dump({"type": "Feature", "properties": {"name": name},
                       "geometry": {"type": "LineString",
                                    "coordinates": [[lon, lat] for lat, lon in pts]}},
                      f, indent=1)
            f.write("\n")


def monterey(data):
    g = np.load(os.path.join(data, "grids", "monterey_gebco2021_15s.npz"))
    depth = g["depth_m"].astype(np.float64)
    lon0, lat0, d = float(g["lon_first_center"]), float(g["lat_first_center"]), float(g["dlon_deg"])
    lat_c = lat0 - d * np.arange(depth.shape[0])
    lon_c = lon0 + d * np.arange(depth.shape[1])
    pts = []
    for name in ["us_monterey_canyon_1", "us_monterey_canyon_2"]:
        rows = open(os.path.join(data, name + ".waypoints.csv")).read().split()[1:]
        pts.append([(float(r.split(",")[2]), float(r.split(",")[3])) for r in rows])
    allp = np.array(pts[0] + pts[1])
    m = 4  # cells of margin
    r0 = int(np.floor((lat0 - allp[:, 0].max()) / d)) - m
    r1 = int(np.ceil((lat0 - allp[:, 0].min()) / d)) + m + 1
    c0 = int(np.floor((allp[:, 1].min() - lon0) / d)) - m
    c1 = int(np.ceil((allp[:, 1].max() - lon0) / d)) + m + 1
    elev = -depth[r0:r1, c0:c1]
    lat_c, lon_c = lat_c[r0:r1], lon_c[c0:c1]
    west, north = lon_c[0] - d / 2, lat_c[0] + d / 2
    south = lat_c[-1] - d / 2
    tif = np.where(np.isnan(elev), NODATA, elev).astype(np.int16)
    write_tiff(os.path.join(GRIDS, "monterey_gebco.tif"), tif, west, north, d, d,
               nodata=NODATA, strip_rows=8)
    write_asc(os.path.join(GRIDS, "monterey_gebco.asc"), elev, west, south, d, NODATA)
    write_nc(os.path.join(GRIDS, "monterey_gebco.nc"), elev, lon_c, lat_c)
    write_line("monterey_1", pts[0], geojson=True)
    write_line("monterey_2", pts[1])
    # Off the crop's west edge.
    write_line("monterey_leaves", [pts[0][0], (pts[0][0][0], west - 0.01)])
    print(f"monterey: rows {r0}:{r1}, cols {c0}:{c1} of the npz, {elev.shape}")


def synthetic():
    d = 1.0 / 120.0
    rows, cols = 40, 50
    lat_n, lon_w = 36.80, -122.10
    lat_c = lat_n - d * np.arange(rows)
    lon_c = lon_w + d * np.arange(cols)
    z = plane(lon_c[None, :], lat_c[:, None]).astype(np.float32)
    z[30, 40] = np.nan     # nodata node
    z[5, 45] = 12.0        # land node
    zz = np.where(np.isnan(z), -9999, z).astype(np.float32)
    write_tiff(os.path.join(GRIDS, "plane_point.tif"), zz, lon_w, lat_n, d, d,
               point=True, nodata=-9999, tile=16)
    node = lambda r, c: (float(lat_c[r]), float(lon_c[c]))  # noqa: E731
    write_line("plane", [node(3, 3), (36.70, -121.95), node(25, 20), node(10, 30)])
    write_line("plane_nodata", [node(30, 35), node(30, 45)])
    write_line("plane_land", [node(8, 42), node(5, 45), node(2, 48)])

    # The GEBCO-style 15" tile n90 s0 w-180 e-90, sparsely stored.
    d, n, t = 1.0 / 240.0, 21600, 256
    line = [(36.75, -122.05), (36.70, -121.98), (36.72, -121.90)]
    write_line("plane_tile", line)
    lats = np.array([p[0] for p in line])
    lons = np.array([p[1] for p in line])
    rr = (90.0 - d / 2 - lats) / d
    cc = (lons - (-180.0 + d / 2)) / d
    need_r = range(int(rr.min()) // t, int(rr.max() + 1) // t + 1)
    need_c = range(int(cc.min()) // t, int(cc.max() + 1) // t + 1)

    class Lazy:
        shape, dtype = (n, n), np.dtype(np.int16)

        def __call__(self, r0, r1, c0, c1):
            la = 90.0 - d / 2 - d * np.arange(r0, r1)
            lo = -180.0 + d / 2 + d * np.arange(c0, c1)
            return np.round(plane(lo[None, :], la[:, None])).astype(np.int16)

    write_tiff(os.path.join(GRIDS, "plane_gebco_tile.tif"), Lazy(), -180.0, 90.0, d, d,
               nodata=NODATA, tile=t, deflate=True,
               stored=lambda r, c: r in need_r and c in need_c)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data", "bathymetry"))
    a = ap.parse_args()
    os.makedirs(GRIDS, exist_ok=True)
    os.makedirs(LINES, exist_ok=True)
    monterey(a.data)
    synthetic()


if __name__ == "__main__":
    main()
