"""pleat LOD: bake LOD chains (and optionally cages) of the selected objects by screen size.

Object > pleat: Bake LODs (also F3 "pleat"). For every selected mesh object the operator bakes
one LOD per screen size n_p (pixels covered by the bounding-box diagonal) with pleat's C library
through its Python package (ctypes), and adds each level as a new object ``<name>_LOD<n_p>``
(plus ``<name>_cage<n_p>`` when "Cage" is on) next to the source, with the bake's statistics as
custom properties (``pleat_faces``, ``pleat_hausdorff_relative``, ``pleat_verified``).

Rigged and morphed sources: a LOD (or cage) of an object with vertex groups, shape keys or an
armature modifier keeps them: the vertex groups (same names; weights interpolated at each LOD
vertex's corresponding point on the source, ``pleat.Transfer``), the shape keys (same names;
their deltas interpolated the same way) and the armature modifiers (same armature object), so
the LOD deforms with the rig. Such objects are baked from their base mesh (no modifiers, the
rest pose) so that the attributes line up with the vertices they belong to.

Guarantees (pleat's): every level is watertight, manifold and self-intersection-free, each
verified by the library; a cage encloses the source without touching it. Meshes are baked in
world space (screen size is about what is seen), so the new objects have an identity transform.

Interactive use runs the bake on a worker thread with a progress bar in the status bar; Esc
cancels it (pleat's progress callback answers "cancel", the library stops and frees everything)
and keeps the levels already added. A failure (a degenerate mesh, no selection, the library
not found) is an error in Blender's report area, never a crash. Run from a script or in
background mode (``blender -b``) the same bake runs synchronously.

The pleat Python package is found by ``import pleat``; otherwise in the folder named by the
add-on preference "pleat Python package", else by the environment variable PLEAT_PYTHON (the
folder holding the ``pleat`` package, e.g. a checkout's bindings/python). The library itself is
found as the package finds it (bundled in a wheel, PLEAT_LIBRARY, or the system's libpleat.so.0).
"""

import os
import sys
import threading

import bpy
from bpy.props import BoolProperty, FloatProperty, IntProperty, StringProperty

bl_info = {
    "name": "pleat LOD",
    "author": "pleat",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Object > pleat: Bake LODs",
    "description": "LOD chains and cages by screen size: watertight, manifold, "
                   "self-intersection-free (pleat C library)",
    "category": "Object",
}


# --- finding the pleat package ----------------------------------------------------------------

def _package_dir():
    """The configured folder holding the ``pleat`` package ('' when none)."""
    addon = bpy.context.preferences.addons.get(__name__)
    pref = addon.preferences.package_dir if addon else ""
    return bpy.path.abspath(pref) if pref else os.environ.get("PLEAT_PYTHON", "")


def load_pleat():
    """Imports and returns the pleat package; raises RuntimeError with a readable message."""
    try:
        import pleat  # noqa: F401
        return sys.modules["pleat"]
    except ImportError as first:
        folder = _package_dir()
        if not folder:
            raise RuntimeError(f"pleat Python package not found ({first}); set the add-on "
                               "preference 'pleat Python package' or PLEAT_PYTHON") from first
        if folder not in sys.path:
            sys.path.insert(0, folder)
        try:
            import pleat  # noqa: F401
        except ImportError as e:
            raise RuntimeError(f"pleat Python package not usable from {folder}: {e}") from e
        return sys.modules["pleat"]


# --- Blender mesh <-> arrays ------------------------------------------------------------------

def object_arrays(obj, depsgraph):
    """World-space (positions float64 (n, 3), triangles uint32 (m, 3)) of the evaluated object
    (modifiers applied), read with foreach_get (no per-element Python loop)."""
    import numpy as np
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        n, m = len(mesh.vertices), len(mesh.loop_triangles)
        co = np.empty(3 * n, dtype=np.float64)
        mesh.vertices.foreach_get("co", co)
        tri = np.empty(3 * m, dtype=np.int32)
        mesh.loop_triangles.foreach_get("vertices", tri)
    finally:
        evaluated.to_mesh_clear()
    world = np.array(obj.matrix_world, dtype=np.float64)
    co = co.reshape(n, 3) @ world[:3, :3].T + world[:3, 3]
    return np.ascontiguousarray(co), tri.reshape(m, 3).astype(np.uint32)


def has_rig(obj):
    """True when ``obj`` has vertex groups, shape keys or an armature modifier (attributes a
    LOD keeps, through ``pleat.Transfer``)."""
    return bool(obj.vertex_groups) or obj.data.shape_keys is not None or any(
        m.type == "ARMATURE" for m in obj.modifiers)


