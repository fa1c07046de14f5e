"""Textured LODs through the Python package: provenance and the bake with numpy arrays."""
import os
import tempfile

import numpy as np
import pytest

import pleat
from conftest import needs


def uv_sphere(slices=24, stacks=12):
    """A unit UV sphere (seam and poles duplicated) with per-vertex UVs (v = 0 at the top)."""
    j, i = np.mgrid[0:stacks + 1, 0:slices + 1]
    u, v = (i / slices).ravel(), (j / stacks).ravel()
    th, ph = 2 * np.pi * u, np.pi * v
    V = np.stack([np.sin(ph) * np.cos(th), np.sin(ph) * np.sin(th), np.cos(ph)], 1)
    a = (np.arange(slices)[None, :] + (slices + 1) * np.arange(stacks)[:, None]).ravel()
    c = a + slices + 1
    F = np.concatenate([np.stack([a, c, c + 1], 1), np.stack([a, c + 1, a + 1], 1)])
    return V, F.astype(np.uint32), np.stack([u, v], 1)


def checker(n=32):
    y, x = np.mgrid[0:n, 0:n]
    img = np.zeros((n, n, 4), np.uint8)
    img[..., 0] = 255 * x // (n - 1)
    img[..., 1] = np.where(((x // 8) + (y // 8)) % 2 == 1, 200, 40)
    img[..., 2] = 255 - 255 * y // (n - 1)
    img[..., 3] = 255
    return img


@pytest.fixture(scope="module")
def sphere_and_lod():
    V, F, UV = uv_sphere()
    mesh = pleat.Mesh.from_arrays(V, F)
    return mesh, mesh.lod(screen_size=50, max_rounds=6), UV


@needs("bake")
def test_lod_provenance_transfers_attributes(sphere_and_lod):
    mesh, lod, _ = sphere_and_lod
    tri, bary, by_ray = pleat.lod_provenance(lod, mesh, screen_size=50)
    assert tri.shape == (lod.vertex_count,) and bary.shape == (lod.vertex_count, 3)
    assert tri.max() < mesh.triangle_count and np.allclose(bary.sum(1), 1.0)
    assert by_ray.mean() > 0.9
    # Transferring the input's positions lands within the LOD's error of each LOD vertex.
    V, F = mesh.positions(), mesh.triangles()
    p = (V[F[tri]] * bary[..., None]).sum(1)
    assert np.abs(np.linalg.norm(p - lod.positions(), axis=1)).max() < 3 * np.sqrt(12) / 50
    t, b, r = pleat.points_provenance(mesh, [[0, 0, 1.2]], [[0, 0, 1]], envelope=0.5)
    assert r[0] and t[0] < 2 * 24
    with pytest.raises(pleat.PleatError) as e:
        pleat.points_provenance(mesh, [[0, np.nan, 1]])
    assert e.value.status == "INVALID_ARGUMENT"


@needs("bake")
def test_bake_copies_out_and_cancels(sphere_and_lod):
    mesh, lod, UV = sphere_and_lod
    stages = []
    b = pleat.bake(lod, mesh, UV, checker(), metallic_factor=0.0, screen_size=50,
                   texture_size=64, error_samples=300,
                   progress=lambda s, f: stages.append(s) and False)
    assert b.textured and "bake: texels" in stages
    assert b.vertex_count >= lod.vertex_count and b.triangle_count == lod.triangle_count
    uv = b.uvs()
    assert uv.shape == (b.vertex_count, 2) and uv.min() >= 0 and uv.max() <= 1
    assert b.triangles().max() < b.vertex_count and b.positions().shape == (b.vertex_count, 3)
    assert set(np.unique(b.tangents()[:, 3])) <= {-1.0, 1.0}
    img = b.image("base_color")
    assert img.shape == (64, 64, 4) and img[..., 1].min() < 90 and img[..., 1].max() > 160
    assert b.image("normal").shape == (64, 64, 4) and b.image("occlusion") is None
    assert b.stats["charts"] > 0 and b.stats["texture_size"] == 64
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "lod.glb")
        b.write_glb(path)
        assert open(path, "rb").read(4) == b"glTF"
    # Two threads of its own give the same bytes.
    b2 = pleat.bake(lod, mesh, UV, checker(), metallic_factor=0.0, screen_size=50,
                    texture_size=64, error_samples=0, threads=2)
    assert np.array_equal(b2.image("base_color"), img)
    with pytest.raises(pleat.PleatError) as e:
        pleat.bake(lod, mesh, UV, checker(), screen_size=50, texture_size=64,
                   progress=lambda s, f: s == "bake: texels")
    assert e.value.status == "CANCELLED"


@needs("bake")
def test_bake_vertex_colours_and_misuse(sphere_and_lod):
    mesh, lod, UV = sphere_and_lod
    V = mesh.positions()
    colors = np.stack([0.5 + 0.5 * V[:, 2], np.full(len(V), 0.2), 0.5 - 0.5 * V[:, 2],
                       np.ones(len(V))], 1)
    b = pleat.bake(lod, mesh, colors=colors, screen_size=50)
    assert not b.textured and b.colors().shape == (lod.vertex_count, 4)
    with pytest.raises(pleat.PleatError):
        b.uvs()
    bad = UV.copy()
    bad[3, 0] = np.nan
    for kwargs, status in [
        (dict(uvs=bad, base_color=checker()), "INVALID_ARGUMENT"),
        (dict(uvs=None, base_color=checker()), "INVALID_ARGUMENT"),
        (dict(uvs=UV, base_color=checker(), texture_size=10 ** 6), "INVALID_ARGUMENT"),
        (dict(uvs=UV, base_color=np.zeros((0, 4, 4), np.uint8)), "INVALID_ARGUMENT"),
    ]:
        with pytest.raises(pleat.PleatError) as e:
            pleat.bake(lod, mesh, screen_size=50, **kwargs)
        assert e.value.status == status, kwargs
    with pytest.raises(pleat.PleatError):
        pleat.bake(lod, mesh, UV[:-1], checker())


@needs("bake")
def test_bake_several_materials(sphere_and_lod):
    mesh, lod, UV = sphere_and_lod
    V = mesh.positions()
    F = mesh.triangles()
    lower = (V[F].mean(axis=1)[:, 2] < 0).astype(np.uint32)
    b = pleat.bake(lod, mesh, UV, screen_size=50, texture_size=64, error_samples=0,
                   materials=[dict(base_color=checker()),
                              dict(base_color_factor=(0.0, 1.0, 0.0, 1.0))],
                   triangle_material=lower)
    img = b.image("base_color")
    green = (img[..., 0] < 20) & (img[..., 1] > 240) & (img[..., 2] < 20)
    assert b.textured and green.sum() > 50
    for kwargs in [dict(triangle_material=np.full(len(F), 2, np.uint32)),
                   dict(triangle_material=lower[:-1]),
                   dict(materials=[dict(colour=1)], triangle_material=lower * 0)]:
        args = dict(materials=[dict(base_color=checker()), dict()], triangle_material=lower)
        args.update(kwargs)
        with pytest.raises(pleat.PleatError) as e:
            pleat.bake(lod, mesh, UV, screen_size=50, texture_size=64, **args)
        assert e.value.status == "INVALID_ARGUMENT", kwargs
