"""Wrinkle design and region edits through the Python package (issue 14): grow a region,
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
