# Per-mesh best valid output: from a run_suite.py results.csv with the methods
# pleat, qem, meshopt and alphawrap_qem at pleat's face count (--target-from pleat), print
#   1. one row per mesh: normal difference and PSNR of each method, and whether QEM's is valid;
#   2. per-method means over all meshes, over the meshes where QEM's output is valid, and over
#      all but the synthetic tree;
#   3. the "best valid" means: per mesh, the lowest normal difference (highest PSNR) among the
#      outputs that are valid (closed, manifold, self-intersection-free), whichever method made
#      it, against QEM's means over all meshes (valid or not).
# Usage: python3 best_valid.py RUN_DIR
import csv
import sys

rows = list(csv.DictReader(open(sys.argv[1] + "/results.csv")))
by = {}
for r in rows:
    by.setdefault(r["input"], {})[r["method"]] = r
meths = [m for m in ["pleat", "qem", "meshopt", "alphawrap_qem"] if any(m in v for v in by.values())]
inputs = sorted(by)


def val(r, k):
    return float(r[k]) if r and r.get(k) not in ("", None) else float("nan")


def is_valid(r):
    return r["success"] == "True" and r["valid"] == "True"


print("| input | faces | normal diff " + " / ".join(meths) + " | PSNR dB " + " / ".join(meths) + " | QEM valid |")
print("|---|---|---|---|---|")
for i in inputs:
    v = by[i]
    nd = " / ".join(f"{val(v.get(m), 'normal_diff'):.4f}" for m in meths)
    ps = " / ".join(f"{val(v.get(m), 'psnr'):.2f}" for m in meths)
    print(f"| {i} | {v['pleat']['out_faces']} | {nd} | {ps} | {'yes' if is_valid(v['qem']) else 'no'} |")


def mean(sel, m, k):
    xs = [val(by[i].get(m), k) for i in sel]
    return sum(xs) / len(xs)


qem_valid = [i for i in inputs if is_valid(by[i]["qem"])]
no_tree = [i for i in inputs if "tree" not in i]
print()
for name, sel in [("all", inputs), ("QEM valid", qem_valid), ("all but the tree", no_tree)]:
    print(f"{name} ({len(sel)}):")
    for m in meths:
        print(f"  {m:14s} normal diff {mean(sel, m, 'normal_diff'):.4f}  PSNR {mean(sel, m, 'psnr'):.2f}"
              f"  silhouette {mean(sel, m, 'sil_diff'):.4f}  HD {100 * mean(sel, m, 'hd_rel'):.3f} % l")

best_nd, best_ps, from_nd, from_ps = [], [], {}, {}
for i in inputs:
    valid = [(m, r) for m, r in by[i].items() if is_valid(r) and r["normal_diff"]]
    m1, r1 = min(valid, key=lambda t: float(t[1]["normal_diff"]))
    m2, r2 = max(valid, key=lambda t: float(t[1]["psnr"]))
    best_nd.append(float(r1["normal_diff"]))
    best_ps.append(float(r2["psnr"]))
    from_nd[m1] = from_nd.get(m1, 0) + 1
    from_ps[m2] = from_ps.get(m2, 0) + 1
n = len(inputs)
print()
print(f"best valid output per mesh: normal diff {sum(best_nd) / n:.4f} (from {from_nd}), "
      f"PSNR {sum(best_ps) / n:.2f} (from {from_ps})")
print(f"QEM over all, valid or not: normal diff {mean(inputs, 'qem', 'normal_diff'):.4f}, "
      f"PSNR {mean(inputs, 'qem', 'psnr'):.2f}")
