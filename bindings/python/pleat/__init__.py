"""pleat — LODs by screen size, cages and complex wrinkle fields, from Python.

A ctypes binding of pleat's C ABI (``include/pleat.h``) with numpy arrays in and out: data
crosses the boundary as whole buffers, never element by element. ``pip install
./bindings/python`` bundles the shared library in the package, so ``import pleat`` needs no
environment variable. Works in Blender, Maya and Houdini's Python as in plain CPython.

    import numpy as np
    import pleat

    mesh = pleat.Mesh.read("bunny.obj")               # or Mesh.from_arrays(V, F)
    lod = mesh.lod(screen_size=50)                     # watertight, manifold, no self-intersections
    print(lod.triangle_count, lod.stats["hausdorff_relative"])
    V, F = lod.positions(), lod.triangles()            # (n, 3) float64, (m, 3) uint32
    chain = mesh.lod_chain([200, 50, 12])              # several screen sizes, one call
    report = lod.check()                               # validity report (dict)

    w = pleat.Cwf.plane_wave(mesh, k=(9, 4, 2), amplitude=0.01)     # wrinkle fields
    wrinkled = w.evaluate(levels=3)

Which library is loaded, first found wins (``pleat.library_path()`` tells):

1. ``$PLEAT_LIBRARY``, a path to a ``libpleat.so`` — an explicit choice beats an implicit one,
   so a developer can test a fresh ``cargo build`` against the installed package;
2. the library bundled next to this file by ``pip install``;
3. the system's (``libpleat.so.0`` as installed by ``packaging/install.sh``).

The loaded library must have the C ABI version this module was written for
(``ABI_VERSION``), else the import fails with a message naming the file.
"""

import ctypes as _c
import ctypes.util as _cutil
import json as _json
import os as _os

import numpy as _np

__all__ = [
    "ABI_VERSION", "Mesh", "Cwf", "Animation", "PleatError", "version", "abi_version",
    "has_feature", "set_thread_count", "thread_count", "library_path", "Bake", "bake",
    "lod_provenance", "points_provenance", "BAKE_IMAGES", "grow_faces", "__version__",
]

#: The C ABI version (``PLEAT_ABI_VERSION`` of pleat.h) this module's declarations match.
ABI_VERSION = 1

_STATUS = {
    0: "OK", 1: "INVALID_ARGUMENT", 2: "INVALID_MESH", 3: "IO", 4: "PARSE", 5: "NUMERICAL",
    6: "CANCELLED", 7: "LIMIT_EXCEEDED", 8: "OUT_OF_MEMORY", 9: "INTERNAL", 10: "UNSUPPORTED",
}


class PleatError(RuntimeError):
    """A pleat call failed. ``status`` is the C status name (``"INVALID_MESH"``, ...),
    ``code`` its number (``PLEAT_STATUS_*``); the message is pleat's."""

    def __init__(self, code, message):
        super().__init__(f"{_STATUS.get(code, code)}: {message}")
        self.code = int(code)
        self.status = _STATUS.get(code, str(code))


# --- loading -------------------------------------------------------------------------------

_HERE = _os.path.dirname(_os.path.abspath(__file__))
_BUNDLED = ("libpleat.so", "libpleat.so.0", "libpleat.dylib", "pleat.dll")


def _candidates():
    """Library paths or names to try, in the order documented in the module doc."""
    env = _os.environ.get("PLEAT_LIBRARY")
    if env:
        return [("$PLEAT_LIBRARY", env)]
    out = [("bundled", _os.path.join(_HERE, n)) for n in _BUNDLED
           if _os.path.exists(_os.path.join(_HERE, n))]
    system = _cutil.find_library("pleat")
    out += [("system", n) for n in ("libpleat.so.0", system) if n]
    return out


def _load():
    errors = []
    for origin, path in _candidates():
        try:
            lib = _c.CDLL(path)
        except OSError as e:
            errors.append(f"{origin} {path}: {e}")
            continue
        lib.pleat_abi_version.restype = _c.c_uint32
        abi = lib.pleat_abi_version()
        if abi != ABI_VERSION:
            raise ImportError(f"{path} ({origin}) has C ABI version {abi}; this pleat module "
                              f"needs {ABI_VERSION}")
        return lib, path
    raise ImportError("cannot load the pleat library (reinstall the package with pip, or set "
                      "PLEAT_LIBRARY to a libpleat.so). Tried:\n  " + "\n  ".join(errors))


_lib, _path = _load()
_P = _c.c_void_p
_sz = _c.c_size_t
_st = _c.c_int32
_u32 = _c.c_uint32
_D = _c.POINTER(_c.c_double)
_F = _c.POINTER(_c.c_float)
_U = _c.POINTER(_c.c_uint32)
_PP = _c.POINTER(_P)


def _sig(name, restype, *args):
    f = getattr(_lib, name)
    f.restype = restype
    f.argtypes = list(args)


def _struct(name, fields):
    """A ctypes Structure with ``fields`` as (name, ctype) pairs."""
    return type(name, (_c.Structure,), {"_fields_": fields})


def _f64s(*names):
    return [(n, _c.c_double) for n in names]


def _u32s(*names):
    return [(n, _c.c_uint32) for n in names]


def _u64s(*names):
    return [(n, _c.c_uint64) for n in names]


_Progress = _struct("PleatProgress", [("stage", _c.c_char_p), ("fraction", _c.c_double)])
_PROGRESS_FN = _c.CFUNCTYPE(_c.c_int32, _c.c_void_p, _c.POINTER(_Progress))

_LodParams = _struct("PleatLodParams", _u32s("struct_size", "max_rounds") + _f64s("screen_size")
                     + _u64s("target_faces") + _f64s("flow_ratio", "epsilon", "theta0_deg")
                     + _u32s("l0", "flags") + _u64s("memory_budget_bytes")
                     + _f64s("clearance") + _u32s("start", "reserved")
                     + _f64s("offset_voxel_scale") + [("deformation", _P)])
_LodStats = _struct("PleatLodStats", _u32s("struct_size", "rounds")
                    + _u64s("face_count", "vertex_count", "start_face_count", "collapse_count")
                    + _f64s("seconds_total", "seconds_offset", "seconds_simplify", "seconds_flow",
                            "seconds_align", "seconds_verify", "offset_distance", "hausdorff",
                            "hausdorff_relative")
                    + _u32s("watertight", "manifold", "self_intersection_free", "encloses_input",
                            "exact_rerun", "target_met")
                    + _f64s("hausdorff_in_to_out_relative", "hausdorff_out_to_in_relative",
                            "hausdorff_floor_relative", "min_clearance",
                            "min_clearance_relative", "clearance_required")
                    + _u32s("clearance_kept", "started_from_input")
                    + _f64s("measured_estimate_bytes")
                    + _u32s("started_from_finer", "stalled", "converged", "fit_reverted")
                    + _f64s("seconds_fit", "seconds_measure")
                    + [("chain_level", _c.c_int64)])
_OffsetParams = _struct("PleatOffsetParams", _u32s("struct_size", "use_absolute_distance")
                        + _f64s("screen_size", "distance", "voxel_scale", "theta0_deg")
                        + _u32s("l0", "features", "remove_interior", "iso_refinement_steps")
                        + _u64s("memory_budget_bytes") + _u32s("verify", "reserved"))
_Report = _struct("PleatMeshReport", _u32s("struct_size", "is_closed")
                  + _u64s("vertex_count", "referenced_vertex_count", "triangle_count", "edge_count",
                          "component_count", "boundary_edge_count", "nonmanifold_edge_count",
                          "nonmanifold_vertex_count", "degenerate_face_count",
                          "duplicate_face_count", "misoriented_edge_count",
                          "self_intersecting_pair_count")
                  + [("total_genus", _c.c_int64), ("euler_characteristic", _c.c_int64)]
                  + _u32s("is_edge_manifold", "is_manifold", "is_watertight",
                          "consistently_oriented", "self_intersections_checked",
                          "self_intersection_free")
                  + _f64s("surface_area", "signed_volume", "bbox_diagonal")
                  + [("bbox_min", _c.c_double * 3), ("bbox_max", _c.c_double * 3)]
                  + _u32s("self_intersecting_pair_count_is_lower_bound", "reserved"))
_EvalParams = _struct("PleatWrinkleEvalParams", _u32s("struct_size", "levels", "flags", "boundary")
                      + _f64s("corner_angle", "displacement_scale")
                      + _u64s("max_output_triangles"))
_EvalStats = _struct("PleatWrinkleEvalStats", _u32s("struct_size", "levels")
                     + _u64s("vertex_count", "triangle_count")
                     + _f64s("total_seconds", "subdivision_seconds", "displacement_seconds"))
_KnoppelParams = _struct("PleatKnoppelParams", _u32s("struct_size", "weights", "max_iterations",
                                                     "reserved") + _f64s("tolerance", "shift"))
_KnoppelReport = _struct("PleatKnoppelReport", _u32s("struct_size", "iterations")
                         + _f64s("eigenvalue", "residual", "shift"))
_InterpParams = _struct("PleatWrinkleInterpParams",
                        _u32s("struct_size", "guide_frames", "substeps", "max_iterations")
                        + _f64s("c_scale", "gradient_tolerance") + _u32s("hessian", "reserved")
                        + _u32s("locality", "reserved2"))
_InterpStats = _struct("PleatWrinkleInterpStats",
                       _u32s("struct_size", "iterations", "stop_reason", "factorizations")
                       + _f64s("total_seconds", "final_gradient_norm", "smooth_energy",
                               "compat_energy", "unit_energy", "g_ave", "c")
                       + _u64s("pinned_vertices"))

_WrinkleSource = _struct("PleatWrinkleSource", _u32s("vertex", "rings")
                         + [("wave_vector", _c.c_double * 3)] + _f64s("amplitude"))
_DesignParams = _struct("PleatCwfDesignParams",
                        _u32s("struct_size", "adjacency", "pin_sources", "reserved")
                        + _f64s("heat_time", "kappa", "gamma", "data_weight"))
_RegionEdit = _struct("PleatCwfRegionEdit", _u32s("struct_size", "interface_rings")
                      + [("faces", _U), ("face_count", _c.c_size_t)]
                      + _f64s("rotate_radians", "frequency_scale", "amplitude_scale"))
_EditParams = _struct("PleatCwfEditParams",
                      _u32s("struct_size", "adjacency", "phase", "max_iterations")
                      + _f64s("eps_omega", "eps_amplitude", "gamma", "tolerance")
                      + _f64s("edit_weight", "compat_target")
                      + _u32s("max_interface_rings", "reserved"))
_EditReport = _struct("PleatCwfEditReport",
                      _u32s("struct_size", "attempts", "region_count", "interface_rings_min",
                            "interface_rings_max", "global", "phase_fallback",
                            "phase_iterations")
                      + [(n, _c.c_uint64 * 3) for n in ("face_counts", "vertex_counts",
                                                        "edge_counts")]
                      + _u64s("clamped")
                      + _f64s("omega_residual", "amplitude_residual", "eigenvalue",
                              "phase_residual", "compat_rms", "compat_rms_edit",
                              "compat_rms_interface", "compat_floor")
                      + [("seconds", _c.c_double * 4)])

