"""Tests of the ctypes bindings; run by tests/c_harness.rs with PLEAT_LIBRARY set.
Prints 'N passed, N failed'."""
import math
import os
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
import pleat  # noqa: E402

passed = failed = 0


def check(cond, what):
    global passed, failed
    if cond:
        passed += 1
    else:
        failed += 1
        print("FAILED:", what)


P = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
T = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]
m = pleat.Mesh.from_arrays(P, T)
check(m.vertex_count == 4 and m.triangle_count == 4, "counts")
check(m.triangles() == T, "triangles round trip")
check(m.positions()[1] == (1.0, 0.0, 0.0), "positions round trip")
with tempfile.TemporaryDirectory() as d:
    f = os.path.join(d, "t.ply")
    m.write(f)
    check(pleat.Mesh.read(f).triangles() == T, "ply round trip")
try:
    pleat.Mesh.from_arrays([(0, 0, math.nan), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    check(False, "NaN accepted")
except pleat.PleatError as e:
    check(e.status == "INVALID_MESH", "NaN status")
try:
    pleat.Mesh.read("/no/such/file.obj")
    check(False, "missing file accepted")
except pleat.PleatError as e:
    check(e.status == "IO" and "file.obj" in str(e), "missing file status")
r = m.check()
check(r["is_watertight"] and r["total_genus"] == 0 and r["component_count"] == 1, "check closed tet")
check(abs(r["surface_area"] - (1.5 + 3 ** 0.5 / 2)) < 1e-12, "area")
check(pleat.version().count(".") == 2, "version")
check(pleat.has_feature("lod") in (True, False), "has_feature")
m.close()
m.close()


def grid(n):
    P = [(i / (n - 1), j / (n - 1), 0.0) for j in range(n) for i in range(n)]
    T = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            T += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    return pleat.Mesh.from_arrays(P, T)


def wrap(x):
    return x - 2 * math.pi * math.floor(x / (2 * math.pi) + 0.5)


g = grid(5)
E = g.edges()
check(len(E) == g.edge_count == 4 * 5 * 2 + 16, "edge count")
check(E == sorted(E) and all(a < b for a, b in E) and E[:3] == [(0, 1), (0, 5), (0, 6)], "edge order")
K = (7.0, 3.0, 0.0)
if pleat.has_feature("wrinkle"):
    w = pleat.Cwf.plane_wave(g, K, 0.02)
    check(w.vertex_count == 25 and w.edge_count == len(E), "cwf counts")
    check(all(abs(abs(z) - 1) < 1e-15 for z in w.zeta()) and w.amplitude() == [0.02] * 25, "cwf copy-out")
    out = w.evaluate(levels=2)
    check(out.triangle_count == 32 * 16, "evaluate triangle count")
    mesh, f = w.evaluate_fields(["phase", "smooth_positions", "z", "normals"], levels=2)
    err = max(abs(wrap(ph - (K[0] * x[0] + K[1] * x[1]))) for ph, x in zip(f["phase"], f["smooth_positions"]))
    check(err < 1e-9, f"plane wave phase exact after refinement ({err:.2e})")
    check(len(f["z"]) == mesh.vertex_count and f["normals"][0] == (0.0, 0.0, 1.0), "fields")
    check(f["stats"]["triangle_count"] == 512 and f["stats"]["levels"] == 2, "eval stats")
    # per-corner omega gives the same field
    X = g.positions()
    corners = [K[0] * (X[t[(i + 1) % 3]][0] - X[t[i]][0]) + K[1] * (X[t[(i + 1) % 3]][1] - X[t[i]][1])
               for t in g.triangles() for i in range(3)]
    wc = pleat.Cwf.from_corner_omega(g, corners, [0.02] * 25, w.zeta())
    check(max(abs(a - b) for a, b in zip(wc.omega(), w.omega())) < 1e-14, "corner omega")
    check(max(abs(a - b) for a, b in zip(wc.corner_omega(), corners)) < 1e-14, "corner omega out")
    bad = list(corners)
    bad[1] += 0.1
    try:
        pleat.Cwf.from_corner_omega(g, bad, [0.02] * 25)
        check(False, "antisymmetry violation accepted")
    except pleat.PleatError as e:
        check(e.status == "INVALID_ARGUMENT" and "antisymmetric" in str(e), "antisymmetry status")
    # Knoppel from wave vectors
    wk = pleat.Cwf.from_frequency(g, [K] * 25, [0.02] * 25)
    r = wk.knoppel_report()
    check(r["iterations"] >= 1 and r["eigenvalue"] < 1e-6, "knoppel report")
    # files
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "w.cwf")
        w.write(path)
        back = pleat.Cwf.read(g, path)
        check(back.omega() == w.omega() and back.zeta() == w.zeta(), "cwf round trip")
        try:
            pleat.Cwf.read(grid(4), path)
            check(False, "cwf for another base accepted")
        except pleat.PleatError as e:
            check(e.status == "INVALID_ARGUMENT", "cwf base mismatch")
    # progress and cancellation
    seen = []
    w.evaluate(levels=3, progress=lambda stage, frac: seen.append((stage, frac)))
    check(len(seen) == 4 and seen[-1] == ("displace", 1.0), f"progress calls {seen}")
    try:
        w.evaluate(levels=3, progress=lambda stage, frac: True)
        check(False, "cancel ignored")
    except pleat.PleatError as e:
        check(e.status == "CANCELLED", "cancel status")

    def boom(stage, frac):
        raise KeyError("from the callback")
    try:
        w.evaluate(levels=2, progress=boom)
        check(False, "callback exception swallowed")
    except KeyError:
        check(True, "callback exception")
    # misuse
    for call, status in [
        (lambda: pleat.Cwf.from_arrays(g, [0.0] * 3, [0.02] * 25), "INVALID_ARGUMENT"),
        (lambda: pleat.Cwf.from_arrays(g, [math.nan] * len(E), [0.02] * 25), "INVALID_ARGUMENT"),
        (lambda: w.evaluate(levels=30), "LIMIT_EXCEEDED"),
        (lambda: pleat.Cwf.from_arrays(pleat.Mesh.from_arrays(P + [(1, 1, 1)], T + [(0, 1, 4)]),
                                       [0.0] * 8, [0.1] * 5), "INVALID_MESH"),
    ]:
        try:
            call()
            check(False, f"misuse accepted, expected {status}")
        except pleat.PleatError as e:
            check(e.status == status, f"{e.status} != {status}: {e}")
    w.close()
else:
    try:
        pleat.Cwf.from_arrays(g, [0.0] * len(E), [0.0] * 25)
        check(False, "wrinkle call in a build without it")
    except pleat.PleatError as e:
        check(e.status == "UNSUPPORTED", "unsupported status")
print(f"python bindings: {passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
