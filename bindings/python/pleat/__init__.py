"""pleat — ctypes bindings for Blender/Maya/Houdini scripts.

Loads the pleat shared library from ``$PLEAT_LIBRARY`` (a file path), else from this package's
directory, else from the system loader path (``libpleat.so.0`` / ``libpleat.so``). No
dependencies; numpy arrays are accepted wherever a sequence of numbers is, and results are
plain lists (or numpy arrays when numpy is importable and ``as_numpy=True``).

    import pleat
    m = pleat.Mesh.read("bunny.obj")
    print(m.vertex_count, m.triangle_count)
    r = m.check()            # dict with the validity report (when the library has it)

    # complex wrinkle fields (when has_feature("wrinkle")): omega per edge of m.edges()
    w = pleat.Cwf.plane_wave(m, k=(9, 4, 2), amplitude=0.01)
    wrinkled = w.evaluate(levels=3)                        # a Mesh
    mesh, f = w.evaluate_fields(["phase", "normals"], 3)   # plus per-vertex fields
"""

import ctypes as _c
import os as _os

__all__ = ["Mesh", "Cwf", "PleatError", "version", "set_thread_count", "has_feature"]

_STATUS = {
    0: "OK", 1: "INVALID_ARGUMENT", 2: "INVALID_MESH", 3: "IO", 4: "PARSE", 5: "NUMERICAL",
    6: "CANCELLED", 7: "LIMIT_EXCEEDED", 8: "OUT_OF_MEMORY", 9: "INTERNAL", 10: "UNSUPPORTED",
}


class PleatError(RuntimeError):
    """A pleat call failed; ``status`` is the C status name, the message is pleat's."""

    def __init__(self, status, message):
        super().__init__(f"{_STATUS.get(status, status)}: {message}")
        self.status = _STATUS.get(status, str(status))


def _load():
    cands = []
    if _os.environ.get("PLEAT_LIBRARY"):
        cands.append(_os.environ["PLEAT_LIBRARY"])
    here = _os.path.dirname(_os.path.abspath(__file__))
    cands += [_os.path.join(here, n) for n in ("libpleat.so.0", "libpleat.so", "libpleat.dylib", "pleat.dll")]
    cands += ["libpleat.so.0", "libpleat.so"]
    errors = []
    for c in cands:
        try:
            return _c.CDLL(c)
        except OSError as e:
            errors.append(f"{c}: {e}")
    raise ImportError("cannot load the pleat library; set PLEAT_LIBRARY. Tried:\n  " + "\n  ".join(errors))


_lib = _load()
_P = _c.c_void_p
_sz = _c.c_size_t
_st = _c.c_int32


def _sig(name, restype, *args):
    f = getattr(_lib, name)
    f.restype = restype
    f.argtypes = list(args)
    return f


_sig("pleat_version", _c.c_char_p)
_sig("pleat_last_error", _c.c_char_p)
_sig("pleat_set_thread_count", _st, _c.c_uint32)
_sig("pleat_has_feature", _c.c_uint32, _c.c_char_p)
_sig("pleat_mesh_create_f64", _st, _c.POINTER(_c.c_double), _sz, _sz, _c.POINTER(_c.c_uint32), _sz, _c.POINTER(_P))
_sig("pleat_mesh_destroy", None, _P)
_sig("pleat_mesh_vertex_count", _sz, _P)
_sig("pleat_mesh_triangle_count", _sz, _P)
_sig("pleat_mesh_copy_positions_f64", _st, _P, _c.POINTER(_c.c_double), _sz, _sz)
_sig("pleat_mesh_copy_indices", _st, _P, _c.POINTER(_c.c_uint32), _sz)
_sig("pleat_mesh_read_file", _st, _c.c_char_p, _c.POINTER(_P))
_sig("pleat_mesh_write_file", _st, _P, _c.c_char_p)


class _Report(_c.Structure):
    _fields_ = [("struct_size", _c.c_uint32), ("is_closed", _c.c_uint32)] + [
        (n, _c.c_uint64) for n in (
            "vertex_count", "referenced_vertex_count", "triangle_count", "edge_count",
            "component_count", "boundary_edge_count", "nonmanifold_edge_count",
            "nonmanifold_vertex_count", "degenerate_face_count", "duplicate_face_count",
            "misoriented_edge_count", "self_intersecting_pair_count")
    ] + [("total_genus", _c.c_int64), ("euler_characteristic", _c.c_int64)] + [
        (n, _c.c_uint32) for n in (
            "is_edge_manifold", "is_manifold", "is_watertight", "consistently_oriented",
            "self_intersections_checked", "self_intersection_free")
    ] + [("surface_area", _c.c_double), ("signed_volume", _c.c_double),
         ("bbox_diagonal", _c.c_double), ("bbox_min", _c.c_double * 3), ("bbox_max", _c.c_double * 3)]