_PROGRESS_ARGS = (_PROGRESS_FN, _c.c_void_p)
for _name, _res, _args in [
    ("pleat_version", _c.c_char_p, ()),
    ("pleat_abi_version", _u32, ()),
    ("pleat_last_error", _c.c_char_p, ()),
    ("pleat_last_error_message", _st, (_c.c_char_p, _sz, _c.POINTER(_sz))),
    ("pleat_set_thread_count", _st, (_u32,)),
    ("pleat_thread_count", _u32, ()),
    ("pleat_has_feature", _u32, (_c.c_char_p,)),
    # meshes
    ("pleat_mesh_create_f32", _st, (_F, _sz, _sz, _U, _sz, _PP)),
    ("pleat_mesh_create_f64", _st, (_D, _sz, _sz, _U, _sz, _PP)),
    ("pleat_mesh_destroy", None, (_P,)),
    ("pleat_mesh_vertex_count", _sz, (_P,)),
    ("pleat_mesh_triangle_count", _sz, (_P,)),
    ("pleat_mesh_copy_positions_f32", _st, (_P, _F, _sz, _sz)),
    ("pleat_mesh_copy_positions_f64", _st, (_P, _D, _sz, _sz)),
    ("pleat_mesh_copy_indices", _st, (_P, _U, _sz)),
    ("pleat_mesh_edge_count", _sz, (_P,)),
    ("pleat_mesh_copy_edges", _st, (_P, _U, _sz)),
    ("pleat_mesh_read_file", _st, (_c.c_char_p, _PP)),
    ("pleat_mesh_write_file", _st, (_P, _c.c_char_p)),
    ("pleat_mesh_check", _st, (_P, _u32, _c.POINTER(_Report))),
    ("pleat_mesh_check_with_progress", _st, (_P, _u32) + _PROGRESS_ARGS
     + (_c.POINTER(_Report),)),
    # LOD, cage, offset, stats
    ("pleat_lod_params_default", _LodParams, ()),
    ("pleat_lod_generate", _st, (_P, _c.POINTER(_LodParams)) + _PROGRESS_ARGS
     + (_PP, _c.POINTER(_LodStats))),
    ("pleat_cage_generate", _st, (_P, _c.POINTER(_LodParams)) + _PROGRESS_ARGS
     + (_PP, _c.POINTER(_LodStats))),
    ("pleat_lod_generate_chain", _st, (_P, _D, _sz, _c.POINTER(_LodParams)) + _PROGRESS_ARGS
     + (_PP, _c.POINTER(_LodStats))),
    ("pleat_offset_params_default", _OffsetParams, ()),
    ("pleat_offset_surface", _st, (_P, _c.POINTER(_OffsetParams)) + _PROGRESS_ARGS + (_PP, _PP)),
    ("pleat_stats_to_json", _st, (_P, _c.c_char_p, _sz, _c.POINTER(_sz))),
    ("pleat_stats_destroy", None, (_P,)),
    # wrinkle fields
    ("pleat_wrinkle_eval_params_default", _EvalParams, ()),
    ("pleat_knoppel_params_default", _KnoppelParams, ()),
    ("pleat_cwf_create", _st, (_P, _D, _sz, _D, _D, _sz, _PP)),
    ("pleat_cwf_create_from_corner_omega", _st, (_P, _D, _sz, _D, _D, _sz, _PP)),
    ("pleat_cwf_create_from_frequency", _st, (_P, _D, _sz, _u32, _D, _sz,
                                              _c.POINTER(_KnoppelParams), _PP)),
    ("pleat_cwf_read_file", _st, (_P, _c.c_char_p, _PP)),
    ("pleat_cwf_write_file", _st, (_P, _c.c_char_p)),
    ("pleat_cwf_destroy", None, (_P,)),
    ("pleat_cwf_vertex_count", _sz, (_P,)),
    ("pleat_cwf_edge_count", _sz, (_P,)),
    ("pleat_cwf_triangle_count", _sz, (_P,)),
    ("pleat_cwf_copy_omega", _st, (_P, _D, _sz)),
    ("pleat_cwf_copy_corner_omega", _st, (_P, _D, _sz)),
    ("pleat_cwf_copy_amplitude", _st, (_P, _D, _sz)),
    ("pleat_cwf_copy_zeta", _st, (_P, _D, _sz)),
    ("pleat_cwf_get_knoppel_report", _st, (_P, _c.POINTER(_KnoppelReport))),
    ("pleat_cwf_evaluate", _st, (_P, _c.POINTER(_EvalParams)) + _PROGRESS_ARGS
     + (_PP, _PP, _c.POINTER(_EvalStats))),
    ("pleat_wrinkle_fields_count", _sz, (_P, _u32)),
    ("pleat_wrinkle_fields_copy", _st, (_P, _u32, _D, _sz, _sz)),
    ("pleat_wrinkle_fields_copy_f32", _st, (_P, _u32, _F, _sz, _sz)),
    ("pleat_wrinkle_fields_destroy", None, (_P,)),
    # wrinkle animation
    ("pleat_wrinkle_interp_params_default", _InterpParams, ()),
    ("pleat_cwf_interpolate", _st, (_P, _P, _c.POINTER(_InterpParams)) + _PROGRESS_ARGS
     + (_PP, _c.POINTER(_InterpStats))),
    ("pleat_cwf_animation_frame", _st, (_P, _c.c_double, _PP)),
    ("pleat_cwf_animation_frame_count", _sz, (_P,)),
    ("pleat_cwf_animation_guide_count", _sz, (_P,)),
    ("pleat_cwf_animation_history_count", _sz, (_P,)),
    ("pleat_cwf_animation_copy_history", _st, (_P, _D, _sz)),
    ("pleat_cwf_animation_write_file", _st, (_P, _c.c_char_p)),
    ("pleat_cwf_animation_read_file", _st, (_P, _c.c_char_p, _PP)),
    ("pleat_cwf_animation_destroy", None, (_P,)),
    # wrinkle design and editing
    ("pleat_cwf_design_params_default", _DesignParams, ()),
    ("pleat_cwf_edit_params_default", _EditParams, ()),
    ("pleat_cwf_design", _st, (_P, _c.POINTER(_WrinkleSource), _sz, _c.POINTER(_DesignParams),
                               _c.POINTER(_KnoppelParams), _PP)),
    ("pleat_cwf_edit", _st, (_P, _c.POINTER(_RegionEdit), _sz, _c.POINTER(_EditParams), _PP,
                             _c.POINTER(_c.c_uint8))),
    ("pleat_cwf_design_with_progress", _st, (_P, _c.POINTER(_WrinkleSource), _sz,
                                             _c.POINTER(_DesignParams),
                                             _c.POINTER(_KnoppelParams)) + _PROGRESS_ARGS
     + (_PP,)),
    ("pleat_cwf_edit_with_progress", _st, (_P, _c.POINTER(_RegionEdit), _sz,
                                           _c.POINTER(_EditParams)) + _PROGRESS_ARGS
     + (_PP, _c.POINTER(_c.c_uint8))),
    ("pleat_cwf_get_edit_report", _st, (_P, _c.POINTER(_EditReport))),
    ("pleat_cwf_copy_edit_interface_rings", _st, (_P, _U, _sz)),
    ("pleat_mesh_grow_faces", _st, (_P, _U, _sz, _U, _sz, _u32, _u32, _c.POINTER(_c.c_uint8),
                                    _c.POINTER(_sz))),
]:
    _sig(_name, _res, *_args)

# The parameter defaults carry the library's sizeof: a layout mismatch fails the import.
for _fn, _cls in [("pleat_lod_params_default", _LodParams),
                  ("pleat_offset_params_default", _OffsetParams),
                  ("pleat_wrinkle_eval_params_default", _EvalParams),
                  ("pleat_knoppel_params_default", _KnoppelParams),
                  ("pleat_wrinkle_interp_params_default", _InterpParams),
                  ("pleat_cwf_design_params_default", _DesignParams),
                  ("pleat_cwf_edit_params_default", _EditParams)]:
    if getattr(_lib, _fn)().struct_size != _c.sizeof(_cls):
        raise ImportError(f"{_path}: {_cls.__name__} is {getattr(_lib, _fn)().struct_size} bytes "
                          f"in the library, {_c.sizeof(_cls)} in this module")

# PLEAT_LOD_* flags, PLEAT_CHECK_* flags, PLEAT_WRINKLE_FIELD_* bits and doubles per element.
_LOD_NO_ALIGN, _LOD_MEASURE_FLOOR, _LOD_NO_FIT = 1, 2, 8
_CHECK_SKIP_SELF_INTERSECTIONS, _CHECK_WELD = 1, 2
_FIELDS = {"amplitude": (1, 1), "phase": (2, 1), "normals": (4, 3), "z": (8, 2),
           "smooth_positions": (16, 3), "omega": (32, 1)}
_HESSIAN = {"projected": 0, "gauss_newton": 1, "exact": 2, "trust_region": 3}
_STOP = {0: "converged", 1: "iteration_cap", 2: "stalled", 3: "identical_keyframes",
         4: "no_unknowns"}


def _check(status):
    if status != 0:
        raise PleatError(status, last_error())


def last_error():
    """The message of the last failed pleat call on this thread ('' after a success)."""
    return _lib.pleat_last_error().decode("utf-8", "replace")


def version():
    """The library version (``major.minor.patch``, Cargo.toml's; also the package version)."""
    return _lib.pleat_version().decode()


#: The package version: the loaded library's ``pleat_version()``, which is Cargo.toml's version,
#: the wheel's metadata version (setup.py reads Cargo.toml), ``pleat --version`` and the
#: pkg-config/CMake version of ``packaging/install.sh`` (tests/version.rs, .ci/packaging.sh).
__version__ = version()


def abi_version():
    """The C ABI version of the loaded library (equals ``ABI_VERSION``, checked at import)."""
    return int(_lib.pleat_abi_version())


def library_path():
    """The path (or system name) of the loaded shared library."""
    return _path


def set_thread_count(n):
    """Worker threads for later calls (0 = one per core); results do not depend on it."""
    _check(_lib.pleat_set_thread_count(int(n)))


def thread_count():
    """Worker threads the next call will use (>= 1)."""
    return int(_lib.pleat_thread_count())


def has_feature(name):
    """True when this build of the library includes capability ``name`` ("lod", "cage",
    "wrinkle", "tfw", "io-gltf", "bake"); without it those calls raise PleatError UNSUPPORTED."""
    return bool(_lib.pleat_has_feature(name.encode()))


# --- helpers -------------------------------------------------------------------------------

def _ptr(a, ctype):
    """ctypes pointer to the data of the contiguous numpy array ``a`` (kept alive by caller)."""
    return a.ctypes.data_as(_c.POINTER(ctype))


def _doubles(values, n, what):
    """``values`` as a contiguous float64 array of exactly ``n`` elements (any shape)."""
    a = _np.ascontiguousarray(values, dtype=_np.float64).reshape(-1)
    if a.size != n:
        raise PleatError(1, f"{what}: {a.size} values given, {n} needed")
    return a if n else _np.zeros(1)


def _indices(values, what):
    """``values`` as a contiguous uint32 array; integers outside [0, 2^32) are an error."""
    a = _np.asarray(values)
    if a.dtype != _np.uint32:
        if a.size and a.dtype.kind not in "iu":
            raise PleatError(1, f"{what}: integer indices needed, got {a.dtype}")
        if a.size and (a.min() < 0 or a.max() > 0xFFFFFFFF):
            raise PleatError(1, f"{what}: indices must be in [0, 2^32)")
    return _np.ascontiguousarray(a, dtype=_np.uint32).reshape(-1)


def _zeta(zeta, n):
    """Unit phases as 2n float64 (re, im): complex array (n,) or float array (n, 2); None."""
    if zeta is None:
        return None
    z = _np.asarray(zeta)
    if _np.iscomplexobj(z):
        z = _np.stack([z.real, z.imag], axis=-1)
    return _doubles(z, 2 * n, "zeta (one complex or (re, im) per vertex)")


def _as_dict(struct, skip=("struct_size",), flags=()):
    """A ctypes struct as a dict; fields named in ``flags`` become bool, arrays tuples."""
    out = {}
    for name, _ in struct._fields_:
        if name in skip:
            continue
        v = getattr(struct, name)
        if name in flags:
            v = bool(v)
        elif hasattr(v, "__len__"):
            v = tuple(v)
        out[name] = v
    return out


class _Relay:
    """Turns ``progress(stage, fraction) -> truthy to cancel`` into a C callback; an exception
    raised by it cancels the call and is re-raised by ``finish``."""

    def __init__(self, progress):
        self.progress = progress
        self.error = None
        self.fn = _PROGRESS_FN(self._call) if progress else _PROGRESS_FN()

    def _call(self, _user, info):
        try:
            stage = info.contents.stage.decode("utf-8", "replace")
            return 1 if self.progress(stage, info.contents.fraction) else 0
        except BaseException as e:  # noqa: BLE001 - re-raised by finish()
            self.error = e
            return 1

    def finish(self, status):
        if self.error is not None:
            raise self.error
        _check(status)


class _Handle:
    """Owner of one pleat handle, released by ``close()``, ``with`` or garbage collection."""

    _destroy = None

    def __init__(self, handle):
        self._h = handle if isinstance(handle, _P) else _P(handle)

    def close(self):
        """Releases the handle now (also done when garbage-collected); idempotent."""
        if self._h:
            getattr(_lib, self._destroy)(self._h)
            self._h = _P()

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


# --- meshes, LODs, cages, offsets ----------------------------------------------------------

_LOD_KEYS = ("max_rounds", "target_faces", "flow_ratio", "epsilon", "theta0_deg", "l0",
             "memory_budget_bytes", "offset_voxel_scale")
