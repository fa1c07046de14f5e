# Per-method means over all meshes and over the meshes where MeshLab QEM is valid, from a
# run_suite.py results.csv: python3 split.py RUN_DIR [x]  (x: also one row per mesh)
import csv,sys,statistics as st
rows=list(csv.DictReader(open(sys.argv[1]+'/results.csv')))
meths=sorted(set(r['method'] for r in rows))
by={(r['input'],r['method']):r for r in rows}
inputs=sorted(set(r['input'] for r in rows))
def f(x):
    try: return float(x)
    except: return None
valid=lambda r: r['success']=='True' and r['watertight']=='True' and r['si_free']=='True' and r['manifold']=='True'
qv=[i for i in inputs if (i,'qem') in by and valid(by[(i,'qem')])]
for name,sel in [('all',inputs),('qem-valid',qv)]:
    print(f"== {name} ({len(sel)})")
    for m in meths:
        rs=[by[(i,m)] for i in sel if (i,m) in by and by[(i,m)]['success']=='True']
        g=lambda k: st.mean(f(r[k]) for r in rs if f(r[k]) is not None)
        print(f"{m:12s} n={len(rs):2d} valid={sum(valid(r) for r in rs):2d} F={g('out_faces'):7.1f} HD={100*g('hd_rel'):.3f} sil={g('sil_diff'):.4f} nd={g('normal_diff'):.4f} psnr={g('psnr'):.2f} t={g('wall_s'):.2f}")
if len(sys.argv)>2:
    for i in inputs:
        print(f"{i[:28]:28s}",' '.join(f"{m[:6]}:{by[(i,m)]['out_faces']:>5s} {f(by[(i,m)]['normal_diff']) or 0:.3f} {f(by[(i,m)]['psnr']) or 0:5.2f}" for m in meths if (i,m) in by))
