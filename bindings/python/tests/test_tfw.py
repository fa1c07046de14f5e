"""Tension-field wrinkles through the Python package: a small stretched sheet from arrays
(13 × 6 vertices, solved in well under a second), stats, history, base mesh, field,
wrinkled mesh, cancellation and errors."""
import numpy as np
import pytest

import pleat
from conftest import needs

pytestmark = needs("tfw")

NX, NY = 13, 6


def sheet_arrays(stretch=0.05):
    """The stretched sheet (0.25 × 0.1 m) on an NX × NY grid, both short edges clamped."""
    j, i = np.mgrid[0:NY, 0:NX]
    uv = np.stack([0.25 * i.ravel() / (NX - 1), 0.1 * j.ravel() / (NY - 1)], axis=1)
    pos = np.stack([(uv[:, 0] - 0.125) * (1 + stretch), uv[:, 1] - 0.05, np.zeros(NX * NY)], 1)
    tris = []
    for jj in range(NY - 1):
        for ii in range(NX - 1):
            a, b, c, d = jj * NX + ii, jj * NX + ii + 1, (jj + 1) * NX + ii + 1, (jj + 1) * NX + ii
            tris += [[a, b, c], [a, c, d]] if (ii + jj) % 2 == 0 else [[a, b, d], [b, c, d]]
    clamped = [jj * NX for jj in range(NY)] + [jj * NX + NX - 1 for jj in range(NY)]
    return uv, np.array(tris, dtype=np.uint32), pos, clamped


@pytest.fixture(scope="module")
def solved():
    uv, tris, pos, clamped = sheet_arrays()
    scene = pleat.TfwScene.from_arrays(uv, tris, pos, clamped, young=1e6, poisson=0.5,
                                       thickness=1e-4)
    return scene.solve(sqp_max_iterations=40)


def test_small_sheet_wrinkles(solved):
    s = solved.stats
    assert s["status"] in ("converged", "not_converged")
    assert s["vertex_count"] == NX * NY and s["triangle_count"] == 2 * (NX - 1) * (NY - 1)
    assert 0 < s["peak_amplitude"] < 5e-3
    assert s["energy"] <= s["initial_energy"] and s["curl_residual"] <= 1e-10
    h = solved.history()
    assert h.shape == (s["sqp_iterations"], 4)
    assert np.all(np.diff(h[:, 0]) <= 0) and np.all(np.diff(h[:, 3]) >= 0)


def test_result_meshes_and_field(solved):
    base = solved.base_mesh()
    assert base.vertex_count == NX * NY
    cwf = solved.cwf()
    assert cwf.vertex_count == NX * NY
    assert cwf.amplitude().max() == solved.stats["peak_amplitude"]
    w = solved.evaluate(levels=2)
    assert w.triangle_count == 16 * base.triangle_count
    z = w.positions()[:, 2]
    assert z.max() - z.min() > 0
    assert solved.evaluate(levels=1, in_plane_v2=False).triangle_count == 4 * base.triangle_count


def test_cancel_and_errors(tmp_path):
    uv, tris, pos, clamped = sheet_arrays()
    scene = pleat.TfwScene.from_arrays(uv, tris, pos, clamped)
    with pytest.raises(pleat.PleatError) as e:
        scene.solve(progress=lambda stage, f: True)
    assert e.value.status == "CANCELLED"
    with pytest.raises(pleat.PleatError) as e:
        scene.solve(sqp_armijo=float("nan"))
    assert "sqp_armijo" in str(e.value)
    bad = uv.copy()
    bad[3, 1] = np.nan
    with pytest.raises(pleat.PleatError) as e:
        pleat.TfwScene.from_arrays(bad, tris, pos, clamped)
    assert "rest[7]" in str(e.value)
    with pytest.raises(pleat.PleatError) as e:
        pleat.TfwScene.from_arrays(uv, tris, pos, clamped, thickness=-1)
    assert "thickness" in str(e.value)
    with pytest.raises(pleat.PleatError) as e:
        pleat.TfwScene.from_json('{"material": {"yung": 1}}')
    assert "yung" in str(e.value)
    with pytest.raises(pleat.PleatError) as e:
        pleat.TfwScene.read(tmp_path / "missing.json")
    assert e.value.status == "IO"


