"""Interactive-path test of the pleat LOD add-on, in a real Blender window (Xvfb):

    xvfb-run -a blender --factory-startup --enable-event-simulate -P bindings/blender/test_modal.py

invokes the operator as a click does (INVOKE_DEFAULT: worker thread + modal timer + progress),
waits for the LODs to appear, then starts a slower bake and presses Esc (a simulated key event):
the bake must end cancelled with nothing added. Exits 0 when both pass, 1 otherwise (.ci/blender.sh
runs it when xvfb-run is installed). Mesh and package as in test_addon.py.
"""
import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from test_addon import corpus_mesh, select_only  # noqa: E402  (also enables the add-on)

import pleat_lod  # noqa: E402

DEADLINE = time.monotonic() + 600


def finish(ok, message):
    print(f"{'ok' if ok else 'FAILED'}: {message}")
    print(f"blender modal: {'1 passed, 0 failed' if ok else '0 passed, 1 failed'}")
    sys.stdout.flush()
    os._exit(0 if ok else 1)


def view3d():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    return win, area


def invoke(**props):
    win, area = view3d()
    pleat_lod.last_result = (None, [])
    with bpy.context.temp_override(window=win, area=area):
        return bpy.ops.object.pleat_bake_lods("INVOKE_DEFAULT", **props)


def start():
    bpy.ops.wm.obj_import(filepath=corpus_mesh())
    src = bpy.context.selected_objects[0]
    select_only(src)
    r = invoke(screen_sizes="40,20", max_rounds=10)
    assert r == {"RUNNING_MODAL"}, r
    print(f"  invoked on {src.name}: {r}")
    bpy.app.timers.register(lambda: wait_for_bake(src), first_interval=0.2)


def wait_for_bake(src):
    result, added = pleat_lod.last_result
    if result is None:
        if time.monotonic() > DEADLINE:
            finish(False, "the modal bake did not finish")
        return 0.2
    if result != {"FINISHED"} or added != [f"{src.name}_LOD40", f"{src.name}_LOD20"]:
        finish(False, f"modal bake: {result} {added}")
    print(f"  modal bake finished: {added}")
    select_only(src)
    r = invoke(screen_sizes="400,200,100", max_rounds=50)
    assert r == {"RUNNING_MODAL"}, r
    win, _ = view3d()
    win.event_simulate(type="ESC", value="PRESS")
    win.event_simulate(type="ESC", value="RELEASE")
    bpy.app.timers.register(wait_for_cancel, first_interval=0.2)
    return None


def wait_for_cancel():
    result, added = pleat_lod.last_result
    if result is None:
        if time.monotonic() > DEADLINE:
            finish(False, "Esc did not end the bake")
        return 0.2
    finish(result == {"CANCELLED"} and not added, f"Esc -> {result}, kept {added}")


bpy.app.timers.register(start, first_interval=1.0)
