"""pleat — ctypes bindings for Blender/Maya/Houdini scripts.

Loads the pleat shared library from ``$PLEAT_LIBRARY`` (a file path), else from this package's
directory, else from the system loader path (``libpleat.so.0`` / ``libpleat.so``). No
dependencies; numpy arrays are accepted wherever a sequence of numbers is, and results are
plain lists (or numpy arrays when numpy is importable and ``as_numpy=True``).

    import pleat
    m = pleat.Mesh.read("bunny.obj")
    print(m.vertex_count, m.triangle_count)
    r = m.check()            # dict with the validity report (when the library has it)
"""

import ctypes as _c
import os as _os

__all__ = ["Mesh", "PleatError", "version", "set_thread_count", "has_feature"]

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