_sig("pleat_mesh_check", _st, _P, _c.c_uint32, _c.POINTER(_Report))
_sig("pleat_mesh_edge_count", _sz, _P)
_sig("pleat_mesh_copy_edges", _st, _P, _c.POINTER(_c.c_uint32), _sz)


class _EvalParams(_c.Structure):
    _fields_ = [("struct_size", _c.c_uint32), ("levels", _c.c_uint32), ("flags", _c.c_uint32),
                ("boundary", _c.c_uint32), ("corner_angle", _c.c_double),
                ("displacement_scale", _c.c_double), ("max_output_triangles", _c.c_uint64)]


class _EvalStats(_c.Structure):
    _fields_ = [("struct_size", _c.c_uint32), ("levels", _c.c_uint32),
                ("vertex_count", _c.c_uint64), ("triangle_count", _c.c_uint64),
                ("total_seconds", _c.c_double), ("subdivision_seconds", _c.c_double),
                ("displacement_seconds", _c.c_double)]


class _KnoppelParams(_c.Structure):
    _fields_ = [("struct_size", _c.c_uint32), ("weights", _c.c_uint32),
                ("max_iterations", _c.c_uint32), ("reserved", _c.c_uint32),
                ("tolerance", _c.c_double), ("shift", _c.c_double)]


class _KnoppelReport(_c.Structure):
    _fields_ = [("struct_size", _c.c_uint32), ("iterations", _c.c_uint32),
                ("eigenvalue", _c.c_double), ("residual", _c.c_double), ("shift", _c.c_double)]


class _Progress(_c.Structure):
    _fields_ = [("stage", _c.c_char_p), ("fraction", _c.c_double)]


_PROGRESS_FN = _c.CFUNCTYPE(_c.c_int32, _c.c_void_p, _c.POINTER(_Progress))
_D = _c.POINTER(_c.c_double)
_sig("pleat_wrinkle_eval_params_default", _EvalParams)
_sig("pleat_knoppel_params_default", _KnoppelParams)
_sig("pleat_cwf_create", _st, _P, _D, _sz, _D, _D, _sz, _c.POINTER(_P))
_sig("pleat_cwf_create_from_corner_omega", _st, _P, _D, _sz, _D, _D, _sz, _c.POINTER(_P))
_sig("pleat_cwf_create_from_frequency", _st, _P, _D, _sz, _c.c_uint32, _D, _sz,
     _c.POINTER(_KnoppelParams), _c.POINTER(_P))
_sig("pleat_cwf_read_file", _st, _P, _c.c_char_p, _c.POINTER(_P))
_sig("pleat_cwf_write_file", _st, _P, _c.c_char_p)
_sig("pleat_cwf_destroy", None, _P)
_sig("pleat_cwf_vertex_count", _sz, _P)
_sig("pleat_cwf_edge_count", _sz, _P)
_sig("pleat_cwf_triangle_count", _sz, _P)
_sig("pleat_cwf_copy_omega", _st, _P, _D, _sz)
_sig("pleat_cwf_copy_corner_omega", _st, _P, _D, _sz)
_sig("pleat_cwf_copy_amplitude", _st, _P, _D, _sz)
_sig("pleat_cwf_copy_zeta", _st, _P, _D, _sz)
_sig("pleat_cwf_get_knoppel_report", _st, _P, _c.POINTER(_KnoppelReport))
_sig("pleat_cwf_evaluate", _st, _P, _c.POINTER(_EvalParams), _PROGRESS_FN, _c.c_void_p,
     _c.POINTER(_P), _c.POINTER(_P), _c.POINTER(_EvalStats))
_sig("pleat_wrinkle_fields_count", _sz, _P, _c.c_uint32)
_sig("pleat_wrinkle_fields_copy", _st, _P, _c.c_uint32, _D, _sz, _sz)
_sig("pleat_wrinkle_fields_destroy", None, _P)