_LOD_FLOAT_KEYS = ("flow_ratio", "epsilon", "theta0_deg", "offset_voxel_scale")
_LOD_STATS_FLAGS = ("watertight", "manifold", "self_intersection_free", "encloses_input",
                    "exact_rerun", "target_met", "started_from_input", "started_from_finer",
                    "stalled", "converged", "fit_reverted")
_REPORT_FLAGS = ("is_closed", "is_edge_manifold", "is_manifold", "is_watertight",
                 "consistently_oriented", "self_intersections_checked", "self_intersection_free",
                 "self_intersecting_pair_count_is_lower_bound")


# PleatLodParams::start (PLEAT_LOD_START_*)
_LOD_STARTS = {"auto": 0, "offset": 1, "input": 2}


def _lod_params(screen_size, align=True, measure_floor=False, fit=True, start="auto",
               deformation=None, **kw):
    """PleatLodParams from the defaults and keyword overrides (names of the C fields);
    ``deformation``: a ``Deformation`` (the caller keeps it alive during the call)."""
    p = _lib.pleat_lod_params_default()
    if deformation is not None:
        if not isinstance(deformation, Deformation):
            raise TypeError(f"deformation must be a pleat.Deformation, got "
                            f"{type(deformation).__name__}")
        p.deformation = deformation._h
    unknown = set(kw) - set(_LOD_KEYS)
    if unknown:
        raise TypeError(f"unknown LOD parameter(s) {sorted(unknown)}; known: "
                        f"{sorted(_LOD_KEYS + ('align', 'measure_floor', 'fit', 'start', 'deformation'))}")
    if start not in _LOD_STARTS:
        raise ValueError(f"start must be one of {sorted(_LOD_STARTS)}, got {start!r}")
    p.start = _LOD_STARTS[start]
    if screen_size is not None:
        p.screen_size = float(screen_size)
    for k, v in kw.items():
        setattr(p, k, float(v) if k in _LOD_FLOAT_KEYS else int(v))
    p.flags = ((0 if align else _LOD_NO_ALIGN) | (_LOD_MEASURE_FLOOR if measure_floor else 0)
               | (0 if fit else _LOD_NO_FIT))
    return p


def _new_lod_stats(count=1):
    stats = (_LodStats * count)()
    for s in stats:
        s.struct_size = _c.sizeof(_LodStats)
    return stats


class Mesh(_Handle):
    """An immutable indexed triangle mesh owned by pleat (any soup). Meshes made by an
    operation (``lod``, ``cage``, ``offset``, ``Cwf.evaluate``) carry its report in ``stats``
    (a dict; None otherwise)."""

    _destroy = "pleat_mesh_destroy"

    def __init__(self, handle, stats=None):
        super().__init__(handle)
        self.stats = stats

    @classmethod
    def from_arrays(cls, positions, triangles):
        """From positions (n×3, or flat 3n) and triangle indices (m×3, or flat 3m).
        float32 positions are passed as floats (an (n, 3) view whose rows are strided, such
        as a column slice of an interleaved vertex buffer, is used without a copy); anything
        else is converted to float64."""
        pos = _np.asarray(positions)
        if pos.ndim == 1:
            pos = pos.reshape(-1, 3)
        if pos.ndim != 2 or pos.shape[1] != 3:
            raise PleatError(1, f"positions: shape {pos.shape}, expected (n, 3)")
        tri = _indices(triangles, "triangles")
        h = _P()
        if pos.dtype == _np.float32 and pos.strides[1] == 4 and pos.strides[0] >= 12:
            _check(_lib.pleat_mesh_create_f32(_ptr(pos, _c.c_float), pos.shape[0],
                                              pos.strides[0], _ptr(tri, _c.c_uint32), tri.size,
                                              _c.byref(h)))
        else:
            pos = _np.ascontiguousarray(pos, dtype=_np.float64)
            _check(_lib.pleat_mesh_create_f64(_ptr(pos, _c.c_double), pos.shape[0], 0,
                                              _ptr(tri, _c.c_uint32), tri.size, _c.byref(h)))
        return cls(h)

    @classmethod
    def read(cls, path):
        """Reads .obj, .ply, .off, .stl, .glb/.gltf (the soup as stored)."""
        h = _P()
        _check(_lib.pleat_mesh_read_file(_os.fsencode(path), _c.byref(h)))
        return cls(h)

    def write(self, path):
        """Writes a mesh file; the format follows the extension (.obj/.ply lossless)."""
        _check(_lib.pleat_mesh_write_file(self._h, _os.fsencode(path)))

    @property
    def vertex_count(self):
        """Number of vertices."""
        return int(_lib.pleat_mesh_vertex_count(self._h))

    @property
    def triangle_count(self):
        """Number of triangles."""
        return int(_lib.pleat_mesh_triangle_count(self._h))

    @property
    def edge_count(self):
        """Number of unique edges: the length of per-edge data such as wrinkle omega."""
        return int(_lib.pleat_mesh_edge_count(self._h))

    def positions(self, dtype=_np.float64):
        """Vertex positions, an (n, 3) array of float64 (exact) or float32 (rounded)."""
        n = self.vertex_count
        if _np.dtype(dtype) == _np.float32:
            out = _np.empty((max(n, 1), 3), dtype=_np.float32)
            _check(_lib.pleat_mesh_copy_positions_f32(self._h, _ptr(out, _c.c_float), n, 0))
        else:
            out = _np.empty((max(n, 1), 3), dtype=_np.float64)
            _check(_lib.pleat_mesh_copy_positions_f64(self._h, _ptr(out, _c.c_double), n, 0))
        return out[:n]

    def triangles(self):
        """Triangle indices, an (m, 3) uint32 array."""
        n = self.triangle_count
        out = _np.empty((max(n, 1), 3), dtype=_np.uint32)
        _check(_lib.pleat_mesh_copy_indices(self._h, _ptr(out, _c.c_uint32), 3 * n))
        return out[:n]

    def edges(self):
        """Edges in pleat's numbering, an (e, 2) uint32 array with a < b, sorted by (a, b);
        per-edge values such as omega are integrated from a to b."""
        n = self.edge_count
        out = _np.empty((max(n, 1), 2), dtype=_np.uint32)
        _check(_lib.pleat_mesh_copy_edges(self._h, _ptr(out, _c.c_uint32), n))
        return out[:n]

    def check(self, self_intersections=True, weld=False, progress=None):
        """Validity report as a dict: the fields of PleatMeshReport (counts as int, yes/no as
        bool, bbox_min/bbox_max as tuples). ``weld`` merges exactly coincident vertices first.
        ``progress(stage, fraction)`` is called on this thread after each phase (stage
        "check"); return True to cancel (raises PleatError CANCELLED)."""
        r = _Report()
        r.struct_size = _c.sizeof(_Report)
        flags = (0 if self_intersections else _CHECK_SKIP_SELF_INTERSECTIONS) | \
            (_CHECK_WELD if weld else 0)
        if progress is None:
            _check(_lib.pleat_mesh_check(self._h, flags, _c.byref(r)))
        else:
            relay = _Relay(progress)
            st = _lib.pleat_mesh_check_with_progress(self._h, flags, relay.fn, None,
                                                     _c.byref(r))
            relay.finish(st)
        return _as_dict(r, skip=("struct_size", "reserved"), flags=_REPORT_FLAGS)

    def _bake(self, fn, screen_size, progress, kw):
        p = _lod_params(screen_size, **kw)
        stats = _new_lod_stats()
        relay, out = _Relay(progress), _P()
        st = fn(self._h, _c.byref(p), relay.fn, None, _c.byref(out), stats)
        relay.finish(st)
        return Mesh(out, _as_dict(stats[0], flags=_LOD_STATS_FLAGS))

    def lod(self, screen_size=200.0, progress=None, **params):
        """One LOD for ``screen_size`` pixels covering the bounding-box diagonal: a
        watertight, manifold, self-intersection-free Mesh within about diag/screen_size of
        this one, with ``stats`` (PleatLodStats as a dict). ``params``: ``target_faces``,
        ``max_rounds``, ``flow_ratio``, ``epsilon``, ``theta0_deg``, ``l0``,
        ``memory_budget_bytes``, ``offset_voxel_scale`` (C field names and defaults; 0 =
        automatic), ``align=False`` to skip the feature alignment, ``measure_floor=True`` for
        ``hausdorff_floor_relative``, ``fit=False`` to skip the final fit to this mesh's planes
        (PLEAT_LOD_NO_FIT), ``start="auto"|"offset"|"input"``: the surface the loop starts
        from (the welded input when it is clean for ``auto``; ``stats["started_from_input"]``),
        ``deformation=Deformation(...)``: the skin and morph targets the LOD must follow when
        posed.
        ``progress(stage, fraction)`` is called on this thread; return True to cancel
        (PleatError CANCELLED); an exception it raises comes out of this call."""
        return self._bake(_lib.pleat_lod_generate, screen_size, progress, params)

    def cage(self, screen_size=200.0, progress=None, **params):
        """A cage: like ``lod`` but strictly enclosing this mesh without touching it
        (``stats["encloses_input"]`` is the independent verification)."""
        return self._bake(_lib.pleat_cage_generate, screen_size, progress, params)

    def lod_chain(self, screen_sizes, progress=None, **params):
        """One LOD per screen size (list of Mesh, in the order given); a coarser level starts
        from the next finer level's loop output (before its fit) when its own offset surface
        has the same topology
        (``stats["started_from_finer"]``), so a chain costs less than baking each level alone;
        independent levels run at the same time on more than one thread, with the results of
        one thread (``progress`` is still called on this thread only).
        ``stats["chain_level"]`` is the level's rank, 0 = finest.
        ``params`` as ``lod`` (``target_faces`` is ignored)."""
        sizes = _doubles(screen_sizes, _np.size(screen_sizes), "screen_sizes")
        n = int(_np.size(screen_sizes))
        p = _lod_params(None, **params)
        stats = _new_lod_stats(max(n, 1))
        outs = (_P * max(n, 1))()
        relay = _Relay(progress)
        st = _lib.pleat_lod_generate_chain(self._h, _ptr(sizes, _c.c_double), n, _c.byref(p),
                                           relay.fn, None, outs, stats)
        relay.finish(st)
        return [Mesh(_P(outs[i]), _as_dict(stats[i], flags=_LOD_STATS_FLAGS)) for i in range(n)]

    def offset(self, screen_size=200.0, distance=None, progress=None, features=True,
               remove_interior=True, verify=True, **params):
        """The watertight, manifold, self-intersection-free d-offset surface (LOD stage 1),
        d = diag/screen_size, or ``distance`` in model units when given. ``params``:
        ``voxel_scale``, ``theta0_deg``, ``l0``, ``iso_refinement_steps``,
        ``memory_budget_bytes``. ``stats`` is pleat's JSON stats object as a dict
        (stages, counts, metrics, verified)."""
        p = _lib.pleat_offset_params_default()
        p.screen_size = float(screen_size)
        if distance is not None:
            p.use_absolute_distance, p.distance = 1, float(distance)
        p.features, p.remove_interior, p.verify = int(bool(features)), \
            int(bool(remove_interior)), int(bool(verify))
        known = ("voxel_scale", "theta0_deg", "l0", "iso_refinement_steps", "memory_budget_bytes")
        for k, v in params.items():
            if k not in known:
                raise TypeError(f"unknown offset parameter {k!r}; known: {list(known)}")
            setattr(p, k, float(v) if k in ("voxel_scale", "theta0_deg") else int(v))
        relay, out, stats = _Relay(progress), _P(), _P()
        st = _lib.pleat_offset_surface(self._h, _c.byref(p), relay.fn, None, _c.byref(out),
                                       _c.byref(stats))
        relay.finish(st)
        try:
            return Mesh(out, _stats_json(stats))
        finally:
            _lib.pleat_stats_destroy(stats)

    def __repr__(self):
        return f"<pleat.Mesh {self.vertex_count} vertices, {self.triangle_count} triangles>"


def _stats_json(stats):
    """A PleatStats handle as the dict of its JSON form."""
    need = _sz()
    _check(_lib.pleat_stats_to_json(stats, None, 0, _c.byref(need)))
    buf = _c.create_string_buffer(need.value + 1)
    _check(_lib.pleat_stats_to_json(stats, buf, len(buf), None))
    return _json.loads(buf.value.decode("utf-8"))


# --- wrinkle fields ------------------------------------------------------------------------

_ADJACENCY = {"vertex": 0, "edge": 1}