def base_arrays(obj):
    """World-space (positions float64 (n, 3), triangles uint32 (m, 3)) of the object's own
    mesh, without modifiers (the rest pose): vertex i is the mesh's vertex i."""
    import numpy as np
    me = obj.data
    me.calc_loop_triangles()
    n, m = len(me.vertices), len(me.loop_triangles)
    co = np.empty(3 * n, dtype=np.float64)
    me.vertices.foreach_get("co", co)
    tri = np.empty(3 * m, dtype=np.int32)
    me.loop_triangles.foreach_get("vertices", tri)
    world = np.array(obj.matrix_world, dtype=np.float64)
    co = co.reshape(n, 3) @ world[:3, :3].T + world[:3, 3]
    return np.ascontiguousarray(co), tri.reshape(m, 3).astype(np.uint32)


def object_attributes(obj):
    """The per-vertex attributes a LOD keeps, as plain arrays (no bpy): ``groups`` (names,
    weights float32 (n, G)), ``shape_keys`` [(name, world-space deltas float32 (n, 3))]."""
    import numpy as np
    me = obj.data
    n = len(me.vertices)
    names = [g.name for g in obj.vertex_groups]
    weights = np.zeros((n, len(names)), dtype=np.float32)
    for v in me.vertices:
        for g in v.groups:
            if g.group < len(names):
                weights[v.index, g.group] = g.weight
    keys = []
    if me.shape_keys is not None:
        basis = me.shape_keys.reference_key
        base = np.empty(3 * n, dtype=np.float64)
        basis.data.foreach_get("co", base)
        rot = np.array(obj.matrix_world, dtype=np.float64)[:3, :3]
        for kb in me.shape_keys.key_blocks:
            if kb.name == basis.name:
                continue
            co = np.empty(3 * n, dtype=np.float64)
            kb.data.foreach_get("co", co)
            keys.append((kb.name, ((co - base).reshape(n, 3) @ rot.T).astype(np.float32)))
    return {"groups": (names, weights), "shape_keys": keys}


def transfer_attributes(pleat, source, level, screen_size, attrs):
    """``attrs`` (from ``object_attributes``) on the vertices of ``level``, a LOD or cage of
    ``source`` (pleat Meshes) at ``screen_size``: the same structure, LOD rows. No bpy."""
    import numpy as np
    names, weights = attrs["groups"]
    with pleat.Transfer(source, level, screen_size=screen_size) as t:
        lod_weights = (t.f32(weights) if names else
                       np.zeros((level.vertex_count, 0), dtype=np.float32))
        keys = [(name, t.f32(deltas)) for name, deltas in attrs["shape_keys"]]
    return {"groups": (names, lod_weights), "shape_keys": keys}


def apply_attributes(obj, positions, like, attrs):
    """Gives ``obj`` (made from ``positions``) the transferred vertex groups and shape keys and
    ``like``'s armature modifiers."""
    import numpy as np
    names, weights = attrs["groups"]
    for g, name in enumerate(names):
        vg = obj.vertex_groups.new(name=name)
        column = weights[:, g]
        for i in np.flatnonzero(column > 0.0):
            vg.add([int(i)], float(column[i]), "REPLACE")
    if attrs["shape_keys"]:
        obj.shape_key_add(name="Basis", from_mix=False)
        base = np.asarray(positions, dtype=np.float64)
        for name, deltas in attrs["shape_keys"]:
            kb = obj.shape_key_add(name=name, from_mix=False)
            kb.data.foreach_set("co", (base + deltas).astype(np.float32).ravel())
    for m in like.modifiers:
        if m.type == "ARMATURE":
            new = obj.modifiers.new(m.name, "ARMATURE")
            new.object = m.object
            new.use_vertex_groups = m.use_vertex_groups
            new.use_bone_envelopes = m.use_bone_envelopes


def new_object(name, positions, triangles, like, stats, attrs=None):
    """A new mesh object from arrays, linked to ``like``'s first collection, with ``stats``
    (a dict of numbers/bools) copied to ``pleat_*`` custom properties, and the transferred
    attributes ``attrs`` (``transfer_attributes``) with ``like``'s armature modifiers."""
    import numpy as np
    m = len(triangles)
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(positions))
    me.vertices.foreach_set("co", np.asarray(positions, dtype=np.float32).ravel())
    me.loops.add(3 * m)
    me.loops.foreach_set("vertex_index", np.asarray(triangles, dtype=np.int32).ravel())
    me.polygons.add(m)
    me.polygons.foreach_set("loop_start", np.arange(0, 3 * m, 3, dtype=np.int32))
    me.polygons.foreach_set("loop_total", np.full(m, 3, dtype=np.int32))
    me.update()
    me.validate()
    obj = bpy.data.objects.new(name, me)
    collection = like.users_collection[0] if like.users_collection else \
        bpy.context.scene.collection
    collection.objects.link(obj)
    for key in ("face_count", "hausdorff_relative", "offset_distance", "rounds",
                "watertight", "manifold", "self_intersection_free", "encloses_input"):
        if key in stats:
            value = stats[key]
            obj["pleat_" + key] = bool(value) if isinstance(value, bool) else float(value)
    obj["pleat_verified"] = bool(stats.get("watertight") and stats.get("manifold")
                                 and stats.get("self_intersection_free"))
    if attrs is not None:
        apply_attributes(obj, positions, like, attrs)
    return obj


