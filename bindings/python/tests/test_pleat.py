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
print(f"python bindings: {passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