def grow_faces(base, seed_vertices=(), seed_faces=(), rings=5, adjacency="vertex"):
    """Triangle ids of the region grown from seed vertices/faces by ``rings`` rings (ring 1 =
    the seeds' triangles) across shared vertices or edges; a uint32 array."""
    sv, sf = _indices(seed_vertices, "seed_vertices"), _indices(seed_faces, "seed_faces")
    flags = _np.zeros(max(base.triangle_count, 1), dtype=_np.uint8)
    _check(_lib.pleat_mesh_grow_faces(
        base._h, _ptr(sf, _c.c_uint32) if sf.size else None, sf.size,
        _ptr(sv, _c.c_uint32) if sv.size else None, sv.size, int(rings), _ADJACENCY[adjacency],
        _ptr(flags, _c.c_uint8), None))
    return _np.flatnonzero(flags[:base.triangle_count]).astype(_np.uint32)


class Cwf(_Handle):
    """A complex wrinkle field on a base Mesh: omega per edge (the order of ``base.edges()``,
    integrated from the smaller to the larger vertex, radians), amplitude and unit phase zeta
    per vertex. Needs a library with the ``wrinkle`` capability (else PleatError
    UNSUPPORTED). Immutable."""

    _destroy = "pleat_cwf_destroy"

    @classmethod
    def from_arrays(cls, base, omega, amplitude, zeta=None):
        """omega: one value per edge of ``base.edges()``; amplitude: one per vertex (>= 0);
        zeta: complex (n,) or float (n, 2) per vertex, or None for Knoppel's phase from omega."""
        nv, ne = base.vertex_count, base.edge_count
        om, am, ze = _doubles(omega, ne, "omega"), _doubles(amplitude, nv, "amplitude"), \
            _zeta(zeta, nv)
        h = _P()
        _check(_lib.pleat_cwf_create(base._h, _ptr(om, _c.c_double), ne, _ptr(am, _c.c_double),
                                     None if ze is None else _ptr(ze, _c.c_double), nv,
                                     _c.byref(h)))
        return cls(h)

    @classmethod
    def from_corner_omega(cls, base, corner_omega, amplitude, zeta=None):
        """corner_omega: (m, 3) or 3m values, value i of triangle t integrated from its corner
        i to corner i+1; opposite across shared edges. Otherwise as ``from_arrays``."""
        nv, nc = base.vertex_count, 3 * base.triangle_count
        co, am, ze = _doubles(corner_omega, nc, "corner_omega"), \
            _doubles(amplitude, nv, "amplitude"), _zeta(zeta, nv)
        h = _P()
        _check(_lib.pleat_cwf_create_from_corner_omega(
            base._h, _ptr(co, _c.c_double), nc, _ptr(am, _c.c_double),
            None if ze is None else _ptr(ze, _c.c_double), nv, _c.byref(h)))
        return cls(h)

    @classmethod
    def from_frequency(cls, base, vectors, amplitude, per_face=False, weights="cotan",
                       max_iterations=None, tolerance=None, shift=None):
        """Wave vectors (k, 3) in radians per length unit, one per vertex (or per triangle
        with ``per_face=True``); zeta by Knoppel et al. 2015 (``weights`` "cotan" or
        "edge_area"); ``knoppel_report()`` tells how the solve went."""
        nv = base.vertex_count
        n = base.triangle_count if per_face else nv
        p = _lib.pleat_knoppel_params_default()
        p.weights = {"cotan": 0, "edge_area": 1}[weights]
        if max_iterations is not None:
            p.max_iterations = int(max_iterations)
        if tolerance is not None:
            p.tolerance = float(tolerance)
        if shift is not None:
            p.shift = float(shift)
        vec, am = _doubles(vectors, 3 * n, "vectors"), _doubles(amplitude, nv, "amplitude")
        h = _P()
        _check(_lib.pleat_cwf_create_from_frequency(
            base._h, _ptr(vec, _c.c_double), n, 1 if per_face else 0, _ptr(am, _c.c_double), nv,
            _c.byref(p), _c.byref(h)))
        return cls(h)

    @classmethod
    def plane_wave(cls, base, k, amplitude):
        """The global wave exp(i k.x): omega_ab = k.x_b - k.x_a, zeta = exp(i k.x);
        ``amplitude`` a number or one per vertex."""
        phase = base.positions() @ _np.asarray(k, dtype=_np.float64)
        e = base.edges().astype(_np.intp)
        omega = phase[e[:, 1]] - phase[e[:, 0]]
        amp = _np.broadcast_to(_np.asarray(amplitude, dtype=_np.float64), phase.shape)
        return cls.from_arrays(base, omega, amp, _np.exp(1j * phase))

    @classmethod
    def read(cls, base, path):
        """Reads a .cwf file written for ``base`` (same connectivity)."""
        h = _P()
        _check(_lib.pleat_cwf_read_file(base._h, _os.fsencode(path), _c.byref(h)))
        return cls(h)

    def write(self, path):
        """Writes the .cwf text file (lossless)."""
        _check(_lib.pleat_cwf_write_file(self._h, _os.fsencode(path)))

    @property
    def vertex_count(self):
        """Vertices of the base mesh."""
        return int(_lib.pleat_cwf_vertex_count(self._h))

    @property
    def edge_count(self):
        """Edges of the base mesh (the length of omega)."""
        return int(_lib.pleat_cwf_edge_count(self._h))

    @property
    def triangle_count(self):
        """Triangles of the base mesh."""
        return int(_lib.pleat_cwf_triangle_count(self._h))

    @classmethod
    def design(cls, base, sources, adjacency="vertex", pin_sources=True, heat_time=1.0,
               kappa=1.0, gamma=1.0, data_weight=1.0, progress=None):
        """A keyframe designed from sources (dissertation 3.6.1): ``sources`` is a list of
        ``(vertex, (kx, ky, kz), amplitude, rings)``; omega by the vector heat method,
        amplitude by eq. 3.25, phase by Knoppel; zero outside the sources' regions.
        ``progress(stage, fraction)`` is called on this thread after each step (stage
        "design"); return True to cancel (raises PleatError CANCELLED)."""
        arr = (_WrinkleSource * max(len(sources), 1))()
        for i, (v, k, a, rings) in enumerate(sources):
            arr[i].vertex, arr[i].rings, arr[i].amplitude = int(v), int(rings), float(a)
            arr[i].wave_vector[:] = [float(x) for x in k]
        p = _lib.pleat_cwf_design_params_default()
        p.adjacency = _ADJACENCY[adjacency]
        p.pin_sources = 1 if pin_sources else 0
        p.heat_time, p.kappa, p.gamma, p.data_weight = heat_time, kappa, gamma, data_weight
        h, relay = _P(), _Relay(progress)
        st = _lib.pleat_cwf_design_with_progress(base._h, arr, len(sources), _c.byref(p), None,
                                                 relay.fn, None, _c.byref(h))
        relay.finish(st)
        return cls(h)

    def edit(self, regions, adjacency="vertex", phase="unit", eps_omega=1e-3,
             eps_amplitude=1e-3, gamma=1.0, compat_target=0.3, max_interface_rings=8,
             edit_weight=1.0, progress=None):
        """Region edits (dissertation 3.6.2): ``regions`` is a list of dicts with ``faces``
        (triangle ids, e.g. from ``grow_faces``) and optional ``interface_rings`` (3),
        ``rotate`` (radians, 0), ``frequency_scale`` (1), ``amplitude_scale`` (1). Returns
        ``(edited Cwf, labels)``: labels per triangle, 0 fixed, 1 edit, 2 interface.

        ``compat_target`` (radians, default 0.3, 0 = off): widen every interface band by one ring while the
        compatibility RMS over edit + interface edges exceeds it, up to ``max_interface_rings``;
        the edited Cwf's ``edit_report()`` says which widths were used. ``edit_weight`` (>= 1)
        weights the edit edges' compatibility terms in the phase solve (eq. 3.28).
        ``progress(stage, fraction)`` is called on this thread after each step (stage "edit");
        return True to cancel (raises PleatError CANCELLED)."""
        keep = []
        arr = (_RegionEdit * max(len(regions), 1))()
        for i, r in enumerate(regions):
            faces = _indices(r["faces"], "faces")
            keep.append(faces)
            arr[i].struct_size = _c.sizeof(_RegionEdit)
            arr[i].interface_rings = int(r.get("interface_rings", 3))
            arr[i].faces = _ptr(faces, _c.c_uint32) if faces.size else None
            arr[i].face_count = faces.size
            arr[i].rotate_radians = float(r.get("rotate", 0.0))
            arr[i].frequency_scale = float(r.get("frequency_scale", 1.0))
            arr[i].amplitude_scale = float(r.get("amplitude_scale", 1.0))
        p = _lib.pleat_cwf_edit_params_default()
        p.adjacency = _ADJACENCY[adjacency]
        p.phase = {"unit": 0, "amplitude_weighted": 1}[phase]
        p.eps_omega, p.eps_amplitude, p.gamma = eps_omega, eps_amplitude, gamma
        p.edit_weight, p.compat_target = float(edit_weight), float(compat_target)
        p.max_interface_rings = int(max_interface_rings)
        labels = _np.zeros(max(self.triangle_count, 1), dtype=_np.uint8)
        h, relay = _P(), _Relay(progress)
        st = _lib.pleat_cwf_edit_with_progress(self._h, arr, len(regions), _c.byref(p), relay.fn,
                                               None, _c.byref(h), _ptr(labels, _c.c_uint8))
        relay.finish(st)
        return Cwf(h), labels[:self.triangle_count]

    def edit_report(self):
        """dict of what ``edit`` did for this (edited) field: ``interface_rings`` (width used
        per region), ``attempts``, ``compat_rms`` (edit + interface edges, radians),
        ``compat_rms_edit``, ``compat_rms_interface``, ``compat_floor``, class counts, each
        solve's residual and ``seconds``; PleatError INVALID_ARGUMENT when the field was not
        made by ``edit``."""
        r = _EditReport()
        r.struct_size = _c.sizeof(r)
        _check(_lib.pleat_cwf_get_edit_report(self._h, _c.byref(r)))
        d = _as_dict(r, flags=("global", "phase_fallback"))
        rings = _np.zeros(max(r.region_count, 1), dtype=_np.uint32)
        _check(_lib.pleat_cwf_copy_edit_interface_rings(self._h, _ptr(rings, _c.c_uint32),
                                                        rings.size))
        d["interface_rings"] = [int(w) for w in rings[:r.region_count]]
        return d

    def _copy(self, fn, n, per=1):
        out = _np.empty(max(per * n, 1), dtype=_np.float64)
        _check(fn(self._h, _ptr(out, _c.c_double), n))
        return out[:per * n]

    def omega(self):
        """omega per edge of ``base.edges()`` (radians), float64 array."""
        return self._copy(_lib.pleat_cwf_copy_omega, self.edge_count)

    def corner_omega(self):
        """omega per triangle corner, an (m, 3) array (corner i to i+1)."""
        return self._copy(_lib.pleat_cwf_copy_corner_omega,
                          3 * self.triangle_count).reshape(-1, 3)

    def amplitude(self):
        """Amplitude per vertex, float64 array."""
        return self._copy(_lib.pleat_cwf_copy_amplitude, self.vertex_count)

    def zeta(self):
        """Unit phase per vertex, complex128 array (0 at a singularity)."""
        return self._copy(_lib.pleat_cwf_copy_zeta, self.vertex_count, 2).view(_np.complex128)

    def knoppel_report(self):
        """dict (iterations, eigenvalue, residual, shift) of the phase solve; PleatError
        INVALID_ARGUMENT when the phase was given rather than computed."""
        r = _KnoppelReport()
        r.struct_size = _c.sizeof(r)
        _check(_lib.pleat_cwf_get_knoppel_report(self._h, _c.byref(r)))
        return _as_dict(r)

    def _evaluate(self, fields, levels, displacement_scale, smooth_boundary, corner_angle,
                  progress, max_output_triangles):
        p = _lib.pleat_wrinkle_eval_params_default()
        p.levels = int(levels)
        p.displacement_scale = float(displacement_scale)
        p.boundary = 1 if smooth_boundary else 0
        if corner_angle is not None:
            p.corner_angle = float(corner_angle)
        if max_output_triangles is not None:
            p.max_output_triangles = int(max_output_triangles)
        for f in fields:
            if f not in _FIELDS:
                raise PleatError(1, f"unknown field {f!r}; known: {sorted(_FIELDS)}")
            p.flags |= _FIELDS[f][0]
        relay, mesh, out_fields = _Relay(progress), _P(), _P()
        stats = _EvalStats()
        stats.struct_size = _c.sizeof(stats)
        st = _lib.pleat_cwf_evaluate(self._h, _c.byref(p), relay.fn, None, _c.byref(mesh),
                                     _c.byref(out_fields) if fields else None, _c.byref(stats))
        relay.finish(st)
        result = {}
        try:
            for f in fields:
                bit, comps = _FIELDS[f]
                n = _lib.pleat_wrinkle_fields_count(out_fields, bit)
                buf = _np.empty((max(n, 1), comps), dtype=_np.float64)
                _check(_lib.pleat_wrinkle_fields_copy(out_fields, bit, _ptr(buf, _c.c_double),
                                                      n, 0))
                buf = buf[:n]
                result[f] = buf[:, 0].copy() if comps == 1 else \
                    buf.view(_np.complex128)[:, 0].copy() if comps == 2 else buf
        finally:
            _lib.pleat_wrinkle_fields_destroy(out_fields)
        return Mesh(mesh, _as_dict(stats)), result

    def evaluate(self, levels=3, displacement_scale=1.0, smooth_boundary=False, corner_angle=None,
                 progress=None, max_output_triangles=None):
        """The wrinkled Mesh after ``levels`` Loop refinements, with ``stats``
        (PleatWrinkleEvalStats). ``progress(stage, fraction)`` is called after each level;
        return True to cancel (PleatError CANCELLED)."""
        return self._evaluate((), levels, displacement_scale, smooth_boundary, corner_angle,
                              progress, max_output_triangles)[0]

    def evaluate_fields(self, fields, levels=3, displacement_scale=1.0, smooth_boundary=False,
                        corner_angle=None, progress=None, max_output_triangles=None):
        """(Mesh, dict of arrays): the wrinkled mesh and the requested fields: "amplitude",
        "phase" (radians), "omega" (per edge of the output's ``edges()``) as (n,) float64;
        "z" as (n,) complex128; "normals", "smooth_positions" as (n, 3) float64."""
        return self._evaluate(tuple(fields), levels, displacement_scale, smooth_boundary,
                              corner_angle, progress, max_output_triangles)

    def interpolate(self, other, guide_frames=None, substeps=None, max_iterations=None,
                    c_scale=None, gradient_tolerance=None, hessian=None, progress=None,
                    locality=True):
        """The Animation from this keyframe (t = 0) to ``other`` (t = 1) on the same base mesh
        (dissertation §3.4). Unset parameters keep the C defaults (50 guide frames, 4
        substeps, 200 iterations, c_scale 1000, tolerance 1e-6, hessian "trust_region"; also
        "projected", "gauss_newton", "exact"). ``locality`` (default True) holds vertices
        whose star is the same in both keyframes (an edit's fixed part) at their keyframe
        phase; False solves every vertex. ``progress`` is called after each Newton
        iteration; True cancels."""
        p = _lib.pleat_wrinkle_interp_params_default()
        for name, v in (("guide_frames", guide_frames), ("substeps", substeps),
                        ("max_iterations", max_iterations)):
            if v is not None:
                setattr(p, name, int(v))
        if c_scale is not None:
            p.c_scale = float(c_scale)
        if gradient_tolerance is not None:
            p.gradient_tolerance = float(gradient_tolerance)
        if hessian is not None:
            p.hessian = _HESSIAN[hessian]
        p.locality = 1 if locality else 0
        stats = _InterpStats()
        stats.struct_size = _c.sizeof(stats)
        relay, out = _Relay(progress), _P()
        st = _lib.pleat_cwf_interpolate(self._h, other._h, _c.byref(p), relay.fn, None,
                                        _c.byref(out), _c.byref(stats))
        relay.finish(st)
        d = _as_dict(stats)
        d["stop_reason"] = _STOP.get(d["stop_reason"], d["stop_reason"])
        return Animation(out, d)

    def __repr__(self):
        return f"<pleat.Cwf on {self.vertex_count} vertices, {self.edge_count} edges>"