#: Outcome of the operator's last run, for scripts and tests: (result set, objects added).
last_result = (None, [])


# --- the bake (no bpy here: it runs on a worker thread) ---------------------------------------

class Cancelled(Exception):
    """Esc was pressed: the library was told to stop."""


class Job:
    """Bakes LOD chains (and cages) of a list of (name, positions, triangles). Thread-safe
    progress (``fraction``, ``stage``) and cancellation (``cancel()``); results in ``done``
    as (name, kind, n_p, positions, triangles, stats), errors in ``errors`` as (name, message).
    One failing object does not stop the others; a cancel stops the job. ``attributes`` maps a
    source name to its ``object_attributes``; each of its levels then gets them transferred,
    in ``transferred[(name, kind, n_p)]``."""

    def __init__(self, pleat, sources, sizes, params, cage_size=None, attributes=None):
        self.pleat, self.sources, self.sizes = pleat, sources, sizes
        self.params, self.cage_size = params, cage_size
        self.attributes = attributes or {}
        self.fraction, self.stage = 0.0, ""
        self.done, self.errors = [], []
        self.transferred = {}
        self._cancel = threading.Event()
        self.finished = threading.Event()

    def cancel(self):
        self._cancel.set()

    def _progress(self, index, part, parts):
        count = len(self.sources)

        def report(stage, fraction):
            self.stage = stage
            self.fraction = (index + (part + fraction) / parts) / count
            return self._cancel.is_set()
        return report

    def run(self):
        try:
            for index, (name, positions, triangles) in enumerate(self.sources):
                if self._cancel.is_set():
                    raise Cancelled()
                self._bake_one(index, name, positions, triangles)
        except Cancelled:
            self.errors.append(("", "cancelled"))
        finally:
            self.fraction = 1.0
            self.finished.set()

    def _bake_one(self, index, name, positions, triangles):
        pleat = self.pleat
        parts = 2 if self.cage_size else 1
        if len(triangles) == 0:
            self.errors.append((name, "the object has no faces"))
            return
        try:
            mesh = pleat.Mesh.from_arrays(positions, triangles)
            with mesh:
                chain = mesh.lod_chain(self.sizes, progress=self._progress(index, 0, parts),
                                       **self.params)
                for n_p, level in zip(self.sizes, chain):
                    with level:
                        self._keep(name, "LOD", n_p, mesh, level)
                if self.cage_size:
                    with mesh.cage(self.cage_size, progress=self._progress(index, 1, parts),
                                   **self.params) as cage:
                        self._keep(name, "cage", self.cage_size, mesh, cage)
        except pleat.PleatError as e:
            if e.status == "CANCELLED" or self._cancel.is_set():
                raise Cancelled() from e
            self.errors.append((name, f"{e}"))


    def _keep(self, name, kind, n_p, source, level):
        """Records a baked level, with the source's attributes transferred onto it."""
        self.done.append((name, kind, n_p, level.positions(), level.triangles(),
                          dict(level.stats)))
        attrs = self.attributes.get(name)
        if attrs is not None:
            self.transferred[(name, kind, n_p)] = transfer_attributes(
                self.pleat, source, level, n_p, attrs)


def parse_sizes(text):
    """'200, 100,50' -> [200.0, 100.0, 50.0]; ValueError for anything else or no size."""
    sizes = [float(s) for s in text.replace(";", ",").split(",") if s.strip()]
    if not sizes or any(not (s > 0) for s in sizes):
        raise ValueError(f"screen sizes must be positive numbers, got '{text}'")
    return sizes


# --- the operator -----------------------------------------------------------------------------

