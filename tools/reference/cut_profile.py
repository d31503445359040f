#!/usr/bin/env python3
"""Independent cut of the map fixtures: the golden profiles the tool's
`plan profile` is checked against (tests/cli_map.rs).

    python3 tools/reference/cut_profile.py [--data ../shared/data/bathymetry]

Shares no code with the Rust (examples/plan/map/) nor with the fixture
writer's file formats: the Monterey depths come straight from the shared
source grid `grids/monterey_gebco2021_15s.npz` (node centres as its README
documents them: row 0 north at `lat_first_center`, column 0 at
`lon_first_center`, 1/240 degree steps), the synthetic ones from the plane
of make_grids.py evaluated at the nodes (float32 for plane_point.tif,
rounded to int16 for plane_gebco_tile.tif). Geodesics: Karney's algorithm
in the `geographiclib` Python package (WGS84). Sampling as spec/cli.md:
each track cut into ceil(s12 / ds) equal geodesic steps, ds = a quarter of
the smaller side (east-west, north-south) of a grid cell at waypoint 0.
Depth = -bilinear elevation of the four nodes around the sample.

Writes tests/fixtures/grids/golden/<case>.csv (x_m,bottom_depth_m,lat,lon)
and <case>.waypoints.csv (wp,x_m).
"""
import argparse
import os

import numpy as np
from geographiclib.geodesic import Geodesic

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
LINES = os.path.join(ROOT, "tests", "fixtures", "lines")
GOLDEN = os.path.join(ROOT, "tests", "fixtures", "grids", "golden")
G = Geodesic.WGS84

PLANE = (-3000.0, 20.0, -30.0)  # make_grids.py: elevation = A + B lon + C lat


class Nodes:
    """Elevation at node (r, c): lat = lat0 - r*d, lon = lon0 + c*d."""

    def __init__(self, lat0, lon0, d, value):
        self.lat0, self.lon0, self.d, self.value = lat0, lon0, d, value

    def bilinear(self, lat, lon):
        fr = (self.lat0 - lat) / self.d
        fc = (lon - self.lon0) / self.d
        r, c = int(np.floor(fr)), int(np.floor(fc))
        t, u = fr - r, fc - c
        z = [[self.value(r + i, c + j) for j in (0, 1)] for i in (0, 1)]
        return ((1 - t) * ((1 - u) * z[0][0] + u * z[0][1])
                + t * ((1 - u) * z[1][0] + u * z[1][1]))


def monterey(data):
    g = np.load(os.path.join(data, "grids", "monterey_gebco2021_15s.npz"))
    depth = g["depth_m"].astype(np.float64)
    return Nodes(float(g["lat_first_center"]), float(g["lon_first_center"]),
                 float(g["dlat_deg"]), lambda r, c: -depth[r, c])


def plane_nodes(lat0, lon0, d, cast):
    a, b, c_ = PLANE

    def value(r, c):
        return cast(a + b * (lon0 + c * d) + c_ * (lat0 - r * d))
    return Nodes(lat0, lon0, d, value)


def read_line(name):
    rows = open(os.path.join(LINES, name + ".csv")).read().split()[1:]
    return [(float(r.split(",")[1]), float(r.split(",")[2])) for r in rows]


def cut(nodes, pts):
    lat, lon = pts[0]
    ew = G.Inverse(lat, lon, lat, lon + nodes.d)["s12"]
    ns = G.Inverse(lat, lon, lat + nodes.d, lon)["s12"]
    ds = min(ew, ns) / 4.0
    out = [(0.0, lat, lon)]
    wx = [0.0]
    x0 = 0.0
    for (la1, lo1), (la2, lo2) in zip(pts, pts[1:]):
        inv = G.Inverse(la1, lo1, la2, lo2)
        s12, azi1 = inv["s12"], inv["azi1"]
        n = max(1, int(np.ceil(s12 / ds)))
        for k in range(1, n + 1):
            if k == n:
                p = (la2, lo2)
            else:
                dr = G.Direct(la1, lo1, azi1, s12 * k / n)
                p = (dr["lat2"], dr["lon2"])
            out.append((x0 + s12 * k / n, p[0], p[1]))
        x0 += s12
        wx.append(x0)
    return [(x, -nodes.bilinear(la, lo), la, lo) for x, la, lo in out], wx


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "data", "bathymetry"))
    ap.add_argument("--check", action="store_true",
                    help="verify the committed goldens reproduce, write nothing")
    a = ap.parse_args()
    os.makedirs(GOLDEN, exist_ok=True)
    differ = []
    d120, d240 = 1.0 / 120.0, 1.0 / 240.0
    cases = {
        "monterey_1": (monterey(a.data), "monterey_1"),
        "monterey_2": (monterey(a.data), "monterey_2"),
        "plane": (plane_nodes(36.80, -122.10, d120, np.float32), "plane"),
        "plane_tile": (plane_nodes(90.0 - d240 / 2, -180.0 + d240 / 2, d240,
                                   lambda v: float(np.round(v))), "plane_tile"),
    }
    for case, (nodes, line) in cases.items():
        prof, wx = cut(nodes, read_line(line))
        texts = {
            case + ".csv": "x_m,bottom_depth_m,lat,lon\n" + "".join(
                f"{x:.4f},{b:.4f},{la:.9f},{lo:.9f}\n" for x, b, la, lo in prof),
            case + ".waypoints.csv": "wp,x_m\n" + "".join(
                f"{i},{x:.4f}\n" for i, x in enumerate(wx)),
        }
        for name, text in texts.items():
            path = os.path.join(GOLDEN, name)
            if a.check:
                if not os.path.exists(path) or open(path).read() != text:
                    differ.append(name)
            else:
                with open(path, "w") as f:
                    f.write(text)
        print(f"{case}: {len(prof)} samples, {wx[-1]:.2f} m")
    if a.check:
        print("goldens reproduce" if not differ else f"DIFFER: {differ}")
        raise SystemExit(1 if differ else 0)


if __name__ == "__main__":
    main()
