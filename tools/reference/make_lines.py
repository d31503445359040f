#!/usr/bin/env python3
"""The random lines the rounds compare builds on, written as
tools/reference/check_planner.py --keep writes them (DIR/unseen_*/ with
PROFILE.csv, WAYPOINTS.csv, VEHICLE.toml):

    python3 tools/reference/make_lines.py DIR [--seeds 5000 5037]
    python3 scripts/compare_lines.py OLD_PLAN NEW_PLAN DIR [-- --mode track]

Seed s gives check_planner.py's eight random lines of that seed
(`unseen_case(s, 0..7)`), all flown by one vehicle: the default (h_r/h_a
80/60) and the ten of tools/reference/vehicles/ in turn, by seed. Seeds
5000-5037 (the default) give 304 lines, none of them a seed the checker
runs were drawn from."""
import argparse
import os
import sys
import tomllib

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import check_planner as cp  # noqa: E402

VEHICLES = [None, "integ", "low", "rate", "second", "slow", "stiff",
            "fast", "heavy", "twoki", "tight"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dir")
    ap.add_argument("--seeds", nargs=2, type=int, default=(5000, 5037),
                    metavar=("FIRST", "LAST"))
    a = ap.parse_args()
    n = 0
    for k, seed in enumerate(range(a.seeds[0], a.seeds[1] + 1)):
        v = VEHICLES[k % len(VEHICLES)]
        veh = None
        if v:
            with open(os.path.join(HERE, "vehicles", f"{v}.toml"), "rb") as f:
                veh = tomllib.load(f)
        for i in range(8):
            c = cp.unseen_case(seed, i)
            c["name"] = f"{c['name']}_{v or 'default'}"
            cp.write_case(c, a.dir, veh)
            n += 1
    print(f"{n} lines in {a.dir}")


if __name__ == "__main__":
    main()
