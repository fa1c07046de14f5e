"""Small generated meshes for the tests (no files needed) and feature markers.

The tests import the ``pleat`` found on sys.path: the installed package under
``.ci/packaging.sh``, the source tree when run through ``test_pleat.py`` as a script
(``tests/c_harness.rs`` does that with ``PLEAT_LIBRARY`` set)."""
import numpy as np
import pytest

import pleat

CUBE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                   [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=np.float64)
CUBE_F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                   [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]],
                  dtype=np.uint32)
TET_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
TET_F = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]], dtype=np.uint32)


def grid_arrays(n):
    """An n×n vertex grid on the unit square in z = 0, two triangles per cell (vectorized)."""
    j, i = np.mgrid[0:n, 0:n]
    V = np.stack([i.ravel() / (n - 1), j.ravel() / (n - 1), np.zeros(n * n)], axis=1)
    a = (np.arange(n - 1)[None, :] + n * np.arange(n - 1)[:, None]).ravel()
    F = np.concatenate([np.stack([a, a + 1, a + n + 1], 1), np.stack([a, a + n + 1, a + n], 1)])
    return V, F.astype(np.uint32)


def two_boxes():
    """Two overlapping cubes: a self-intersecting soup with two components."""
    V = np.concatenate([CUBE_V, CUBE_V * 0.8 + 0.5])
    F = np.concatenate([CUBE_F, CUBE_F + 8])
    return V, F


@pytest.fixture
def cube():
    return pleat.Mesh.from_arrays(CUBE_V, CUBE_F)


@pytest.fixture
def tet():
    return pleat.Mesh.from_arrays(TET_V, TET_F)


@pytest.fixture
def grid5():
    return pleat.Mesh.from_arrays(*grid_arrays(5))


def needs(feature):
    """Skip marker for tests of a capability the loaded library was built without."""
    return pytest.mark.skipif(not pleat.has_feature(feature),
                              reason=f"library built without the {feature!r} capability")