class Animation(_Handle):
    """A wrinkle animation between two keyframes (``Cwf.interpolate`` or ``Animation.read``):
    ``frame(t)`` gives the field at any t in [0, 1]. ``stats`` holds the solve's report
    (None when read from a file). Immutable."""

    _destroy = "pleat_cwf_animation_destroy"

    def __init__(self, handle, stats=None):
        super().__init__(handle)
        self.stats = stats

    @classmethod
    def read(cls, base, path):
        """Reads a .cwfa file written for ``base``."""
        h = _P()
        _check(_lib.pleat_cwf_animation_read_file(base._h, _os.fsencode(path), _c.byref(h)))
        return cls(h)

    def write(self, path):
        """Writes the .cwfa text file (lossless)."""
        _check(_lib.pleat_cwf_animation_write_file(self._h, _os.fsencode(path)))

    @property
    def frame_count(self):
        """Playback frames, guide_frames * substeps + 1; frame i is at t = i / (count - 1)."""
        return int(_lib.pleat_cwf_animation_frame_count(self._h))

    @property
    def guide_count(self):
        """Guide intervals N' (there are N' + 1 guide frames)."""
        return int(_lib.pleat_cwf_animation_guide_count(self._h))

    def frame(self, t):
        """The wrinkle field (Cwf) at time t in [0, 1]; 0 and 1 give the keyframes exactly."""
        h = _P()
        _check(_lib.pleat_cwf_animation_frame(self._h, float(t), _c.byref(h)))
        return Cwf(h)

    def frames(self):
        """Every playback frame, in order (a generator of Cwf)."""
        n = self.frame_count
        for i in range(n):
            yield self.frame(i / (n - 1) if n > 1 else 0.0)

    def history(self):
        """Convergence history, a (k, 2) array of (wall seconds since the start, normalized
        gradient norm): error against run time. Empty for an animation read from a file."""
        n = int(_lib.pleat_cwf_animation_history_count(self._h))
        out = _np.empty((max(n, 1), 2), dtype=_np.float64)
        _check(_lib.pleat_cwf_animation_copy_history(self._h, _ptr(out, _c.c_double), n))
        return out[:n]



# --- textured LODs: provenance and bake (capability "bake") --------------------------------

_ProvParams = _struct("PleatProvenanceParams", _u32s("struct_size", "reserved")
                      + _f64s("screen_size", "envelope_d", "envelope"))
_Image = _struct("PleatImage", [("rgba", _c.c_void_p)]
                 + _u32s("width", "height", "srgb", "reserved"))
_BakeMaterial = _struct("PleatBakeMaterial", _u32s("struct_size", "uv_layout")
                        + [("uvs", _F), ("uv_count", _sz), ("normals", _F), ("colors", _F),
                           ("base_color_factor", _c.c_double * 4), ("base_color", _Image)]
                        + _f64s("metallic_factor", "roughness_factor")
                        + [("metallic_roughness", _Image), ("normal", _Image)]
                        + _f64s("normal_scale") + [("occlusion", _Image)]
                        + _f64s("occlusion_strength")
                        + [("emissive_factor", _c.c_double * 3), ("emissive", _Image)]
                        + _u32s("wrap", "reserved"))
_BakeParams = _struct("PleatBakeParams", _u32s("struct_size", "texture_size")
                      + _f64s("screen_size") + _u32s("padding", "threads")
                      + _f64s("texels_per_pixel", "envelope_d")
                      + _u32s("normal_map", "error_samples", "vertex_colors", "reserved"))
_BakeStats = _struct("PleatBakeStats", _u32s("struct_size", "flags", "texture_size", "charts")
                     + _u64s("texels_covered", "overlapping_texels", "vertex_count",
                             "triangle_count")
                     + _f64s("seconds_total", "seconds_atlas", "seconds_tangents",
                             "seconds_rasterise", "seconds_sample", "seconds_dilate",
                             "seconds_measure", "fallback_fraction", "appearance_error_mean",
                             "appearance_error_p95", "appearance_error_max")
                     + _u32s("atlas_padding") + [("seam_clean_mip", _c.c_int32)])
_B = _c.POINTER(_c.c_uint8)
for _name, _res, _args in [
    ("pleat_provenance_params_default", _ProvParams, ()),
    ("pleat_bake_material_default", _BakeMaterial, ()),
    ("pleat_bake_params_default", _BakeParams, ()),
    ("pleat_lod_provenance", _st, (_P, _P, _c.POINTER(_ProvParams), _U, _sz, _D, _sz, _B, _sz)),
    ("pleat_points_provenance", _st, (_P, _D, _D, _sz, _c.POINTER(_ProvParams), _U, _sz, _D,
                                      _sz, _B, _sz)),
    ("pleat_bake_lod", _st, (_P, _P, _c.POINTER(_BakeMaterial), _c.POINTER(_BakeParams))
     + _PROGRESS_ARGS + (_PP, _c.POINTER(_BakeStats))),
    ("pleat_bake_lod_multi", _st, (_P, _P, _c.POINTER(_BakeMaterial), _sz, _U, _sz,
                                   _c.POINTER(_BakeParams))
     + _PROGRESS_ARGS + (_PP, _c.POINTER(_BakeStats))),
    ("pleat_bake_free", None, (_P,)),
    ("pleat_bake_vertex_count", _sz, (_P,)),
    ("pleat_bake_triangle_count", _sz, (_P,)),
    ("pleat_bake_get_stats", _st, (_P, _c.POINTER(_BakeStats))),
    ("pleat_bake_copy_positions", _st, (_P, _D, _sz)),
    ("pleat_bake_copy_indices", _st, (_P, _U, _sz)),
    ("pleat_bake_copy_uvs", _st, (_P, _F, _sz)),
    ("pleat_bake_copy_normals", _st, (_P, _F, _sz)),
    ("pleat_bake_copy_tangents", _st, (_P, _F, _sz)),
    ("pleat_bake_copy_colors", _st, (_P, _F, _sz)),
    ("pleat_bake_image_size", _st, (_P, _u32, _U, _U)),
    ("pleat_bake_copy_image", _st, (_P, _u32, _B, _sz)),
    ("pleat_bake_write_glb", _st, (_P, _c.c_char_p)),
]:
    _sig(_name, _res, *_args)
for _fn, _cls in [("pleat_provenance_params_default", _ProvParams),
                  ("pleat_bake_material_default", _BakeMaterial),
                  ("pleat_bake_params_default", _BakeParams)]:
    if getattr(_lib, _fn)().struct_size != _c.sizeof(_cls):
        raise ImportError(f"{_path}: {_cls.__name__} is {getattr(_lib, _fn)().struct_size} bytes "
                          f"in the library, {_c.sizeof(_cls)} in this module")

#: Names of the baked images (``Bake.image``), PLEAT_BAKE_IMAGE_* values.
BAKE_IMAGES = {"base_color": 0, "metallic_roughness": 1, "occlusion": 2, "emissive": 3,
               "normal": 4}
_WRAP = {"repeat": 0, "clamp": 1, "mirror": 2}


def _prov_params(screen_size, envelope_d, envelope):
    p = _lib.pleat_provenance_params_default()
    p.screen_size, p.envelope_d, p.envelope = float(screen_size), float(envelope_d), \
        float(envelope)
    return p


def _provenance(n, call):
    """Runs a provenance call into fresh arrays: (tri (n,), bary (n, 3), by_ray (n,) bool)."""
    tri = _np.zeros(max(n, 1), dtype=_np.uint32)
    bary = _np.zeros((max(n, 1), 3), dtype=_np.float64)
    flags = _np.zeros(max(n, 1), dtype=_np.uint8)
    _check(call(_ptr(tri, _c.c_uint32), n, _ptr(bary, _c.c_double), 3 * n,
                _ptr(flags, _c.c_uint8), n))
    return tri[:n], bary[:n], flags[:n].astype(bool)


def lod_provenance(lod, input, screen_size=200.0, envelope_d=3.0, envelope=0.0):
    """For every vertex of ``lod`` (a Mesh made from ``input`` at ``screen_size``): the input
    triangle ``tri[i]`` and barycentric coordinates ``bary[i]`` of the point it stands for,
    found by casting along the LOD's vertex normal within ``envelope_d · diag / screen_size``
    (or ``envelope`` model units when > 0), ``by_ray[i]`` False where the closest point was
    taken instead. Transfer any per-vertex attribute A of the input with
    ``(A[input_triangles[tri]] * bary[..., None]).sum(1)``."""
    p = _prov_params(screen_size, envelope_d, envelope)
    return _provenance(lod.vertex_count, lambda *out: _lib.pleat_lod_provenance(
        lod._h, input._h, _c.byref(p), *out))