def test_both_step_solvers():
    """``qp`` (PleatTfwParams.qp, appended 2026-11-27): both SQP step solvers give a
    curl-free field with about the same peak amplitude; an unknown name is an error."""
    uv, tris, pos, clamped = sheet_arrays()
    scene = pleat.TfwScene.from_arrays(uv, tris, pos, clamped, young=1e6, poisson=0.5,
                                       thickness=1e-4)
    peaks = []
    for qp in ("clarabel", "newton"):
        s = scene.solve(sqp_max_iterations=40, qp=qp).stats
        assert s["curl_residual"] <= 1e-10 and s["energy"] <= s["initial_energy"]
        peaks.append(s["peak_amplitude"])
    assert abs(peaks[0] - peaks[1]) <= 0.05 * peaks[0]
    with pytest.raises(pleat.PleatError) as e:
        scene.solve(qp="simplex")
    assert "qp" in str(e.value)


def test_snap_rescue_stats_and_valley_switch(solved):
    """The fields appended 2026-11-29: snapping statistics (a flat sheet has no
    non-contractible loop: nothing snapped), the SQP rescue (none: −1), and
    ``valley_search=0`` (same kind of field without the valley search); 2 is an error."""
    s = solved.stats
    assert s["snapped_loops"] == 0 and s["snap_max_correction"] == 0
    assert s["sqp_rescue_iteration"] == -1
    uv, tris, pos, clamped = sheet_arrays()
    scene = pleat.TfwScene.from_arrays(uv, tris, pos, clamped, young=1e6, poisson=0.5,
                                       thickness=1e-4)
    off = scene.solve(sqp_max_iterations=40, valley_search=0, snap_periods=1).stats
    assert off["curl_residual"] <= 1e-10 and off["energy"] <= off["initial_energy"]
    assert off["snapped_loops"] == 0
    with pytest.raises(pleat.PleatError) as e:
        scene.solve(valley_search=2)
    assert "valley_search" in str(e.value)


def test_count_waves(solved):
    """``count_waves`` (pleat_tfw_result_count_waves): the automatic section crosses the
    sheet's waves; the same plane given explicitly gives the same count; bad input raises."""
    w = solved.count_waves(levels=2)
    assert w["waves"] >= 1 and 0 < w["peak_amplitude"] < 5e-3 and w["samples"] > 0
    again = solved.count_waves(levels=2, point=w["point"], normal=w["normal"],
                               closed=w["closed"])
    assert again["waves"] == w["waves"] and again["peak_amplitude"] == w["peak_amplitude"]
    cut = solved.count_waves(levels=2, point=w["point"], normal=w["normal"],
                             closed=w["closed"], min_radius=0.02)
    assert cut["min_radius"] == 0.02 and 0 < cut["samples"] < w["samples"]
    with pytest.raises(pleat.PleatError) as e:
        solved.count_waves(min_radius=-1.0)
    assert "min_radius" in str(e.value)
    with pytest.raises(pleat.PleatError) as e:
        solved.count_waves(levels=9)
    assert "levels" in str(e.value)
    with pytest.raises(pleat.PleatError) as e:
        solved.count_waves(point=(0, 0, 0), normal=(0, 0, 0))
    assert "section_normal" in str(e.value)


def test_obstacles():
    """``add_obstacle`` (pleat_tfw_scene_add_obstacle): a plane just below the sheet keeps the
    base above it; bad obstacles raise naming the field and leave the scene as it was."""
    uv, tris, pos, clamped = sheet_arrays()
    scene = pleat.TfwScene.from_arrays(uv, tris, pos, clamped, thickness=1e-4, density=1000,
                                       gravity=(0, 0, -9.81))
    with pytest.raises(pleat.PleatError) as e:
        scene.add_obstacle("sphere", point=(0, 0, -1), radius=0)
    assert "radius" in str(e.value)
    with pytest.raises(pleat.PleatError) as e:
        scene.add_obstacle("cone")
    assert "cone" in str(e.value)
    scene.add_obstacle("plane", point=(0, 0, -1e-3), normal=(0, 0, 1))
    r = scene.solve(sqp_max_iterations=5)
    z = r.base_mesh().positions()[:, 2]
    assert z.min() > -1e-3 - 1e-4
