"""Total J and safety of two builds of the plan tool on the shared
profiles, per option set: python3 scripts/compare_j.py OLD_PLAN NEW_PLAN
(e.g. the tool built at an earlier commit in a worktree)."""
import json, os, subprocess, sys
A, B = sys.argv[1], sys.argv[2]
D=os.path.join(os.path.dirname(__file__), '..', 'data', 'bathymetry')
cases={'us_monterey_canyon_1':(80,60),'us_monterey_canyon_2':(80,60),'es_medes_islands_1':(5,3),'es_medes_islands_2':(5,3),'jp_aburatsubo_sagami_1':(2,1)}
rows=[]
for p,(hr,ha) in cases.items():
    cfg=f'/tmp/auvnav_j_{p}.toml'; open(cfg,'w').write(f'reference_altitude = {hr}\nmin_altitude = {ha}\n')
    for opts in ([],['--horizon','1'],['--horizon','2'],['--horizon','3'],['--mode','track'],['--method','gd']):
        out=[]
        for b in (A,B):
            r=subprocess.run([b,'--profile',f'{D}/{p}.csv','--waypoints',f'{D}/{p}.waypoints.csv','--config',cfg,'--json']+opts,capture_output=True,text=True)
            out.append(json.loads(r.stdout) if r.returncode==0 else None)
        a,bb=out
        if a is None or bb is None: print(p,opts,'err'); continue
        rel=(bb['total_J']-a['total_J'])/a['total_J']
        print(f"{p:24s} {' '.join(opts):18s} base J {a['total_J']:.4e} safe {a['safe']!s:5} | new J {bb['total_J']:.4e} safe {bb['safe']!s:5} | {100*rel:+.2f}%")