def points_provenance(input, points, normals=None, screen_size=200.0, envelope_d=3.0,
                      envelope=0.0):
    """As ``lod_provenance`` for arbitrary points (n, 3) cast along ``normals`` (n, 3); without
    normals (or where a normal is zero) the closest input point."""
    pts = _np.ascontiguousarray(points, dtype=_np.float64).reshape(-1, 3)
    n = pts.shape[0]
    nrm = None if normals is None else _doubles(normals, 3 * n, "normals (one xyz per point)")
    p = _prov_params(screen_size, envelope_d, envelope)
    return _provenance(n, lambda *out: _lib.pleat_points_provenance(
        input._h, _ptr(pts if n else _np.zeros((1, 3)), _c.c_double),
        None if nrm is None else _ptr(nrm, _c.c_double), n, _c.byref(p), *out))


def _floats(values, k, n, what):
    """``values`` as contiguous float32 of exactly n×k elements (None passes through)."""
    if values is None:
        return None
    a = _np.ascontiguousarray(values, dtype=_np.float32).reshape(-1)
    if a.size != n * k:
        raise PleatError(1, f"{what}: {a.size} values given, {n * k} needed")
    return a


def _image(img, srgb, keep):
    """A PleatImage over an (h, w, 4) or (h, w, 3) uint8 array (kept alive in ``keep``)."""
    out = _Image()
    if img is None:
        return out
    a = _np.asarray(img)
    if a.dtype != _np.uint8 or a.ndim != 3 or a.shape[2] not in (3, 4):
        raise PleatError(1, f"images must be (h, w, 4) or (h, w, 3) uint8, got {a.dtype} "
                            f"{a.shape}")
    if a.shape[2] == 3:
        a = _np.concatenate([a, _np.full(a.shape[:2] + (1,), 255, _np.uint8)], axis=2)
    a = _np.ascontiguousarray(a)
    keep.append(a)
    out.rgba = a.ctypes.data
    out.height, out.width = a.shape[0], a.shape[1]
    out.srgb = 1 if srgb else 0
    return out


class Bake(_Handle):
    """A LOD with the input's appearance baked on (``bake``): mesh arrays with the atlas UVs
    (the atlas splits vertices at chart seams), MikkTSpace tangents and RGBA8 images, or vertex
    colours when the input had no image. ``stats`` is PleatBakeStats as a dict (``atlas_padding``
    in texels, ``seam_clean_mip`` the deepest clean mip or None). Immutable."""

    _destroy = "pleat_bake_free"

    def __init__(self, handle, stats=None):
        super().__init__(handle)
        self.stats = stats

    @property
    def vertex_count(self):
        """Vertices of the baked mesh."""
        return int(_lib.pleat_bake_vertex_count(self._h))

    @property
    def triangle_count(self):
        """Triangles of the baked mesh."""
        return int(_lib.pleat_bake_triangle_count(self._h))

    @property
    def textured(self):
        """True when the bake has UVs, tangents and images (False: vertex colours)."""
        return bool(self.stats["flags"] & 1)

    def _copy(self, fn, k, dtype, ctype):
        n = self.vertex_count
        out = _np.empty((max(n, 1), k), dtype=dtype)
        _check(fn(self._h, _ptr(out, ctype), n))
        return out[:n]

    def positions(self):
        """(n, 3) float64 vertex positions."""
        return self._copy(_lib.pleat_bake_copy_positions, 3, _np.float64, _c.c_double)

    def triangles(self):
        """(m, 3) uint32 triangles."""
        m = self.triangle_count
        out = _np.empty((max(m, 1), 3), dtype=_np.uint32)
        _check(_lib.pleat_bake_copy_indices(self._h, _ptr(out, _c.c_uint32), 3 * m))
        return out[:m]

    def uvs(self):
        """(n, 2) float32 atlas UVs in [0, 1] (v = 0 at the images' top row)."""
        return self._copy(_lib.pleat_bake_copy_uvs, 2, _np.float32, _c.c_float)

    def normals(self):
        """(n, 3) float32 unit vertex normals."""
        return self._copy(_lib.pleat_bake_copy_normals, 3, _np.float32, _c.c_float)

    def tangents(self):
        """(n, 4) float32 MikkTSpace tangents (glTF TANGENT: xyz, handedness w)."""
        return self._copy(_lib.pleat_bake_copy_tangents, 4, _np.float32, _c.c_float)

    def colors(self):
        """(n, 4) float32 linear RGBA vertex colours (untextured bakes only)."""
        return self._copy(_lib.pleat_bake_copy_colors, 4, _np.float32, _c.c_float)

    def image(self, which="base_color"):
        """Baked image ``which`` (a key of BAKE_IMAGES) as (h, w, 4) uint8, or None when this
        bake has none."""
        code = BAKE_IMAGES[which]
        w, h = _c.c_uint32(), _c.c_uint32()
        _check(_lib.pleat_bake_image_size(self._h, code, _c.byref(w), _c.byref(h)))
        if w.value == 0:
            return None
        out = _np.empty((h.value, w.value, 4), dtype=_np.uint8)
        _check(_lib.pleat_bake_copy_image(self._h, code, _ptr(out, _c.c_uint8), out.size))
        return out

    def write_glb(self, path):
        """Writes the bake as a .glb (mesh, material, embedded PNG textures)."""
        _check(_lib.pleat_bake_write_glb(self._h, _os.fsencode(path)))

    def __repr__(self):
        return f"<pleat.Bake {self.vertex_count} vertices, {self.triangle_count} triangles>"


#: The per-material keywords of ``bake`` (also the keys of its ``materials`` dicts).
_MATERIAL_KEYS = ("base_color", "base_color_factor", "metallic_factor", "roughness_factor",
                  "metallic_roughness", "normal", "normal_scale", "occlusion",
                  "occlusion_strength", "emissive", "emissive_factor", "wrap")


def _fill_material(m, keep, base_color=None, base_color_factor=(1.0, 1.0, 1.0, 1.0),
                   metallic_factor=1.0, roughness_factor=1.0, metallic_roughness=None,
                   normal=None, normal_scale=1.0, occlusion=None, occlusion_strength=1.0,
                   emissive=None, emissive_factor=(0.0, 0.0, 0.0), wrap="repeat"):
    """Sets the factors, images and wrap mode of a PleatBakeMaterial (arrays kept alive in
    ``keep``)."""
    m.base_color_factor[:] = [float(x) for x in base_color_factor]
    m.emissive_factor[:] = [float(x) for x in emissive_factor]
    m.metallic_factor, m.roughness_factor = float(metallic_factor), float(roughness_factor)
    m.normal_scale, m.occlusion_strength = float(normal_scale), float(occlusion_strength)
    m.base_color = _image(base_color, True, keep)
    m.emissive = _image(emissive, True, keep)
    m.metallic_roughness = _image(metallic_roughness, False, keep)
    m.occlusion = _image(occlusion, False, keep)
    m.normal = _image(normal, False, keep)
    if wrap not in _WRAP:
        raise PleatError(1, f"wrap must be one of {sorted(_WRAP)}, got {wrap!r}")
    m.wrap = _WRAP[wrap]


_VERTEX_COLORS = {"auto": 0, "vertex": 1, "texture": 2}


def bake(lod, input, uvs=None, base_color=None, *, uv_layout="vertex", normals=None,
         colors=None, base_color_factor=(1.0, 1.0, 1.0, 1.0), metallic_factor=1.0,
         roughness_factor=1.0, metallic_roughness=None, normal=None, normal_scale=1.0,
         occlusion=None, occlusion_strength=1.0, emissive=None, emissive_factor=(0.0, 0.0, 0.0),
         wrap="repeat", screen_size=200.0, texture_size=0, padding=None, threads=0,
         texels_per_pixel=2.0, envelope_d=3.0, normal_map=True, error_samples=20000,
         vertex_colors="auto", progress=None, materials=None, triangle_material=None):
    """Bakes ``input``'s appearance onto ``lod`` (a Mesh made from it at ``screen_size``):
    returns a Bake.

    - ``uvs``: (n, 2) per input vertex (``uv_layout="vertex"``) or (3m, 2) per triangle
      corner (``"corner"``); glTF convention (v = 0 at the image's top row).
    - images: (h, w, 4) or (h, w, 3) uint8 arrays; ``base_color`` and ``emissive`` are
      sRGB-encoded, ``metallic_roughness`` (G roughness, B metallic), ``occlusion`` (R) and
      ``normal`` (tangent space) linear, as in glTF.
    - ``normals`` (n, 3), ``colors`` (n, 4 linear RGBA): optional per input vertex.
    - ``texture_size``: 0 for the screen-size rule; ``threads``: 0 for the global setting;
      ``padding``: None for the library's gutter rule.
    - ``vertex_colors``: "auto", "vertex" or "texture" — how ``colors`` without any image
      are baked (auto: vertex colours when the screen size allows, else a texture).
    - ``progress(stage, fraction)``: return True to cancel (raises PleatError CANCELLED).
    - Several materials (``pleat_bake_lod_multi``): ``materials`` a list of dicts with the
      per-material keywords above (``base_color``, ``base_color_factor``, ..., ``wrap``) and
      ``triangle_material`` (m,) indices into it; the call's own material keywords are then
      not used (passing ``base_color`` too is an error). UVs, normals and colours are shared.
    """
    nv, nt = input.vertex_count, input.triangle_count
    m = _lib.pleat_bake_material_default()
    keep = []
    if uv_layout not in ("vertex", "corner"):
        raise PleatError(1, f"uv_layout must be 'vertex' or 'corner', got {uv_layout!r}")
    m.uv_layout = 0 if uv_layout == "vertex" else 1
    if uvs is not None:
        count = nv if uv_layout == "vertex" else 3 * nt
        a = _floats(uvs, 2, count, f"uvs (one (u, v) per {uv_layout})")
        keep.append(a)
        m.uvs, m.uv_count = _ptr(a, _c.c_float), count
    for field, values, k in (("normals", normals, 3), ("colors", colors, 4)):
        a = _floats(values, k, nv, f"{field} (one per input vertex)")
        if a is not None:
            keep.append(a)
            setattr(m, field, _ptr(a, _c.c_float))
    p = _lib.pleat_bake_params_default()
    p.screen_size, p.texture_size = float(screen_size), int(texture_size)
    if padding is not None:
        p.padding = int(padding)
    if vertex_colors not in _VERTEX_COLORS:
        raise PleatError(1, f"vertex_colors must be one of {sorted(_VERTEX_COLORS)}, "
                            f"got {vertex_colors!r}")
    p.vertex_colors = _VERTEX_COLORS[vertex_colors]
    p.threads, p.texels_per_pixel, p.envelope_d = int(threads), float(texels_per_pixel), \
        float(envelope_d)
    p.normal_map, p.error_samples = int(bool(normal_map)), int(error_samples)
    stats = _BakeStats()
    stats.struct_size = _c.sizeof(_BakeStats)
    relay, out = _Relay(progress), _P()
    if materials is None:
        if triangle_material is not None:
            raise PleatError(1, "triangle_material needs materials")
        _fill_material(m, keep, base_color, base_color_factor, metallic_factor,
                       roughness_factor, metallic_roughness, normal, normal_scale, occlusion,
                       occlusion_strength, emissive, emissive_factor, wrap)
        st = _lib.pleat_bake_lod(lod._h, input._h, _c.byref(m), _c.byref(p), relay.fn, None,
                                 _c.byref(out), _c.byref(stats))
    else:
        if base_color is not None:
            raise PleatError(1, "pass base_color inside materials when materials is given")
        if triangle_material is None:
            raise PleatError(1, "materials needs triangle_material (one index per triangle)")
        arr = (_BakeMaterial * max(len(materials), 1))()
        for i, fields in enumerate(materials):
            unknown = set(fields) - set(_MATERIAL_KEYS)
            if unknown:
                raise PleatError(1, f"materials[{i}]: unknown keys {sorted(unknown)}")
            arr[i] = m if i == 0 else _lib.pleat_bake_material_default()
            _fill_material(arr[i], keep, **fields)
        tm = _np.ascontiguousarray(triangle_material, dtype=_np.uint32).reshape(-1)
        keep.append(tm)
        st = _lib.pleat_bake_lod_multi(lod._h, input._h, arr, len(materials),
                                       _ptr(tm, _c.c_uint32), tm.size, _c.byref(p), relay.fn,
                                       None, _c.byref(out), _c.byref(stats))
    relay.finish(st)
    del keep
    d = _as_dict(stats)
    if d["seam_clean_mip"] < 0:
        d["seam_clean_mip"] = None  # vertex colours, or even mip 0 mixes charts
    return Bake(out, d)


