"""The README's cost-of-certification table: J, RMS and the least certified
altitude on the shared profiles, nominal and with declared map and vehicle
uncertainty. Usage: python3 scripts/uncertainty_cost.py (after
cargo build --release --example plan)."""
import os
import json, subprocess
B='target/release/examples/plan'; D=os.path.join(os.path.dirname(__file__), '..', 'data', 'bathymetry')
cases={'us_monterey_canyon_1':(80,60,1.0),'us_monterey_canyon_2':(80,60,1.0),'es_medes_islands_1':(5,3,0.1),'es_medes_islands_2':(5,3,0.1),'jp_aburatsubo_sagami_1':(2,1,0.05)}
sets={'nominal':{},
 'map':{'horizontal_uncertainty':10,'nav_drift':0.002,'vertical_uncertainty':5},
 'vehicle':{'speed_uncertainty':0.05,'flight_path_offset':1.5,'vertical_current':0.05},
 'all':{'horizontal_uncertainty':10,'nav_drift':0.002,'vertical_uncertainty':5,'speed_uncertainty':0.05,'flight_path_offset':1.5,'vertical_current':0.05}}
print('| profile | declared | total J m³ | vs nominal | mean RMS m | safe | min certified altitude m |')
print('|---|---|---:|---:|---:|:---:|---:|')
for p,(hr,ha,sc) in cases.items():
    base=None
    for name,u in sets.items():
        lines=[f'reference_altitude = {hr}',f'min_altitude = {ha}']
        for k,v in u.items():
            vv = v*sc if k in ('horizontal_uncertainty','vertical_uncertainty') else v
            lines.append(f'{k} = {vv}')
        cfg=f'/tmp/auvnav_u_{p}_{name}.toml'; open(cfg,'w').write('\n'.join(lines)+'\n')
        r=subprocess.run([B,'--profile',f'{D}/{p}.csv','--waypoints',f'{D}/{p}.waypoints.csv','--config',cfg,'--json'],capture_output=True,text=True)
        if r.returncode: print(p,name,r.stderr); continue
        j=json.loads(r.stdout)
        J=j['total_J']; rms=sum(t['rms'] for t in j['tracks'])/len(j['tracks'])
        cm=min(t['certified_min_altitude'] for t in j['tracks'])
        if base is None: base=J
        print(f"| {p} | {name} | {J:.4g} | {100*(J/base-1):+.1f} % | {rms:.2f} | {'yes' if j['safe'] else '**no**'} | {cm:.2f} |")