class OBJECT_OT_pleat_bake_lods(bpy.types.Operator):
    """Bake LODs (and optionally a cage) of the selected objects by screen size with pleat"""
    bl_idname = "object.pleat_bake_lods"
    bl_label = "pleat: Bake LODs"
    bl_options = {"REGISTER", "UNDO"}

    screen_sizes: StringProperty(
        name="Screen sizes", default="200,100,50",
        description="Pixels covered by the bounding-box diagonal, one LOD each (comma separated)")
    max_rounds: IntProperty(name="Max rounds", default=50, min=1, max=1000,
                            description="Optimization rounds N per level")
    align: BoolProperty(name="Align features", default=True,
                        description="Align the LODs to sharp features")
    cage: BoolProperty(name="Cage", default=False,
                       description="Also bake a cage enclosing each object")
    cage_screen_size: FloatProperty(name="Cage screen size", default=100.0, min=1e-3,
                                    description="Screen size of the cage")

    _job = None
    _thread = None
    _timer = None

    @classmethod
    def poll(cls, context):
        return context.mode == "OBJECT"

    def _prepare(self, context):
        """(Job, source objects by name) or None after reporting the error."""
        try:
            pleat = load_pleat()
            sizes = parse_sizes(self.screen_sizes)
        except (RuntimeError, ValueError) as e:
            self.report({"ERROR"}, str(e))
            return None
        objects = [o for o in context.selected_objects if o.type == "MESH"]
        if not objects:
            self.report({"ERROR"}, "pleat: select at least one mesh object")
            return None
        depsgraph = context.evaluated_depsgraph_get()
        sources = [(o.name, *(base_arrays(o) if has_rig(o) else object_arrays(o, depsgraph)))
                   for o in objects]
        attributes = {o.name: object_attributes(o) for o in objects if has_rig(o)}
        params = {"max_rounds": self.max_rounds, "align": self.align}
        job = Job(pleat, sources, sizes, params,
                  self.cage_screen_size if self.cage else None, attributes)
        return job, {o.name: o for o in objects}

    def _finish(self, context, job, by_name):
        """Adds the baked levels as objects and reports; the operator's return value (also
        recorded in ``last_result``)."""
        global last_result
        result, added = self._add_and_report(job, by_name)
        last_result = (result, [o.name for o in added])
        return result

    def _add_and_report(self, job, by_name):
        """Adds the baked levels as objects and reports errors: (result set, objects)."""
        added = []
        for name, kind, n_p, positions, triangles, stats in job.done:
            label = f"{name}_{kind}{n_p:g}"
            added.append(new_object(label, positions, triangles, by_name[name], stats,
                                    job.transferred.get((name, kind, n_p))))
        for obj in added:
            obj.select_set(True)
        cancelled = any(msg == "cancelled" for _, msg in job.errors)
        failures = [(n, m) for n, m in job.errors if n]
        for name, message in failures:
            self.report({"ERROR"}, f"pleat: {name}: {message}")
        if cancelled:
            self.report({"WARNING"}, f"pleat: cancelled; kept {len(added)} baked level(s)")
            return {"CANCELLED"}, added
        if failures:
            return ({"CANCELLED"} if not added else {"FINISHED"}), added
        self.report({"INFO"}, f"pleat: added {len(added)} object(s)")
        return {"FINISHED"}, added

    def execute(self, context):
        """Synchronous bake (scripts, background mode, redo panel)."""
        prepared = self._prepare(context)
        if prepared is None:
            return {"CANCELLED"}
        job, by_name = prepared
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            job.run()
        finally:
            wm.progress_end()
        return self._finish(context, job, by_name)

    def invoke(self, context, event):
        """Interactive bake on a worker thread; the modal handler shows progress and maps Esc
        to a cancel."""
        prepared = self._prepare(context)
        if prepared is None:
            return {"CANCELLED"}
        self._job, self._by_name = prepared
        self._thread = threading.Thread(target=self._job.run, daemon=True)
        self._thread.start()
        wm = context.window_manager
        wm.progress_begin(0, 100)
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = self._job
        if event.type == "ESC":
            job.cancel()
        if event.type != "TIMER":
            return {"PASS_THROUGH"} if event.type != "ESC" else {"RUNNING_MODAL"}
        wm = context.window_manager
        wm.progress_update(int(100 * job.fraction))
        context.workspace.status_text_set(
            f"pleat: {job.stage} {100 * job.fraction:.0f}%  (Esc to cancel)")
        if not job.finished.is_set():
            return {"RUNNING_MODAL"}
        self._thread.join()
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)
        return self._finish(context, job, self._by_name)


class PleatPreferences(bpy.types.AddonPreferences):
    bl_idname = __name__

    package_dir: StringProperty(
        name="pleat Python package", subtype="DIR_PATH", default="",
        description="Folder holding the 'pleat' package (e.g. bindings/python), when "
                    "'import pleat' does not find it")

    def draw(self, context):
        self.layout.prop(self, "package_dir")


def _menu(self, context):
    self.layout.operator(OBJECT_OT_pleat_bake_lods.bl_idname)


_CLASSES = (PleatPreferences, OBJECT_OT_pleat_bake_lods)


def register():
    for c in _CLASSES:
        bpy.utils.register_class(c)
    bpy.types.VIEW3D_MT_object.append(_menu)


def unregister():
    bpy.types.VIEW3D_MT_object.remove(_menu)
    for c in reversed(_CLASSES):
        bpy.utils.unregister_class(c)


if __name__ == "__main__":
    register()