# --- tension-field wrinkles (capability "tfw") ----------------------------------------------

_TfwParams = _struct("PleatTfwParams",
                     _u32s("struct_size", "sqp_max_iterations", "base_max_iterations",
                           "base_load_steps", "w_rule", "reserved")
                     + _f64s("base_gradient_tolerance", "base_energy_tolerance", "bending_scale",
                             "initial_amplitude", "sqp_stationarity_tolerance",
                             "sqp_energy_tolerance", "sqp_step_tolerance", "sqp_armijo",
                             "sqp_initial_shift", "sqp_time_limit_seconds",
                             "out_of_scope_slack_fraction")
                     + _u32s("curvature", "reserved2", "qp", "reserved3", "snap_periods",
                             "reserved4", "valley_search", "reserved5"))
_TfwMaterial = _struct("PleatTfwMaterial", _u32s("struct_size", "reserved")
                       + _f64s("young", "poisson", "thickness", "density")
                       + [("gravity", _c.c_double * 3)] + _f64s("pressure"))
_TfwStats = _struct("PleatTfwStats",
                    _u32s("struct_size", "status", "base_status", "sqp_status", "base_iterations",
                          "sqp_iterations")
                    + _u64s("vertex_count", "triangle_count", "wrinkle_free_face_count")
                    + _f64s("energy", "initial_energy", "residual", "initial_residual",
                            "curl_residual", "peak_amplitude", "base_relative_gradient",
                            "seconds_base", "seconds_init", "seconds_sqp", "seconds_qp",
                            "seconds_phase")
                    + _u32s("snapped_loops", "snap_kept_loops")
                    + _f64s("snap_max_period_error", "snap_max_correction",
                            "snap_relative_correction")
                    + [("sqp_rescue_iteration", _c.c_int64)])
_TfwObstacle = _struct("PleatTfwObstacle", _u32s("struct_size", "kind")
                       + [("point", _c.c_double * 3), ("normal", _c.c_double * 3)]
                       + _f64s("radius", "stiffness", "margin"))
_TfwWaveCount = _struct("PleatTfwWaveCount", _u32s("struct_size", "closed")
                        + _f64s("waves", "peak_amplitude") + _u64s("samples")
                        + [("point", _c.c_double * 3), ("normal", _c.c_double * 3)]
                        + _f64s("min_radius"))
for _name, _res, _args in [
    ("pleat_tfw_params_default", _TfwParams, ()),
    ("pleat_tfw_obstacle_default", _TfwObstacle, ()),
    ("pleat_tfw_scene_add_obstacle", _st, (_P, _c.POINTER(_TfwObstacle))),
    ("pleat_tfw_result_count_waves", _st, (_P, _u32, _D, _D, _u32,
                                           _c.POINTER(_TfwWaveCount))),
    ("pleat_tfw_material_default", _TfwMaterial, ()),
    ("pleat_tfw_scene_read_file", _st, (_c.c_char_p, _PP)),
    ("pleat_tfw_scene_from_json", _st, (_c.c_char_p, _PP)),
    ("pleat_tfw_scene_from_arrays", _st, (_D, _sz, _U, _sz, _D, _c.POINTER(_TfwMaterial), _U,
                                          _sz, _D, _PP)),
    ("pleat_tfw_scene_destroy", None, (_P,)),
    ("pleat_tfw_solve", _st, (_P, _c.POINTER(_TfwParams)) + _PROGRESS_ARGS + (_PP,)),
    ("pleat_tfw_result_destroy", None, (_P,)),
    ("pleat_tfw_result_base_mesh", _st, (_P, _PP)),
    ("pleat_tfw_result_cwf", _st, (_P, _PP)),
    ("pleat_tfw_result_evaluate", _st, (_P, _c.POINTER(_EvalParams), _u32) + _PROGRESS_ARGS
     + (_PP,)),
    ("pleat_tfw_result_get_stats", _st, (_P, _c.POINTER(_TfwStats))),
    ("pleat_tfw_result_history_count", _sz, (_P,)),
    ("pleat_tfw_result_copy_history", _st, (_P, _D, _sz)),
]:
    _sig(_name, _res, *_args)
for _fn, _cls in [("pleat_tfw_params_default", _TfwParams),
                  ("pleat_tfw_material_default", _TfwMaterial),
                  ("pleat_tfw_obstacle_default", _TfwObstacle)]:
    if getattr(_lib, _fn)().struct_size != _c.sizeof(_cls):
        raise ImportError(f"{_path}: {_cls.__name__} is {getattr(_lib, _fn)().struct_size} bytes "
                          f"in the library, {_c.sizeof(_cls)} in this module")

#: PleatTfwStats.status values.
TFW_STATUS = {0: "converged", 1: "not_converged", 2: "no_compression", 3: "out_of_scope"}
_TFW_W_RULE = {"text": 0, "reference": 1}
_TFW_CURVATURE = {"quadric": 0, "normals": 1}
_TFW_QP = {"clarabel": 0, "newton": 1}
_TFW_MATERIAL_KEYS = ("young", "poisson", "thickness", "density", "gravity", "pressure")


def _tfw_params(w_rule="text", curvature="quadric", qp=None, **kw):
    p = _lib.pleat_tfw_params_default()
    if w_rule not in _TFW_W_RULE:
        raise PleatError(1, f"w_rule {w_rule!r}; known: {sorted(_TFW_W_RULE)}")
    p.w_rule = _TFW_W_RULE[w_rule]
    if curvature not in _TFW_CURVATURE:
        raise PleatError(1, f"curvature {curvature!r}; known: {sorted(_TFW_CURVATURE)}")
    p.curvature = _TFW_CURVATURE[curvature]
    if qp is not None:
        if qp not in _TFW_QP:
            raise PleatError(1, f"qp {qp!r}; known: {sorted(_TFW_QP)}")
        p.qp = _TFW_QP[qp]
    names = {n for n, _ in _TfwParams._fields_} - {"struct_size", "reserved", "w_rule",
                                                    "curvature", "reserved2", "qp",
                                                    "reserved3", "reserved4", "reserved5"}
    for k, v in kw.items():
        if k not in names:
            raise PleatError(1, f"unknown TFW parameter {k!r}; known: {sorted(names)}")
        setattr(p, k, v)
    return p


class TfwScene(_Handle):
    """A validated tension-field wrinkle scene (panels, material, loads, Dirichlet
    conditions; README "Tension-field wrinkles"). Needs the ``tfw`` capability (else
    PleatError UNSUPPORTED). ``add_obstacle()`` adds a plane or sphere; ``solve()`` gives a
    TfwResult."""

    _destroy = "pleat_tfw_scene_destroy"

    @classmethod
    def read(cls, path):
        """Reads a scene file (JSON)."""
        h = _P()
        _check(_lib.pleat_tfw_scene_read_file(_os.fsencode(path), _c.byref(h)))
        return cls(h)

    @classmethod
    def from_json(cls, text):
        """Parses scene JSON text (errors name the field)."""
        h = _P()
        _check(_lib.pleat_tfw_scene_from_json(text.encode("utf-8"), _c.byref(h)))
        return cls(h)

    @classmethod
    def from_arrays(cls, rest, triangles, positions=None, clamped=(), translation=None,
                    **material):
        """One flat panel: rest uv (n×2), triangles (m×3), initial positions (n×3; None = rest
        at z = 0), clamped vertex indices moved by ``translation`` (3 values; None = held in
        place); material keywords: young, poisson, thickness, density, gravity, pressure (SI;
        defaults Y 1 MPa, nu 0.5, h 0.1 mm)."""
        uv = _np.ascontiguousarray(rest, dtype=_np.float64).reshape(-1)
        if uv.size % 2:
            raise PleatError(1, "rest: 2 values per vertex")
        n = uv.size // 2
        tri = _indices(triangles, "triangles")
        if tri.size % 3:
            raise PleatError(1, "triangles: 3 indices per triangle")
        pos = None if positions is None else _doubles(positions, 3 * n, "positions")
        cl = _indices(clamped, "clamped")
        tr = None if translation is None else _doubles(translation, 3, "translation")
        m = _lib.pleat_tfw_material_default()
        for k, v in material.items():
            if k not in _TFW_MATERIAL_KEYS:
                raise PleatError(1, f"unknown material key {k!r}; known: {_TFW_MATERIAL_KEYS}")
            if k == "gravity":
                m.gravity[:] = [float(x) for x in v]
            else:
                setattr(m, k, float(v))
        h = _P()
        _check(_lib.pleat_tfw_scene_from_arrays(
            _ptr(uv, _c.c_double), n, _ptr(tri, _c.c_uint32), tri.size // 3,
            None if pos is None else _ptr(pos, _c.c_double), _c.byref(m),
            _ptr(cl, _c.c_uint32) if cl.size else None, cl.size,
            None if tr is None else _ptr(tr, _c.c_double), _c.byref(h)))
        return cls(h)

    def add_obstacle(self, kind, point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), radius=0.0,
                     stiffness=None, margin=0.0):
        """Adds a rigid obstacle kept out by a penalty in the base solve: ``kind`` "plane"
        (``point``, ``normal`` pointing to the allowed side) or "sphere" (centre ``point``,
        ``radius``); ``stiffness`` J/m^5 (None = the library's 1e9), ``margin`` m. Invalid
        values raise PleatError naming the field; the scene is then unchanged."""
        kinds = {"plane": 0, "sphere": 1}
        if kind not in kinds:
            raise PleatError(1, f"obstacle kind {kind!r}; known: {sorted(kinds)}")
        o = _lib.pleat_tfw_obstacle_default()
        o.kind = kinds[kind]
        o.point[:] = [float(x) for x in point]
        o.normal[:] = [float(x) for x in normal]
        o.radius = float(radius)
        if stiffness is not None:
            o.stiffness = float(stiffness)
        o.margin = float(margin)
        _check(_lib.pleat_tfw_scene_add_obstacle(self._h, _c.byref(o)))

    def solve(self, progress=None, **params):
        """Solves the scene (base surface, wrinkle SQP, phase); keywords are PleatTfwParams
        fields (e.g. ``sqp_max_iterations=50``, ``w_rule="reference"``,
        ``curvature="normals"``, ``qp="newton"`` or ``"clarabel"``, ``snap_periods=1`` to
        snap ω's periods around non-contractible loops to multiples of 2π, ``valley_search=0``
        to turn off the projected Newton's valley search; default: the library's). ``stats``
        of the result then carry ``snapped_loops``, ``snap_max_period_error``, … and
        ``sqp_rescue_iteration`` (−1: none).
        ``progress(stage, fraction)`` returning True cancels (PleatError CANCELLED)."""
        p = _tfw_params(**params)
        relay, h = _Relay(progress), _P()
        st = _lib.pleat_tfw_solve(self._h, _c.byref(p), relay.fn, None, _c.byref(h))
        relay.finish(st)
        return TfwResult(h)


