"""The safety matrix of the README: every shared profile, --horizon 1..5,
max_iterations in {1, 2, 5, 10, 20, 200}; prints the runs that are not safe
(Monterey 3 is expected infeasible). Usage: python3 scripts/safety_matrix.py
[PLAN_BINARY] (default target/release/examples/plan; build it first)."""
import os
import json, subprocess, sys, os, itertools
B=sys.argv[1] if len(sys.argv)>1 else 'target/release/examples/plan'
D=os.path.join(os.path.dirname(__file__), '..', 'data', 'bathymetry')
cases={'us_monterey_canyon_1':(80,60),'us_monterey_canyon_2':(80,60),'us_monterey_canyon_3':(80,60),
       'es_medes_islands_1':(5,3),'es_medes_islands_2':(5,3),'jp_aburatsubo_sagami_1':(2,1)}
extra=sys.argv[2] if len(sys.argv)>2 else ''
bad=0; n=0
for p,(hr,ha) in cases.items():
    for h in range(1,6):
        for it in (1,2,5,10,20,200):
            cfg=f'/tmp/auvnav_cfg_{p}_{it}.toml'
            open(cfg,'w').write(f'reference_altitude = {hr}\nmin_altitude = {ha}\n{extra}\n[optimizer]\nmax_iterations = {it}\n')
            r=subprocess.run([B,'--profile',f'{D}/{p}.csv','--waypoints',f'{D}/{p}.waypoints.csv','--config',cfg,'--horizon',str(h),'--json'],capture_output=True,text=True)
            n+=1
            if r.returncode!=0:
                print(p,h,it,'ERR',r.stderr.strip()[:200]); bad+=1; continue
            j=json.loads(r.stdout)
            st=[t['status'] for t in j['tracks']]
            ok = j['safe'] or (p=='us_monterey_canyon_3')
            minalt=j['min_altitude']
            if not ok or (p!='us_monterey_canyon_3' and minalt < ha-1e-3):
                bad+=1; print(p,h,it,'UNSAFE',round(minalt,2),st)
            elif p=='us_monterey_canyon_3' and h==5 and it==200:
                print(p,h,it,'m3',round(minalt,2),st, [t['safe'] for t in j['tracks']])
print(n,'runs',bad,'bad')
