"""Headless test of the pleat LOD add-on (.ci/blender.sh runs it):

    blender -b --factory-startup --python-exit-code 1 -P bindings/blender/test_addon.py

1. imports a corpus mesh with Blender's OBJ importer, runs the operator (LOD chain + cage) and
   checks every new object through pleat's own check (watertight, self-intersection-free);
2. feeds degenerate meshes (all vertices at one point, a NaN vertex, no faces): each must give
   an error report (RuntimeError from bpy.ops carrying the message), not a crash;
3. cancels a bake from its progress callback (what Esc does) and checks nothing is added;
4. bakes a rigged object (vertex groups, a shape key, an armature modifier) and checks the LOD
   keeps all three, transferred by pleat.Transfer.

Mesh: $PLEAT_BLENDER_MESH, else shared/meshes/coarse_spot_1k.obj beside the repository (as CI lays
it out), else the repository's assets/dirty_two_boxes.obj.
The pleat package: $PLEAT_PYTHON (default bindings/python); its library: $PLEAT_LIBRARY.
"""
import os
import sys
import traceback

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
os.environ.setdefault("PLEAT_PYTHON", os.path.join(ROOT, "bindings", "python"))
sys.path.insert(0, HERE)

import addon_utils  # noqa: E402

addon_utils.enable("pleat_lod", default_set=True, handle_error=None)
import pleat_lod  # noqa: E402

pleat = pleat_lod.load_pleat()
print(f"pleat {pleat.version()} from {pleat.library_path()} in Blender {bpy.app.version_string}")

results = []


def case(fn):
    try:
        fn()
        results.append((fn.__name__, None))
        print(f"ok: {fn.__name__}")
    except Exception:  # noqa: BLE001 - every case reports, the script fails at the end
        results.append((fn.__name__, traceback.format_exc()))
        print(f"FAILED: {fn.__name__}\n{traceback.format_exc()}")


def corpus_mesh():
    env = os.environ.get("PLEAT_BLENDER_MESH")
    shared = os.path.join(ROOT, "..", "shared", "meshes", "coarse_spot_1k.obj")
    return env or (shared if os.path.exists(shared) else
                   os.path.join(ROOT, "assets", "dirty_two_boxes.obj"))


def select_only(obj):
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def checked(obj):
    """pleat's independent check of a Blender object (world space)."""
    V, F = pleat_lod.object_arrays(obj, bpy.context.evaluated_depsgraph_get())
    with pleat.Mesh.from_arrays(V, F) as m:
        return m.check(), len(F)


def bake_corpus_mesh():
    path = corpus_mesh()
    bpy.ops.wm.obj_import(filepath=path)
    src = bpy.context.selected_objects[0]
    select_only(src)
    _, source_faces = checked(src)
    result = bpy.ops.object.pleat_bake_lods(screen_sizes="40,20", max_rounds=10, cage=True,
                                            cage_screen_size=40)
    assert result == {"FINISHED"}, result
    for suffix in ("LOD40", "LOD20", "cage40"):
        obj = bpy.data.objects[f"{src.name}_{suffix}"]
        report, faces = checked(obj)
        assert report["is_watertight"] and report["self_intersection_free"], report
        assert obj["pleat_verified"] and faces == obj["pleat_face_count"], dict(obj)
        assert faces < source_faces or source_faces < 100, (faces, source_faces)
        print(f"  {os.path.basename(path)} ({source_faces} triangles) -> {obj.name}: {faces} "
              f"triangles, Hausdorff/l = {obj['pleat_hausdorff_relative']:.4f}, pleat check: "
              "watertight, self-intersection-free")
    assert bpy.data.objects[f"{src.name}_cage40"]["pleat_encloses_input"]


def degenerate(name, verts, faces):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    obj = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(obj)
    select_only(obj)
    before = len(bpy.data.objects)
    try:
        bpy.ops.object.pleat_bake_lods(screen_sizes="20")
    except RuntimeError as e:
        message = str(e).strip()
        assert "pleat" in message, message
        assert len(bpy.data.objects) == before
        print(f"  {name}: error report: {message}")
        return
    raise AssertionError(f"{name}: no error report")