class TfwResult(_Handle):
    """The result of ``TfwScene.solve``: ``stats`` (dict of PleatTfwStats, status as a name),
    the base mesh, the wrinkle field (a Cwf), the wrinkled mesh and the SQP history."""

    _destroy = "pleat_tfw_result_destroy"

    def __init__(self, handle):
        super().__init__(handle)
        s = _TfwStats()
        s.struct_size = _c.sizeof(s)
        _check(_lib.pleat_tfw_result_get_stats(self._h, _c.byref(s)))
        self.stats = _as_dict(s)
        self.stats["status"] = TFW_STATUS.get(self.stats["status"], self.stats["status"])

    def base_mesh(self):
        """The base surface (a Mesh)."""
        h = _P()
        _check(_lib.pleat_tfw_result_base_mesh(self._h, _c.byref(h)))
        return Mesh(h)

    def cwf(self):
        """The complex wrinkle field on the base mesh (a Cwf)."""
        h = _P()
        _check(_lib.pleat_tfw_result_cwf(self._h, _c.byref(h)))
        return Cwf(h)

    def evaluate(self, levels=3, in_plane_v2=True, progress=None):
        """The wrinkled Mesh after ``levels`` Loop refinements (with the in-plane v2 term of
        eq. 2.19 unless ``in_plane_v2`` is False)."""
        p = _lib.pleat_wrinkle_eval_params_default()
        p.levels = int(levels)
        relay, h = _Relay(progress), _P()
        st = _lib.pleat_tfw_result_evaluate(self._h, _c.byref(p), 1 if in_plane_v2 else 0,
                                            relay.fn, None, _c.byref(h))
        relay.finish(st)
        return Mesh(h)

    def count_waves(self, levels=2, point=None, normal=None, closed=False, min_radius=0.0):
        """The library's wave counter on the evaluated field: sign changes of Re z / 2 where
        the smooth surface crosses the plane through ``point`` with ``normal`` (a closed ring
        about ``point`` when ``closed``), or, with both None, the axis plane through the
        bounding-box centre crossing the most waves. Samples closer than ``min_radius`` (m)
        to the line through the point along the normal are dropped (a balloon's outer half:
        half its outer radius). A dict: waves, peak_amplitude (m), samples, closed, point,
        normal, min_radius."""
        if (point is None) != (normal is None):
            raise PleatError(1, "count_waves: give both point and normal, or neither")
        w = _TfwWaveCount()
        w.struct_size = _c.sizeof(w)
        w.min_radius = float(min_radius)
        p = None if point is None else _doubles(point, 3, "point")
        n = None if normal is None else _doubles(normal, 3, "normal")
        _check(_lib.pleat_tfw_result_count_waves(
            self._h, int(levels), None if p is None else _ptr(p, _c.c_double),
            None if n is None else _ptr(n, _c.c_double), 1 if closed else 0, _c.byref(w)))
        d = _as_dict(w)
        d["closed"] = bool(d["closed"])
        return d

    def history(self):
        """SQP history, a (k, 4) array: energy (J), stationarity residual, step, wall
        seconds since the SQP started."""
        n = int(_lib.pleat_tfw_result_history_count(self._h))
        out = _np.empty((max(n, 1), 4), dtype=_np.float64)
        _check(_lib.pleat_tfw_result_copy_history(self._h, _ptr(out, _c.c_double), n))
        return out[:n]

    def __repr__(self):
        s = self.stats
        return (f"<pleat.TfwResult {s['status']}, {s['vertex_count']} vertices, "
                f"{s['sqp_iterations']} SQP iterations>")


# --- attribute transfer to LODs (capability "lod") -----------------------------------------

_TransferParams = _struct("PleatTransferParams", _u32s("struct_size", "lookup")
                          + _f64s("screen_size", "envelope_d", "max_distance_d")
                          + _u32s("skin_smoothing", "reserved"))
for _name, _res, _args in [
    ("pleat_transfer_params_default", _TransferParams, ()),
    ("pleat_transfer_create", _st, (_P, _P, _c.POINTER(_TransferParams), _PP)),
    ("pleat_transfer_destroy", None, (_P,)),
    ("pleat_transfer_lod_vertex_count", _sz, (_P,)),
    ("pleat_transfer_input_vertex_count", _sz, (_P,)),
    ("pleat_transfer_f32", _st, (_P, _u32, _F, _sz, _sz, _F, _sz)),
    ("pleat_transfer_u32", _st, (_P, _U, _sz, _sz, _U, _sz)),
    ("pleat_transfer_skin", _st, (_P, _U, _F, _sz, _sz, _u32, _U, _F, _sz)),
]:
    _sig(_name, _res, *_args)
if _lib.pleat_transfer_params_default().struct_size != _c.sizeof(_TransferParams):
    raise ImportError(f"{_path}: PleatTransferParams is "
                      f"{_lib.pleat_transfer_params_default().struct_size} bytes in the library, "
                      f"{_c.sizeof(_TransferParams)} in this module")
_TRANSFER_MODES = {"barycentric": 0, "nearest": 1}
_LOOKUPS = {"cast": 0, "closest": 1}


def _rows(values, n, dtype, what):
    """``values`` as a contiguous 2-D (n, k) array of ``dtype``: (n,) is taken as (n, 1)."""
    a = _np.asarray(values)
    if a.ndim == 1:
        a = a.reshape(-1, 1)
    if a.ndim != 2 or a.shape[0] != n:
        raise PleatError(1, f"{what}: shape {_np.shape(values)}; ({n}, k) needed (one row per "
                            f"input vertex)")
    return _np.ascontiguousarray(a, dtype=dtype)


class Transfer(_Handle):
    """The correspondence of a LOD's vertices on the input it was made from, computed once
    (``pleat_transfer_create``) and applied to any number of per-vertex arrays of the input:
    ``f32`` (UVs, colours, morph deltas; barycentric or nearest), ``u32`` (ids, groups) and
    ``skin`` (joints + weights, top-k, renormalised). Raises PleatError (INVALID_ARGUMENT)
    when ``input`` is not the mesh ``lod`` was made from at ``screen_size``. Deterministic,
    whatever the thread count."""

    _destroy = "pleat_transfer_destroy"

    def __init__(self, input, lod, screen_size=200.0, lookup="cast", envelope_d=3.0,
                 max_distance_d=4.0, skin_smoothing=0):
        if lookup not in _LOOKUPS:
            raise ValueError(f"lookup must be one of {sorted(_LOOKUPS)}, got {lookup!r}")
        p = _lib.pleat_transfer_params_default()
        p.screen_size, p.envelope_d, p.max_distance_d = (float(screen_size), float(envelope_d),
                                                         float(max_distance_d))
        p.lookup, p.skin_smoothing = _LOOKUPS[lookup], int(skin_smoothing)
        h = _P()
        _check(_lib.pleat_transfer_create(input._h, lod._h, _c.byref(p), _c.byref(h)))
        super().__init__(h)

    @property
    def lod_vertex_count(self):
        return int(_lib.pleat_transfer_lod_vertex_count(self._h))

    @property
    def input_vertex_count(self):
        return int(_lib.pleat_transfer_input_vertex_count(self._h))

    def f32(self, values, mode="barycentric"):
        """``values`` (n_input, k) (or (n_input,)) on the LOD's vertices: float32 (n_lod, k)."""
        if mode not in _TRANSFER_MODES:
            raise ValueError(f"mode must be one of {sorted(_TRANSFER_MODES)}, got {mode!r}")
        n = self.input_vertex_count
        a = _rows(values, n, _np.float32, "values")
        k, m = a.shape[1], self.lod_vertex_count
        out = _np.empty((max(m, 1), max(k, 1)), dtype=_np.float32)
        _check(_lib.pleat_transfer_f32(self._h, _TRANSFER_MODES[mode],
                                       _ptr(a if a.size else _np.zeros(1, _np.float32),
                                            _c.c_float), n, k, _ptr(out, _c.c_float), m))
        return out[:m, :k]

    def u32(self, values):
        """Integer ``values`` (n_input, k): the nearest corner's row, uint32 (n_lod, k)."""
        n = self.input_vertex_count
        a = _np.asarray(values)
        if a.size and a.dtype.kind not in "iu":
            raise PleatError(1, f"values: integers needed, got {a.dtype}")
        if a.size and (a.min() < 0 or a.max() > 0xFFFFFFFF):
            raise PleatError(1, "values must be in [0, 2^32)")
        a = _rows(a, n, _np.uint32, "values")
        k, m = a.shape[1], self.lod_vertex_count
        out = _np.empty((max(m, 1), max(k, 1)), dtype=_np.uint32)
        _check(_lib.pleat_transfer_u32(self._h, _ptr(a if a.size else _np.zeros(1, _np.uint32),
                                                     _c.c_uint32), n, k,
                                       _ptr(out, _c.c_uint32), m))
        return out[:m, :k]

    def skin(self, joints, weights, max_influences=4):
        """Skin weights: ``joints`` (n_input, m) integers and ``weights`` (n_input, m) on the
        LOD's vertices, ``(joints uint32 (n_lod, k), weights float32 (n_lod, k))`` with
        k = ``max_influences``, sorted by weight, each row summing to 1 within 1e-6."""
        n = self.input_vertex_count
        j = _rows(_indices(joints, "joints").reshape(_np.shape(joints)), n, _np.uint32,
                  "joints")
        w = _rows(weights, n, _np.float32, "weights")
        if j.shape != w.shape:
            raise PleatError(1, f"joints {j.shape} and weights {w.shape} differ in shape")
        k, lm = int(max_influences), self.lod_vertex_count
        oj = _np.zeros((max(lm, 1), max(k, 1)), dtype=_np.uint32)
        ow = _np.zeros((max(lm, 1), max(k, 1)), dtype=_np.float32)
        _check(_lib.pleat_transfer_skin(self._h, _ptr(j, _c.c_uint32), _ptr(w, _c.c_float), n,
                                        j.shape[1], k, _ptr(oj, _c.c_uint32),
                                        _ptr(ow, _c.c_float), lm))
        return oj[:lm, :k], ow[:lm, :k]


__all__.append("Transfer")

_DeformationDesc = _struct("PleatDeformationDesc", _u32s("struct_size", "influences")
                           + [("vertex_count", _sz), ("joints", _U), ("weights", _F),
                              ("joint_count", _sz), ("joint_pivots", _D), ("morph_count", _sz),
                              ("morph_deltas", _F)]
                           + _f64s("max_rotation", "max_skin_error"))
for _name, _res, _args in [
    ("pleat_deformation_desc_default", _DeformationDesc, ()),
    ("pleat_deformation_create", _st, (_c.POINTER(_DeformationDesc), _PP)),
    ("pleat_deformation_destroy", None, (_P,)),
]:
    _sig(_name, _res, *_args)
if _lib.pleat_deformation_desc_default().struct_size != _c.sizeof(_DeformationDesc):
    raise ImportError(f"{_path}: PleatDeformationDesc is "
                      f"{_lib.pleat_deformation_desc_default().struct_size} bytes in the "
                      f"library, {_c.sizeof(_DeformationDesc)} in this module")


class Deformation(_Handle):
    """The skin and morph targets of an input mesh, for LODs that must follow them when posed
    (``pleat_deformation_create``; pass it as ``Mesh.lod(..., deformation=d)`` or
    ``lod_chain``). ``vertex_count``: the input's vertices; ``joints`` and ``weights``:
    (n, k) per-vertex influences (or None); ``pivots``: (joints, 3) bind-pose joint positions
    (or None); ``morph_deltas``: (targets, n, 3) displacements (or None); ``max_rotation`` in
    radians and ``max_skin_error`` in pixels (0: 1 rad and half a pixel). The arrays are copied.
    Raises PleatError (INVALID_ARGUMENT) for mismatched shapes, negative or non-finite weights,
    non-finite pivots or displacements."""

    _destroy = "pleat_deformation_destroy"

    def __init__(self, vertex_count, joints=None, weights=None, pivots=None,
                 morph_deltas=None, max_rotation=0.0, max_skin_error=0.0):
        n = int(vertex_count)
        d = _lib.pleat_deformation_desc_default()
        d.vertex_count = n
        keep = []
        if (joints is None) != (weights is None):
            raise PleatError(1, "joints and weights come together (both or neither)")
        if joints is not None:
            j = _rows(_indices(joints, "joints").reshape(_np.shape(joints)), n, _np.uint32,
                      "joints")
            w = _rows(weights, n, _np.float32, "weights")
            if j.shape != w.shape:
                raise PleatError(1, f"joints {j.shape} and weights {w.shape} differ in shape")
            keep += [j, w]
            d.influences = j.shape[1]
            d.joints, d.weights = _ptr(j, _c.c_uint32), _ptr(w, _c.c_float)
        if pivots is not None:
            pv = _np.ascontiguousarray(pivots, dtype=_np.float64)
            if pv.ndim != 2 or pv.shape[1] != 3:
                raise PleatError(1, f"pivots: shape {pv.shape}; (joints, 3) needed")
            keep.append(pv)
            d.joint_count, d.joint_pivots = pv.shape[0], _ptr(pv, _c.c_double)
        if morph_deltas is not None:
            md = _np.ascontiguousarray(morph_deltas, dtype=_np.float32)
            if md.ndim != 3 or md.shape[1:] != (n, 3):
                raise PleatError(1, f"morph_deltas: shape {md.shape}; (targets, {n}, 3) needed")
            keep.append(md)
            d.morph_count, d.morph_deltas = md.shape[0], _ptr(md, _c.c_float)
        d.max_rotation, d.max_skin_error = float(max_rotation), float(max_skin_error)
        h = _P()
        _check(_lib.pleat_deformation_create(_c.byref(d), _c.byref(h)))
        super().__init__(h)


__all__.append("Deformation")
