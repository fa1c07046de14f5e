"""Wrinkle design and region edits through the Python package: grow a region,
rotate it, fixed part copied bit for bit, identity edit, design from a source, errors."""
import math

import numpy as np
import pytest

import pleat
from conftest import grid_arrays, needs

pytestmark = needs("wrinkle")

N = 21
K = np.array([8 * math.pi, 0.0, 0.0])


@pytest.fixture
def grid():
    return pleat.Mesh.from_arrays(*grid_arrays(N))


def test_edit_keeps_fixed_bits_and_identity(grid):
    a = pleat.Cwf.plane_wave(grid, K, 0.01)
    centre = (N // 2) * N + N // 2
    faces = pleat.grow_faces(grid, seed_vertices=[centre], rings=3)
    assert 6 < faces.size < grid.triangle_count
    b, labels = a.edit([{"faces": faces, "interface_rings": 3, "rotate": math.pi / 2}])
    assert labels.shape == (grid.triangle_count,) and set(np.unique(labels)) == {0, 1, 2}
    tri = grid.triangles().astype(np.intp)
    touched = np.zeros(grid.vertex_count, dtype=bool)
    touched[tri[labels != 0].ravel()] = True
    assert np.array_equal(a.amplitude()[~touched], b.amplitude()[~touched])
    assert np.array_equal(a.zeta()[~touched], b.zeta()[~touched])
    c, _ = a.edit([{"faces": faces}])
    assert np.allclose(c.omega(), a.omega(), atol=1e-12, rtol=0)


def test_design_and_errors(grid):
    centre = (N // 2) * N + N // 2
    d = pleat.Cwf.design(grid, [(centre, K, 0.02, 4)])
    amp = d.amplitude()
    assert amp[centre] == 0.02 and amp[0] == 0.0
    with pytest.raises(pleat.PleatError):
        pleat.Cwf.design(grid, [(centre, (np.nan, 0, 0), 0.02, 4)])
    a = pleat.Cwf.plane_wave(grid, K, 0.01)
    faces = pleat.grow_faces(grid, seed_vertices=[centre], rings=2)
    with pytest.raises(pleat.PleatError):
        a.edit([{"faces": faces, "frequency_scale": 0.0}])
    with pytest.raises(pleat.PleatError):
        a.edit([{"faces": faces}, {"faces": faces}])
    with pytest.raises(pleat.PleatError):
        pleat.grow_faces(grid, seed_vertices=[centre], rings=0)


def test_edit_compat_target_widens_the_interface(grid):
    a = pleat.Cwf.plane_wave(grid, K / 2, 0.01)  # 2 waves: resolved on the grid
    centre = (N // 2) * N + N // 2
    faces = pleat.grow_faces(grid, seed_vertices=[centre], rings=3)
    region = {"faces": faces, "interface_rings": 1, "rotate": math.pi / 2}
    narrow, _ = a.edit([region], compat_target=0.0)
    rn = narrow.edit_report()
    assert rn["interface_rings"] == [1] and rn["attempts"] == 1
    assert rn["compat_rms"] > 0.3
    wide, labels = a.edit([region], compat_target=0.3, max_interface_rings=6, edit_weight=1.0)
    rw = wide.edit_report()
    assert rw["attempts"] > 1 and 1 < rw["interface_rings"][0] <= 6
    assert rw["interface_rings_max"] == rw["interface_rings"][0]
    assert rw["compat_rms"] < rn["compat_rms"]
    assert rw["compat_rms"] <= 0.3
    assert (labels == 2).sum() > (a.edit([region], compat_target=0.0)[1] == 2).sum()
    for bad in ({"compat_target": float("nan")}, {"compat_target": -0.3},
                {"edit_weight": 0.5}, {"max_interface_rings": 0}):
        with pytest.raises(pleat.PleatError, match=next(iter(bad))):
            a.edit([region], **bad)
    with pytest.raises(pleat.PleatError):
        a.edit_report()


def test_interpolate_locality_flag(grid):
    a = pleat.Cwf.plane_wave(grid, K, 0.01)
    centre = (N // 2) * N + N // 2
    faces = pleat.grow_faces(grid, seed_vertices=[centre], rings=2)
    b, labels = a.edit([{"faces": faces, "interface_rings": 2, "rotate": math.pi / 2}])
    tri = grid.triangles().astype(np.intp)
    touched = np.zeros(grid.vertex_count, dtype=bool)
    touched[tri[labels != 0].ravel()] = True
    kw = dict(guide_frames=2, substeps=1, max_iterations=20)
    anim_local, anim_free = a.interpolate(b, **kw), a.interpolate(b, locality=False, **kw)
    assert anim_local.stats["pinned_vertices"] > 0
    assert anim_free.stats["pinned_vertices"] == 0
    local, free = anim_local.frame(0.5).zeta(), anim_free.frame(0.5).zeta()
    far = ~touched
    far[tri[touched[tri].any(axis=1)].ravel()] = False  # also away from the stars
    assert np.array_equal(local[far], a.zeta()[far])
    assert not np.array_equal(free, local)


def test_design_and_edit_progress_and_cancel(grid):
    centre = (N // 2) * N + N // 2
    calls = []
    d = pleat.Cwf.design(grid, [(centre, K, 0.02, 4)],
                         progress=lambda stage, f: calls.append((stage, f)))
    assert np.array_equal(d.zeta(), pleat.Cwf.design(grid, [(centre, K, 0.02, 4)]).zeta())
    assert len(calls) > 3 and all(s == "design" for s, _ in calls)
    with pytest.raises(pleat.PleatError) as e:
        pleat.Cwf.design(grid, [(centre, K, 0.02, 4)], progress=lambda s, f: True)
    assert e.value.status == "CANCELLED"
    a = pleat.Cwf.plane_wave(grid, K, 0.01)
    faces = pleat.grow_faces(grid, seed_vertices=[centre], rings=3)
    region = {"faces": faces, "rotate": math.pi / 2}
    calls.clear()
    b, labels = a.edit([region], progress=lambda stage, f: calls.append((stage, f)))
    assert np.array_equal(b.zeta(), a.edit([region])[0].zeta())
    assert len(calls) > 3 and all(s == "edit" for s, _ in calls)
    with pytest.raises(pleat.PleatError) as e:
        a.edit([region], progress=lambda s, f: True)
    assert e.value.status == "CANCELLED"
