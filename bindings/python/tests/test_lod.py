"""LODs, LOD chains, cages and offset surfaces through the Python package (tiny meshes)."""
import numpy as np
import pytest

import pleat
from conftest import needs, two_boxes


@needs("lod")
def test_lod_is_verified_and_checks_independently(cube):
    lod = cube.lod(screen_size=10)
    s = lod.stats
    assert 4 <= lod.triangle_count == s["face_count"] and s["vertex_count"] == lod.vertex_count
    assert s["watertight"] and s["manifold"] and s["self_intersection_free"]
    assert 0 < s["hausdorff_relative"] < 0.2 and s["seconds_total"] > 0
    r = lod.check()
    assert r["is_watertight"] and r["self_intersection_free"] and r["consistently_oriented"]
    V, F = lod.positions(), lod.triangles()
    assert V.shape == (lod.vertex_count, 3) and F.max() < lod.vertex_count


@needs("lod")
def test_lod_of_a_soup_and_parameters():
    soup = pleat.Mesh.from_arrays(*two_boxes())
    lod = soup.lod(screen_size=10, max_rounds=5, align=False, measure_floor=True)
    assert lod.check()["is_watertight"] and lod.stats["rounds"] <= 5
    assert np.isfinite(lod.stats["hausdorff_floor_relative"])
    with pytest.raises(TypeError):
        soup.lod(screen_size=10, no_such_parameter=1)
    with pytest.raises(pleat.PleatError) as e:
        soup.lod(screen_size=-1)
    assert e.value.status == "INVALID_ARGUMENT"
    # the offset voxel (the memory budget's knob): 0 = automatic, (0, 2] passed on, else refused
    assert soup.lod(screen_size=10, max_rounds=2, offset_voxel_scale=1.5).check()["is_watertight"]
    with pytest.raises(pleat.PleatError) as e:
        soup.lod(screen_size=10, offset_voxel_scale=3)
    assert e.value.status == "INVALID_ARGUMENT" and "offset_voxel_scale" in str(e.value)


@needs("lod")
def test_lod_start(cube):
    assert cube.lod(screen_size=10, start="input").stats["started_from_input"]
    assert cube.lod(screen_size=10).stats["started_from_input"]  # auto: the cube is clean
    assert not cube.lod(screen_size=10, start="offset").stats["started_from_input"]
    soup = pleat.Mesh.from_arrays(*two_boxes())
    assert not soup.lod(screen_size=10, max_rounds=2).stats["started_from_input"]
    with pytest.raises(pleat.PleatError) as e:
        soup.lod(screen_size=10, start="input")
    assert e.value.status == "INVALID_ARGUMENT"
    with pytest.raises(ValueError):
        cube.lod(screen_size=10, start="sideways")


@needs("lod")
def test_lod_chain(cube):
    chain = cube.lod_chain([20, 10])
    assert len(chain) == 2
    for level in chain:
        assert level.stats["watertight"] and level.check()["is_watertight"]
    assert chain[0].stats["offset_distance"] < chain[1].stats["offset_distance"]
    assert [level.stats["chain_level"] for level in chain] == [0, 1]
    assert chain[0].stats["started_from_finer"] is False
    assert chain[1].stats["seconds_measure"] > 0.0
    assert cube.lod(screen_size=10).stats["chain_level"] == -1
    with pytest.raises(pleat.PleatError):
        cube.lod_chain([])


@needs("lod")
def test_lod_chain_on_two_threads_is_the_one_thread_chain(cube):
    """Independent levels run beside each other on two threads: the same levels, the callback
    on this thread only, fractions that never go back."""
    import threading
    soup = pleat.Mesh.from_arrays(*two_boxes())
    for mesh in (cube, soup):
        runs = []
        for threads in (1, 2):
            seen = []
            pleat.set_thread_count(threads)
            try:
                chain = mesh.lod_chain(
                    [40, 20, 10], progress=lambda stage, f: seen.append((threading.get_ident(), f)))
            finally:
                pleat.set_thread_count(0)
            assert seen and all(t == threading.get_ident() for t, _ in seen)
            fractions = [f for _, f in seen]
            assert fractions == sorted(fractions)
            runs.append([(level.positions(), level.triangles()) for level in chain])
        for (p1, t1), (p2, t2) in zip(*runs):
            assert np.array_equal(p1, p2) and np.array_equal(t1, t2)


@needs("lod")
def test_progress_and_cancel(cube):
    seen = []
    cube.lod(screen_size=10, progress=lambda stage, f: seen.append((stage, f)))
    assert seen and all(0.0 <= f <= 1.0 for _, f in seen)
    with pytest.raises(pleat.PleatError) as e:
        cube.lod(screen_size=10, progress=lambda stage, f: True)
    assert e.value.status == "CANCELLED"

    def boom(stage, f):
        raise KeyError("from the callback")
    with pytest.raises(KeyError):
        cube.lod(screen_size=10, progress=boom)


@needs("cage")
def test_cage_encloses(cube):
    cage = cube.cage(screen_size=10)
    assert cage.stats["encloses_input"] and cage.check()["is_watertight"]
    lo, hi = cage.positions().min(axis=0), cage.positions().max(axis=0)
    assert np.all(lo < 0) and np.all(hi > 1)


@needs("lod")
def test_offset_surface(cube):
    off = cube.offset(screen_size=10)
    assert off.triangle_count > 0 and off.check()["is_watertight"]
    assert set(off.stats) == {"stages", "counts", "metrics", "verified"}
    assert all(off.stats["verified"].values())
    d = 0.1
    off = cube.offset(distance=d, features=False)
    assert abs(off.stats["metrics"]["d"] - d) < 1e-12
    lo = off.positions().min(axis=0)
    assert np.all(np.abs(lo + d) < 0.05 * d + 1e-3)


def test_without_lod_capability(cube):
    if pleat.has_feature("lod"):
        pytest.skip("library has the lod capability")
    with pytest.raises(pleat.PleatError) as e:
        cube.lod(screen_size=10)
    assert e.value.status == "UNSUPPORTED"