def degenerate_meshes_give_error_reports():
    degenerate("collapsed", [(1, 1, 1)] * 3, [(0, 1, 2)])
    degenerate("nan_vertex", [(0, 0, 0), (1, 0, 0), (float("nan"), 1, 0)], [(0, 1, 2)])
    degenerate("no_faces", [(0, 0, 0), (1, 0, 0)], [])


def cancel_from_the_progress_callback():
    src = next(o for o in bpy.data.objects if o.name.startswith(("coarse", "dirty", "spot")))
    V, F = pleat_lod.object_arrays(src, bpy.context.evaluated_depsgraph_get())
    job = pleat_lod.Job(pleat, [(src.name, V, F)], [40.0], {"max_rounds": 10})
    calls = []
    reporter = job._progress

    def esc_on_first_report(index, part, parts):
        inner = reporter(index, part, parts)

        def report(stage, fraction):
            calls.append(stage)
            job.cancel()  # what Esc does in the modal operator
            return inner(stage, fraction)
        return report
    job._progress = esc_on_first_report
    job.run()
    assert calls and job.errors == [("", "cancelled")] and not job.done, (calls, job.errors)
    print(f"  cancelled after {len(calls)} progress report(s), nothing kept")


def rigged_object_keeps_groups_keys_and_armature():
    """Two touching boxes rigged to a two-bone armature, with a shape key: the LOD has the same
    vertex groups (weights summing to 1), shape key and armature modifier."""
    import numpy as np
    cube = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    verts = cube + [(x + 1.0, y, z) for x, y, z in cube]
    faces = quads + [tuple(i + 8 for i in q) for q in quads]
    me = bpy.data.meshes.new("rigged")
    me.from_pydata(verts, [], faces)
    obj = bpy.data.objects.new("rigged", me)
    bpy.context.scene.collection.objects.link(obj)
    arm = bpy.data.objects.new("rig", bpy.data.armatures.new("rig"))
    bpy.context.scene.collection.objects.link(arm)
    select_only(arm)
    bpy.ops.object.mode_set(mode="EDIT")
    for name, x in (("left", 0.5), ("right", 1.5)):
        bone = arm.data.edit_bones.new(name)
        bone.head, bone.tail = (x, 0.5, 0.0), (x, 0.5, 1.0)
    bpy.ops.object.mode_set(mode="OBJECT")
    for name, ids in (("left", range(8)), ("right", range(8, 16))):
        obj.vertex_groups.new(name=name).add(list(ids), 1.0, "REPLACE")
    obj.shape_key_add(name="Basis", from_mix=False)
    lift = obj.shape_key_add(name="lift", from_mix=False)
    for v in lift.data:
        v.co.z += 0.25
    obj.modifiers.new("Armature", "ARMATURE").object = arm
    select_only(obj)
    result = bpy.ops.object.pleat_bake_lods(screen_sizes="20", max_rounds=10)
    assert result == {"FINISHED"}, result
    lod = bpy.data.objects["rigged_LOD20"]
    assert sorted(g.name for g in lod.vertex_groups) == ["left", "right"]
    sums = np.zeros(len(lod.data.vertices))
    for v in lod.data.vertices:
        sums[v.index] = sum(g.weight for g in v.groups)
    assert np.all(np.abs(sums - 1.0) < 1e-4), sums
    keys = lod.data.shape_keys.key_blocks
    assert [k.name for k in keys] == ["Basis", "lift"]
    n = len(lod.data.vertices)
    base, up = np.empty(3 * n), np.empty(3 * n)
    keys["Basis"].data.foreach_get("co", base)
    keys["lift"].data.foreach_get("co", up)
    assert np.allclose((up - base).reshape(n, 3), [0.0, 0.0, 0.25], atol=1e-4)
    mods = [m for m in lod.modifiers if m.type == "ARMATURE"]
    assert len(mods) == 1 and mods[0].object == arm
    print(f"  rigged: {n} LOD vertices with groups left/right, shape key lift, armature rig")


def main():
    case(bake_corpus_mesh)
    case(rigged_object_keeps_groups_keys_and_armature)
    case(degenerate_meshes_give_error_reports)
    case(cancel_from_the_progress_callback)
    failed = [n for n, err in results if err]
    print(f"blender add-on: {len(results) - len(failed)} passed, {len(failed)} failed")
    if failed:
        sys.exit(1)


if __name__ == "__main__":
    main()
