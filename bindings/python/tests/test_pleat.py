"""Mesh basics of the Python package: arrays in and out, files, errors, the validity report.

Run with pytest (``python -m pytest bindings/python/tests``). Run as a script it runs the
whole directory with pytest against the source tree (``tests/c_harness.rs`` does that with
``PLEAT_LIBRARY`` pointing at the freshly built library); without numpy or pytest it says so
and exits 0."""
import math
import os
import sys

if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, os.path.dirname(here))
    try:
        import numpy  # noqa: F401
        import pytest
    except ImportError as e:
        print(f"SKIPPED: Python binding tests need numpy and pytest ({e}); "
              "pip install numpy pytest, or run .ci/packaging.sh")
        sys.exit(0)
    sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", here]))

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import pleat  # noqa: E402
from conftest import CUBE_F, CUBE_V, TET_F, TET_V, grid_arrays, two_boxes  # noqa: E402


def test_version_and_library():
    assert pleat.version().count(".") == 2
    assert pleat.abi_version() == pleat.ABI_VERSION == 1
    assert os.path.exists(pleat.library_path()) or pleat.library_path().startswith("libpleat")
    assert pleat.has_feature("lod") in (True, False)
    assert not pleat.has_feature("no-such-capability")
    assert pleat.thread_count() >= 1


def test_package_version_matches_library():
    try:
        from importlib.metadata import PackageNotFoundError, version
        meta = version("pleat")
    except (ImportError, PackageNotFoundError):
        pytest.skip("pleat is not installed as a distribution (source tree)")
    assert meta == pleat.version()


def test_arrays_round_trip(tet):
    assert (tet.vertex_count, tet.triangle_count, tet.edge_count) == (4, 4, 6)
    P, T = tet.positions(), tet.triangles()
    assert P.dtype == np.float64 and P.shape == (4, 3) and np.array_equal(P, TET_V)
    assert T.dtype == np.uint32 and T.shape == (4, 3) and np.array_equal(T, TET_F)
    assert tet.positions(np.float32).dtype == np.float32
    E = tet.edges()
    assert E.shape == (6, 2) and np.all(E[:, 0] < E[:, 1]) and E[0].tolist() == [0, 1]


def test_float32_interleaved_buffer_without_copy():
    # an interleaved vertex buffer: xyz + uv per vertex (5 floats, stride 20 bytes)
    buf = np.zeros((4, 5), dtype=np.float32)
    buf[:, :3] = TET_V
    buf[:, 3:] = 7.0
    m = pleat.Mesh.from_arrays(buf[:, :3], TET_F.astype(np.int64))
    assert np.array_equal(m.positions(), TET_V)


def test_flat_inputs(tet):
    m = pleat.Mesh.from_arrays(TET_V.ravel().tolist(), TET_F.ravel().tolist())
    assert np.array_equal(m.triangles(), tet.triangles())


def test_files_round_trip(tmp_path, cube):
    path = tmp_path / "cube.ply"
    cube.write(path)
    back = pleat.Mesh.read(path)
    assert np.array_equal(back.positions(), CUBE_V) and np.array_equal(back.triangles(), CUBE_F)


def test_errors_carry_status_and_message():
    with pytest.raises(pleat.PleatError) as e:
        pleat.Mesh.from_arrays([(0, 0, math.nan), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    assert e.value.status == "INVALID_MESH" and e.value.code == 2
    with pytest.raises(pleat.PleatError) as e:
        pleat.Mesh.read("/no/such/file.obj")
    assert e.value.status == "IO" and "file.obj" in str(e.value)
    with pytest.raises(pleat.PleatError) as e:
        pleat.Mesh.from_arrays(TET_V, [(0, 1, 9)])
    assert e.value.status == "INVALID_MESH"
    with pytest.raises(pleat.PleatError) as e:
        pleat.Mesh.from_arrays(TET_V, [(0, 1, -1)])
    assert e.value.status == "INVALID_ARGUMENT"
    with pytest.raises(pleat.PleatError):
        pleat.Mesh.from_arrays(np.zeros((4, 2)), TET_F)
    # errors raised by the binding itself leave the C library's last error alone
    assert "references a vertex" in pleat.last_error()


def test_check_report(tet):
    r = tet.check()
    assert r["is_watertight"] is True and r["total_genus"] == 0 and r["component_count"] == 1
    assert abs(r["surface_area"] - (1.5 + 3 ** 0.5 / 2)) < 1e-12
    assert r["bbox_min"] == (0.0, 0.0, 0.0) and r["bbox_max"] == (1.0, 1.0, 1.0)
    soup = pleat.Mesh.from_arrays(*two_boxes())
    r = soup.check()
    assert r["component_count"] == 2 and r["self_intersections_checked"]
    assert r["self_intersecting_pair_count"] > 0 and not r["self_intersection_free"]
    assert r["self_intersecting_pair_count_is_lower_bound"] is False and "reserved" not in r
    r = soup.check(self_intersections=False)
    assert not r["self_intersections_checked"] and r["self_intersecting_pair_count"] == 0
    open_grid = pleat.Mesh.from_arrays(*grid_arrays(4))
    r = open_grid.check()
    assert not r["is_closed"] and r["boundary_edge_count"] == 12 and r["total_genus"] == -1


def test_check_progress_and_cancel():
    soup = pleat.Mesh.from_arrays(*two_boxes())
    calls = []
    r = soup.check(weld=True, progress=lambda stage, f: calls.append((stage, f)))
    assert r == soup.check(weld=True)
    assert len(calls) >= 7 and all(s == "check" for s, _ in calls)
    assert [f for _, f in calls] == sorted(f for _, f in calls)
    with pytest.raises(pleat.PleatError) as e:
        soup.check(progress=lambda stage, f: True)
    assert e.value.status == "CANCELLED"


def test_weld():
    # the tetrahedron with every triangle on its own vertices: closed only after welding
    V = TET_V[TET_F.ravel()]
    F = np.arange(12, dtype=np.uint32).reshape(4, 3)
    m = pleat.Mesh.from_arrays(V, F)
    assert not m.check()["is_closed"] and m.check(weld=True)["is_watertight"]


def test_close_is_idempotent_and_context_manager():
    with pleat.Mesh.from_arrays(TET_V, TET_F) as m:
        assert m.triangle_count == 4
    m.close()
    assert m.triangle_count == 0


def test_threads():
    n = pleat.thread_count()
    pleat.set_thread_count(1)
    assert pleat.thread_count() == 1
    pleat.set_thread_count(0)
    assert pleat.thread_count() >= 1
    assert n >= 1