# PLEAT_WRINKLE_FIELD_* bits and doubles per element
_FIELDS = {"amplitude": (1, 1), "phase": (2, 1), "normals": (4, 3), "z": (8, 2),
           "smooth_positions": (16, 3), "omega": (32, 1)}


def _check(status):
    if status != 0:
        raise PleatError(status, _lib.pleat_last_error().decode("utf-8", "replace"))


def version():
    """The library version string."""
    return _lib.pleat_version().decode()


def set_thread_count(n):
    """Worker threads for later calls (0 = all cores); results do not depend on it."""
    _check(_lib.pleat_set_thread_count(int(n)))


def has_feature(name):
    """True when this build of the library includes capability ``name`` (lod, cage, wrinkle, ...)."""
    return bool(_lib.pleat_has_feature(name.encode()))


def _flat(seq, ctype):
    try:  # numpy fast path without importing numpy ourselves
        flat = seq.reshape(-1).tolist()
    except AttributeError:
        flat = [x for row in seq for x in (row if hasattr(row, "__len__") else (row,))]
    return (ctype * len(flat))(*flat), len(flat)


class Mesh:
    """An immutable triangle mesh owned by pleat."""

    def __init__(self, handle):
        self._h = _P(handle) if not isinstance(handle, _P) else handle

    @classmethod
    def from_arrays(cls, positions, triangles):
        """From xyz positions (n×3 or flat 3n) and triangle indices (m×3 or flat 3m)."""
        p, npos = _flat(positions, _c.c_double)
        t, nidx = _flat(triangles, _c.c_uint32)
        h = _P()
        _check(_lib.pleat_mesh_create_f64(p, npos // 3 if npos % 3 == 0 else npos, 0, t, nidx, _c.byref(h)))
        return cls(h)

    @classmethod
    def read(cls, path):
        """Reads obj/ply/off/stl/glb/gltf."""
        h = _P()
        _check(_lib.pleat_mesh_read_file(_os.fsencode(path), _c.byref(h)))
        return cls(h)

    def write(self, path):
        """Writes a mesh file; format by extension."""
        _check(_lib.pleat_mesh_write_file(self._h, _os.fsencode(path)))

    @property
    def vertex_count(self):
        return _lib.pleat_mesh_vertex_count(self._h)

    @property
    def triangle_count(self):
        return _lib.pleat_mesh_triangle_count(self._h)

    def positions(self):
        """List of (x, y, z) tuples."""
        n = self.vertex_count
        buf = (_c.c_double * (3 * n))()
        _check(_lib.pleat_mesh_copy_positions_f64(self._h, buf, n, 0))
        return [tuple(buf[3 * i:3 * i + 3]) for i in range(n)]

    def triangles(self):
        """List of (a, b, c) index tuples."""
        n = self.triangle_count
        buf = (_c.c_uint32 * (3 * n))()
        _check(_lib.pleat_mesh_copy_indices(self._h, buf, 3 * n))
        return [tuple(buf[3 * i:3 * i + 3]) for i in range(n)]

    @property
    def edge_count(self):
        """Number of unique edges: the length of per-edge data such as wrinkle omega."""
        return _lib.pleat_mesh_edge_count(self._h)

    def edges(self):
        """List of (a, b) with a < b, in pleat's edge numbering (sorted by (a, b)); per-edge
        values such as omega are integrated from a to b."""
        n = self.edge_count
        buf = (_c.c_uint32 * max(1, 2 * n))()
        _check(_lib.pleat_mesh_copy_edges(self._h, buf, n))
        return [(buf[2 * i], buf[2 * i + 1]) for i in range(n)]

    def check(self, self_intersections=True, weld=False):
        """Validity report as a dict (same fields as PleatMeshReport; yes/no fields as bool)."""
        r = _Report()
        r.struct_size = _c.sizeof(_Report)
        flags = (0 if self_intersections else 1) | (2 if weld else 0)
        _check(_lib.pleat_mesh_check(self._h, flags, _c.byref(r)))
        out = {}
        for name, ctype in _Report._fields_:
            v = getattr(r, name)
            if name == "struct_size":
                continue
            if ctype is _c.c_uint32:
                v = bool(v)
            elif hasattr(v, "__len__"):
                v = tuple(v)
            out[name] = v
        return out

    def close(self):
        """Releases the mesh now (also done when garbage-collected)."""
        if self._h:
            _lib.pleat_mesh_destroy(self._h)
            self._h = _P()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _doubles(seq, n, what):
    buf, got = _flat(seq, _c.c_double)
    if got != n:
        raise PleatError(1, f"{what}: {got} values given, {n} needed")
    return buf


def _zeta_buf(zeta, n):
    if zeta is None:
        return None
    flat = []
    for z in zeta:
        if isinstance(z, complex):
            flat += [z.real, z.imag]
        else:
            flat += [float(z[0]), float(z[1])]
    return _doubles(flat, 2 * n, "zeta (one complex or (re, im) per vertex)")


class Cwf:
    """A complex wrinkle field on a base Mesh: omega per edge (the order of ``base.edges()``,
    integrated from the smaller to the larger vertex), amplitude and unit phase zeta per vertex.
    Needs a library built with the ``wrinkle`` capability (else PleatError UNSUPPORTED)."""

    def __init__(self, handle):
        self._h = _P(handle) if not isinstance(handle, _P) else handle

    @classmethod
    def from_arrays(cls, base, omega, amplitude, zeta=None):
        """omega: one value per edge of base.edges(); amplitude: one per vertex (>= 0);
        zeta: one complex (or (re, im)) per vertex, or None for Knoppel's phase from omega."""
        nv, ne = base.vertex_count, base.edge_count
        h = _P()
        _check(_lib.pleat_cwf_create(base._h, _doubles(omega, ne, "omega"), ne,
                                     _doubles(amplitude, nv, "amplitude"), _zeta_buf(zeta, nv),
                                     nv, _c.byref(h)))
        return cls(h)

    @classmethod
    def from_corner_omega(cls, base, corner_omega, amplitude, zeta=None):
        """corner_omega: 3 values per triangle, value i integrated from corner i to corner i+1;
        must be antisymmetric across shared edges. Otherwise as from_arrays."""
        nv, nc = base.vertex_count, 3 * base.triangle_count
        h = _P()
        _check(_lib.pleat_cwf_create_from_corner_omega(
            base._h, _doubles(corner_omega, nc, "corner_omega"), nc,
            _doubles(amplitude, nv, "amplitude"), _zeta_buf(zeta, nv), nv, _c.byref(h)))
        return cls(h)

    @classmethod
    def from_frequency(cls, base, vectors, amplitude, per_face=False, weights="cotan",
                       max_iterations=None):
        """Wave vectors (x, y, z; radians per length unit), one per vertex (or per triangle
        with per_face=True); zeta by Knoppel et al. 2015 (weights "cotan" or "edge_area")."""
        nv = base.vertex_count
        n = base.triangle_count if per_face else nv
        p = _lib.pleat_knoppel_params_default()
        p.weights = {"cotan": 0, "edge_area": 1}[weights]
        if max_iterations is not None:
            p.max_iterations = int(max_iterations)
        h = _P()
        _check(_lib.pleat_cwf_create_from_frequency(
            base._h, _doubles(vectors, 3 * n, "vectors"), n, 1 if per_face else 0,
            _doubles(amplitude, nv, "amplitude"), nv, _c.byref(p), _c.byref(h)))
        return cls(h)

    @classmethod
    def plane_wave(cls, base, k, amplitude):
        """The global wave exp(i k.x): omega_ab = k.x_b - k.x_a, zeta = exp(i k.x)."""
        import cmath
        phase = [sum(kc * xc for kc, xc in zip(k, x)) for x in base.positions()]
        omega = [phase[b] - phase[a] for a, b in base.edges()]
        a = amplitude if hasattr(amplitude, "__len__") else [amplitude] * base.vertex_count
        return cls.from_arrays(base, omega, a, [cmath.exp(1j * t) for t in phase])

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
        return _lib.pleat_cwf_vertex_count(self._h)

    @property
    def edge_count(self):
        return _lib.pleat_cwf_edge_count(self._h)

    def _copy(self, fn, n):
        buf = (_c.c_double * max(1, n))()
        _check(fn(self._h, buf, n))
        return list(buf[:n])

    def omega(self):
        """omega per edge of base.edges() (radians)."""
        return self._copy(_lib.pleat_cwf_copy_omega, self.edge_count)

    def corner_omega(self):
        """omega per triangle corner (3 per triangle, corner i to i+1)."""
        return self._copy(_lib.pleat_cwf_copy_corner_omega,
                          3 * _lib.pleat_cwf_triangle_count(self._h))

    def amplitude(self):
        """Amplitude per vertex."""
        return self._copy(_lib.pleat_cwf_copy_amplitude, self.vertex_count)

    def zeta(self):
        """Unit phase per vertex, as complex numbers."""
        n = self.vertex_count
        buf = (_c.c_double * max(1, 2 * n))()
        _check(_lib.pleat_cwf_copy_zeta(self._h, buf, n))
        return [complex(buf[2 * i], buf[2 * i + 1]) for i in range(n)]

    def knoppel_report(self):
        """dict (iterations, eigenvalue, residual, shift) of the phase solve; PleatError when
        the phase was given rather than computed."""
        r = _KnoppelReport()
        r.struct_size = _c.sizeof(r)
        _check(_lib.pleat_cwf_get_knoppel_report(self._h, _c.byref(r)))
        return {n: getattr(r, n) for n, _ in _KnoppelReport._fields_ if n != "struct_size"}

    def _evaluate(self, fields, levels, displacement_scale, smooth_boundary, progress,
                  max_output_triangles):
        p = _lib.pleat_wrinkle_eval_params_default()
        p.levels = int(levels)
        p.displacement_scale = float(displacement_scale)
        p.boundary = 1 if smooth_boundary else 0
        if max_output_triangles is not None:
            p.max_output_triangles = int(max_output_triangles)
        for f in fields:
            if f not in _FIELDS:
                raise PleatError(1, f"unknown field {f!r}; known: {sorted(_FIELDS)}")
            p.flags |= _FIELDS[f][0]
        raised = []

        def relay(_user, info):
            try:
                stage = info.contents.stage.decode("utf-8", "replace")
                return 1 if progress(stage, info.contents.fraction) else 0
            except BaseException as e:  # noqa: BLE001 - re-raised after the call
                raised.append(e)
                return 1
        cb = _PROGRESS_FN(relay) if progress else _PROGRESS_FN()
        mesh, out_fields = _P(), _P()
        stats = _EvalStats()
        stats.struct_size = _c.sizeof(stats)
        st = _lib.pleat_cwf_evaluate(self._h, _c.byref(p), cb, None, _c.byref(mesh),
                                     _c.byref(out_fields) if fields else None, _c.byref(stats))
        if raised:
            raise raised[0]
        _check(st)
        result = {}
        try:
            for f in fields:
                bit, comps = _FIELDS[f]
                n = _lib.pleat_wrinkle_fields_count(out_fields, bit)
                buf = (_c.c_double * max(1, comps * n))()
                _check(_lib.pleat_wrinkle_fields_copy(out_fields, bit, buf, n, 0))
                if comps == 1:
                    result[f] = list(buf[:n])
                elif comps == 2:
                    result[f] = [complex(buf[2 * i], buf[2 * i + 1]) for i in range(n)]
                else:
                    result[f] = [tuple(buf[3 * i:3 * i + 3]) for i in range(n)]
        finally:
            if out_fields:
                _lib.pleat_wrinkle_fields_destroy(out_fields)
        result["stats"] = {n: getattr(stats, n) for n, _ in _EvalStats._fields_
                           if n != "struct_size"}
        return Mesh(mesh), result

    def evaluate(self, levels=3, displacement_scale=1.0, smooth_boundary=False, progress=None,
                 max_output_triangles=None):
        """The wrinkled Mesh after ``levels`` Loop refinements. ``progress(stage, fraction)``
        is called after each level; return True from it to cancel (PleatError CANCELLED)."""
        return self._evaluate((), levels, displacement_scale, smooth_boundary, progress,
                              max_output_triangles)[0]

    def evaluate_fields(self, fields, levels=3, displacement_scale=1.0, smooth_boundary=False,
                        progress=None, max_output_triangles=None):
        """(Mesh, dict): the wrinkled mesh and the requested per-vertex fields, any of
        "amplitude", "phase" (radians), "normals", "z" (complex), "smooth_positions",
        "omega" (per edge of the output mesh's edges()); the dict also has "stats"."""
        return self._evaluate(tuple(fields), levels, displacement_scale, smooth_boundary,
                              progress, max_output_triangles)

    def close(self):
        """Releases the field now (also done when garbage-collected)."""
        if self._h:
            _lib.pleat_cwf_destroy(self._h)
            self._h = _P()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
