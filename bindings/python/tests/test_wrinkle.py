"""Complex wrinkle fields through the Python package: creation (per edge, per corner, from
wave vectors), copy-out, files, evaluation with fields, progress, interpolation."""
import math

import numpy as np
import pytest

import pleat
from conftest import TET_F, TET_V, grid_arrays, needs

K = np.array([7.0, 3.0, 0.0])

pytestmark = needs("wrinkle")


def wrap(x):
    return x - 2 * math.pi * np.floor(x / (2 * math.pi) + 0.5)


@pytest.fixture
def wave(grid5):
    return pleat.Cwf.plane_wave(grid5, K, 0.02)


def test_plane_wave_copy_out(grid5, wave):
    assert (wave.vertex_count, wave.edge_count, wave.triangle_count) == (25, 56, 32)
    assert wave.edge_count == grid5.edge_count == len(grid5.edges())
    z = wave.zeta()
    assert z.dtype == np.complex128 and z.shape == (25,) and np.allclose(np.abs(z), 1, atol=1e-15)
    assert np.array_equal(wave.amplitude(), np.full(25, 0.02))
    E, X = grid5.edges(), grid5.positions()
    assert np.allclose(wave.omega(), (X[E[:, 1]] - X[E[:, 0]]) @ K, atol=1e-14)
    assert wave.corner_omega().shape == (32, 3)


def test_evaluate_with_fields(wave):
    out = wave.evaluate(levels=2)
    assert out.triangle_count == 32 * 16 and out.stats["levels"] == 2
    mesh, f = wave.evaluate_fields(["phase", "smooth_positions", "z", "normals", "amplitude",
                                    "omega"], levels=2)
    n = mesh.vertex_count
    assert f["phase"].shape == (n,) and f["z"].dtype == np.complex128
    assert f["normals"].shape == (n, 3) and np.array_equal(f["normals"][0], [0.0, 0.0, 1.0])
    assert f["omega"].shape == (mesh.edge_count,)
    err = np.abs(wrap(f["phase"] - f["smooth_positions"] @ K)).max()
    assert err < 1e-9, "a plane wave's phase is exact after refinement"
    # displacement along the normal by Re(z) (amplitude included)
    disp = mesh.positions() - f["smooth_positions"]
    assert np.allclose(disp, f["z"].real[:, None] * f["normals"], atol=1e-12)
    with pytest.raises(pleat.PleatError):
        wave.evaluate_fields(["no_such_field"], levels=1)


def test_corner_omega_matches_edge_omega(grid5, wave):
    X, T = grid5.positions(), grid5.triangles().astype(np.intp)
    corners = (X[np.roll(T, -1, axis=1)] - X[T]) @ K
    wc = pleat.Cwf.from_corner_omega(grid5, corners, np.full(25, 0.02), wave.zeta())
    assert np.abs(wc.omega() - wave.omega()).max() < 1e-14
    assert np.abs(wc.corner_omega() - corners).max() < 1e-14
    bad = corners.copy()
    bad[0, 1] += 0.1
    with pytest.raises(pleat.PleatError) as e:
        pleat.Cwf.from_corner_omega(grid5, bad, np.full(25, 0.02))
    assert e.value.status == "INVALID_ARGUMENT" and "antisymmetric" in str(e.value)


def test_knoppel_from_wave_vectors(grid5):
    w = pleat.Cwf.from_frequency(grid5, np.tile(K, (25, 1)), np.full(25, 0.02))
    r = w.knoppel_report()
    assert r["iterations"] >= 1 and r["eigenvalue"] < 1e-6
    wf = pleat.Cwf.from_frequency(grid5, np.tile(K, (32, 1)), np.full(25, 0.02), per_face=True,
                                  weights="edge_area")
    assert wf.edge_count == 56
    with pytest.raises(pleat.PleatError) as e:
        pleat.Cwf.plane_wave(grid5, K, 0.02).knoppel_report()
    assert e.value.status == "INVALID_ARGUMENT"


def test_files(tmp_path, grid5, wave):
    path = tmp_path / "w.cwf"
    wave.write(path)
    back = pleat.Cwf.read(grid5, path)
    assert np.array_equal(back.omega(), wave.omega()) and np.array_equal(back.zeta(), wave.zeta())
    with pytest.raises(pleat.PleatError) as e:
        pleat.Cwf.read(pleat.Mesh.from_arrays(*grid_arrays(4)), path)
    assert e.value.status == "INVALID_ARGUMENT"


def test_progress_cancel_and_callback_errors(wave):
    seen = []
    wave.evaluate(levels=3, progress=lambda stage, frac: seen.append((stage, frac)))
    assert len(seen) == 3 * 6 and seen[-1] == ("displace", 1.0)
    with pytest.raises(pleat.PleatError) as e:
        wave.evaluate(levels=3, progress=lambda stage, frac: True)
    assert e.value.status == "CANCELLED"

    def boom(stage, frac):
        raise KeyError("from the callback")
    with pytest.raises(KeyError):
        wave.evaluate(levels=2, progress=boom)


@pytest.mark.parametrize("call, status", [
    (lambda g: pleat.Cwf.from_arrays(g, np.zeros(3), np.full(25, 0.02)), "INVALID_ARGUMENT"),
    (lambda g: pleat.Cwf.from_arrays(g, np.full(56, np.nan), np.full(25, 0.02)),
     "INVALID_ARGUMENT"),
    (lambda g: pleat.Cwf.plane_wave(g, K, 0.02).evaluate(levels=30), "LIMIT_EXCEEDED"),
    (lambda g: pleat.Cwf.from_arrays(
        pleat.Mesh.from_arrays(np.vstack([TET_V, [1, 1, 1]]), np.vstack([TET_F, [0, 1, 4]])),
        np.zeros(8), np.full(5, 0.1)), "INVALID_MESH"),
])
def test_misuse(grid5, call, status):
    with pytest.raises(pleat.PleatError) as e:
        call(grid5)
    assert e.value.status == status


def test_interpolation(tmp_path, grid5):
    a = pleat.Cwf.plane_wave(grid5, K, 0.02)
    b = pleat.Cwf.plane_wave(grid5, 1.5 * K[[1, 0, 2]], 0.03)
    anim = a.interpolate(b, guide_frames=4, substeps=2, max_iterations=50)
    assert anim.frame_count == 4 * 2 + 1 and anim.guide_count == 4
    s = anim.stats
    assert s["stop_reason"] in ("converged", "stalled", "iteration_cap") and s["iterations"] <= 50
    h = anim.history()
    assert h.shape == (s["iterations"] + 1, 2) and np.all(np.diff(h[:, 0]) >= 0)
    start, end = anim.frame(0.0), anim.frame(1.0)
    assert np.array_equal(start.omega(), a.omega()) and np.array_equal(end.omega(), b.omega())
    mid = anim.frame(0.5)
    assert np.allclose(mid.amplitude(), 0.025)
    frames = list(anim.frames())
    assert len(frames) == anim.frame_count
    assert frames[4].evaluate(levels=1).triangle_count == 32 * 4
    path = tmp_path / "a.cwfa"
    anim.write(path)
    back = pleat.Animation.read(grid5, path)
    assert back.frame_count == anim.frame_count and back.history().shape == (0, 2)
    assert np.array_equal(back.frame(0.5).zeta(), mid.zeta())
    with pytest.raises(pleat.PleatError) as e:
        anim.frame(1.5)
    assert e.value.status == "INVALID_ARGUMENT"
    with pytest.raises(pleat.PleatError) as e:
        a.interpolate(b, guide_frames=4, progress=lambda stage, frac: True)
    assert e.value.status == "CANCELLED"
