"""The README's "Flown" study: `plan fly` on every shared profile in the
nominal, realistic and harsh worlds (examples/plan/fly/worlds/), every
guidance; prints a markdown table per world. Usage:
  python3 scripts/flown_study.py [RUNS_REALISTIC] [RUNS_HARSH] [HORIZON] [PLAN_BINARY]
(defaults 1000, 100, horizon 1, target/release/examples/plan; build it
first with `cargo build --release --example plan`). HORIZON is `--horizon`
of the planned guidances (`all` for every remaining track). The nominal world has no random
key: its flights are all the same, one is flown."""
import json, os, subprocess, sys
R = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
H = int(sys.argv[2]) if len(sys.argv) > 2 else 100
K = sys.argv[3] if len(sys.argv) > 3 else '1'
B = sys.argv[4] if len(sys.argv) > 4 else 'target/release/examples/plan'
ROOT = os.path.join(os.path.dirname(__file__), '..')
D = os.path.join(ROOT, 'data', 'bathymetry')
W = os.path.join(ROOT, 'examples', 'plan', 'fly', 'worlds')
cases = {'us_monterey_canyon_1': (80, 60, 'deep'), 'us_monterey_canyon_2': (80, 60, 'deep'),
         'us_monterey_canyon_3': (80, 60, 'deep'), 'es_medes_islands_1': (5, 3, 'shallow'),
         'es_medes_islands_2': (5, 3, 'shallow'), 'jp_aburatsubo_sagami_1': (2, 1, 'shallow')}
only = os.environ.get('FLOWN_ONLY')
for sev, runs in (('nominal', 1), ('realistic', R), ('harsh', H)):
    print(f'\n#### {sev} world ({runs} flight{"s" if runs > 1 else ""} per profile, --horizon {K})\n')
    print('| profile | guidance | collisions | below h_a | worst min alt (m) | mean alt (m) | RMS vs h_r (m) | time below h_a (s/flight) | bottom lock |')
    print('|---|---|---|---|---|---|---|---|---|')
    for p, (hr, ha, kind) in cases.items():
        if only and p not in only.split(','):
            continue
        cfg = f'/tmp/auvnav_flown_{p}.toml'
        declared = open(os.path.join(W, f'{kind}_declared.toml')).read()
        open(cfg, 'w').write(f'reference_altitude = {hr}\nmin_altitude = {ha}\n{declared}')
        cmd = [B, 'fly', '--profile', f'{D}/{p}.csv', '--waypoints', f'{D}/{p}.waypoints.csv',
               '--config', cfg, '--runs', str(runs), '--seed', '1', '--json']
        if K != 'all':
            cmd += ['--horizon', K]
        if sev != 'nominal':
            cmd += ['--world', os.path.join(W, f'{kind}_{sev}.toml')]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            print(f'| {p} | error: {r.stderr.strip()[-200:]} |'); continue
        j = json.loads(r.stdout)
        for g in j['guidance']:
            lock = '–' if g['bottom_lock_fraction'] is None else f"{g['bottom_lock_fraction']:.3f}"
            print(f"| {p} | {g['name']} | {g['collisions']} | {g['below_min_altitude']} | "
                  f"{g['worst_min_altitude']:.2f} | {g['mean_altitude']:.1f} | "
                  f"{g['mean_rms_altitude_error']:.1f} | {g['time_below_min_altitude_s']:.1f} | {lock} |")
            e = g.get('estimator')
            if e and sev != 'nominal':
                print(f"|  | ↳ estimator ({e['replans']} replans) | depth rms {e['depth_error_rms_m']:.3f} / max {e['depth_error_max_m']:.3f} m | "
                      f"pitch rms {e['pitch_error_rms_deg']:.3f} / max {e['pitch_error_max_deg']:.3f}° | "
                      f"pred. min alt (estimate − truth) rms {e['predicted_min_altitude_error_rms_m']:.3f} / max {e['predicted_min_altitude_error_max_m']:.3f} m | | | | |")
        sys.stdout.flush()
