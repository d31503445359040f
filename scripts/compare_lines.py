"""Total J, flights and safety of two builds of the plan tool on the lines
kept by tools/reference/check_planner.py --keep DIR (each DIR/unseen_*/
holds PROFILE.csv, WAYPOINTS.csv, VEHICLE.toml):

    python3 scripts/compare_lines.py OLD_PLAN NEW_PLAN DIR [DIR ...] [-- OPTIONS]

OPTIONS go to both tools (e.g. -- --mode track). Prints the lines whose J
moved by more than 1e-5 (relative) or whose flights changed, then how many
lines got lower, higher or stayed equal."""
import glob, json, os, subprocess, sys

args = sys.argv[1:]
opts = args[args.index('--') + 1:] if '--' in args else []
args = args[:args.index('--')] if '--' in args else args
old, new, dirs = args[0], args[1], args[2:]


def run(b, c):
    r = subprocess.run([b, '--profile', f'{c}/PROFILE.csv', '--waypoints', f'{c}/WAYPOINTS.csv',
                        '--config', f'{c}/VEHICLE.toml', '--json'] + opts, capture_output=True, text=True)
    if r.returncode != 0:
        return None
    d = json.loads(r.stdout)
    return d['total_J'], sum(t.get('evaluations', 0) for t in d['tracks']), d['safe']


lower = higher = equal = 0
for c in sorted(c for d in dirs for c in glob.glob(os.path.join(d, 'unseen_*'))):
    a, b = run(old, c), run(new, c)
    if a is None or b is None:
        print(f'{os.path.basename(c):14s} error: {a} {b}')
        continue
    rel = (b[0] - a[0]) / a[0] if a[0] else 0.0
    lower += rel < -1e-5
    higher += rel > 1e-5
    equal += abs(rel) <= 1e-5
    if abs(rel) > 1e-5 or a[1] != b[1] or a[2] != b[2]:
        print(f'{os.path.basename(c):14s} J {a[0]:.6e} -> {b[0]:.6e} ({100 * rel:+.3f} %), '
              f'flights {a[1]} -> {b[1]}, safe {a[2]} -> {b[2]}')
print(f'{lower} lower, {higher} higher, {equal} equal')
