"""Attribute transfer through the Python package: UVs, ids and skin weights of an input on
its LOD, with numpy arrays in and out, and the refusals."""
import numpy as np
import pytest

import pleat
from conftest import needs


def torus(ring=32, tube=16):
    j, i = np.mgrid[0:ring, 0:tube]
    u, t = 2 * np.pi * j.ravel() / ring, 2 * np.pi * i.ravel() / tube
    r = 1 + 0.35 * np.cos(t)
    V = np.stack([r * np.cos(u), r * np.sin(u), 0.35 * np.sin(t)], 1)
    a = (j * tube + i).ravel()
    b = (((j + 1) % ring) * tube + i).ravel()
    c = (((j + 1) % ring) * tube + (i + 1) % tube).ravel()
    d = (j * tube + (i + 1) % tube).ravel()
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.uint32)
    return V, F, np.stack([j.ravel() / ring, i.ravel() / tube], 1)


@needs("lod")
def test_uvs_ids_and_skin_on_a_lod():
    V, F, uv = torus()
    mesh = pleat.Mesh.from_arrays(V, F)
    lod = mesh.lod(screen_size=40)
    with pleat.Transfer(mesh, lod, screen_size=40) as t:
        assert t.lod_vertex_count == lod.vertex_count and t.input_vertex_count == len(V)
        luv = t.f32(uv)
        assert luv.shape == (lod.vertex_count, 2) and luv.dtype == np.float32
        assert luv.min() >= -1e-6 and luv.max() <= 1 + 1e-6
        ids = t.u32(np.arange(len(V)) * 2)
        assert ids.shape == (lod.vertex_count, 1) and np.all(ids % 2 == 0)
        near = t.f32(uv, mode="nearest")
        assert np.array_equal(near, uv[ids[:, 0] // 2].astype(np.float32))
        w0 = 0.5 + 0.5 * np.tanh(3 * V[:, 0])
        joints = np.stack([np.zeros(len(V)), np.ones(len(V))], 1).astype(np.uint32)
        weights = np.stack([w0, 1 - w0], 1)
        lj, lw = t.skin(joints, weights, max_influences=4)
        assert lj.shape == lw.shape == (lod.vertex_count, 4)
        assert np.all(np.abs(lw.astype(np.float64).sum(1) - 1) <= 1e-6)
        assert np.all(lw[:, :-1] >= lw[:, 1:]) and np.all(lj[:, 2:] == 0)


@needs("lod")
def test_refusals():
    V, F, uv = torus()
    mesh = pleat.Mesh.from_arrays(V, F)
    lod = mesh.lod(screen_size=40)
    far = pleat.Mesh.from_arrays(V + 3.0, F)
    with pytest.raises(pleat.PleatError, match="not the mesh this LOD was made from"):
        pleat.Transfer(far, lod, screen_size=40)
    t = pleat.Transfer(mesh, lod, screen_size=40)
    with pytest.raises(pleat.PleatError, match="INVALID_ARGUMENT"):
        t.f32(uv[:-1])
    bad = uv.copy()
    bad[3, 1] = np.nan
    with pytest.raises(pleat.PleatError, match="NaN"):
        t.f32(bad)
    with pytest.raises(pleat.PleatError, match="k is 0"):
        t.f32(np.zeros((len(V), 0)))
    with pytest.raises(ValueError):
        t.f32(uv, mode="cubic")
    with pytest.raises(pleat.PleatError, match="max_influences"):
        t.skin(np.zeros((len(V), 1), np.uint32), np.ones((len(V), 1)), max_influences=9)


def tube(seg=16, rings=25):
    """A capped tube of radius 0.3 from y = 0 to 2, with two joints: joint 1 (pivot (0, 1, 0))
    takes over from joint 0 across y in [0.8, 1.2]."""
    r, s = np.mgrid[0:rings, 0:seg]
    a = 2 * np.pi * s.ravel() / seg
    V = np.stack([0.3 * np.cos(a), 2.0 * r.ravel() / (rings - 1), 0.3 * np.sin(a)], 1)
    V = np.vstack([V, [[0, 0, 0], [0, 2, 0]]])
    F = []
    for i in range(rings - 1):
        for k in range(seg):
            a0, a1 = i * seg + k, i * seg + (k + 1) % seg
            F += [[a0, a1 + seg, a1], [a0, a0 + seg, a1 + seg]]
    n = rings * seg
    for k in range(seg):
        F += [[n, k, (k + 1) % seg], [n + 1, (rings - 1) * seg + (k + 1) % seg, (rings - 1) * seg + k]]
    t = np.clip((V[:, 1] - 0.8) / 0.4, 0, 1)
    joints = np.tile([0, 1], (len(V), 1)).astype(np.uint32)
    return V, np.array(F, dtype=np.uint32), joints, np.stack([1 - t, t], 1)


@needs("lod")
def test_a_lod_follows_a_skin_and_refuses_a_bad_one():
    V, F, joints, weights = tube()
    mesh = pleat.Mesh.from_arrays(V, F)
    plain = mesh.lod(screen_size=50)
    with pleat.Deformation(len(V), joints, weights, pivots=[[0, 0, 0], [0, 1, 0]],
                           morph_deltas=np.zeros((1, len(V), 3)), max_rotation=1.0) as skin:
        followed = mesh.lod(screen_size=50, deformation=skin)
        chain = mesh.lod_chain([100, 50], deformation=skin)
    assert followed.triangle_count > plain.triangle_count
    assert followed.stats["watertight"] and len(chain) == 2
    with pytest.raises(pleat.PleatError, match="INVALID_ARGUMENT"):
        pleat.Deformation(len(V), joints, -weights)
    with pytest.raises(pleat.PleatError, match="shape"):
        pleat.Deformation(len(V), joints[:-1], weights[:-1])
    with pytest.raises(pleat.PleatError, match="morph_deltas"):
        pleat.Deformation(len(V), morph_deltas=np.zeros((1, 3, 3)))
    with pytest.raises(TypeError, match="Deformation"):
        mesh.lod(screen_size=50, deformation="skin")
    other = pleat.Deformation(len(V) - 1, joints[:-1], weights[:-1])
    with pytest.raises(pleat.PleatError, match="deformation"):
        mesh.lod(screen_size=50, deformation=other)
