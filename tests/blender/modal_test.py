"""The add-on's interactive path, which background mode cannot run: the Bake button's modal
operator (timer, status bar progress) to completion, Edit > Undo and Redo of a Load, then a second
bake cancelled by Esc.
Needs a display; with Xvfb and Mesa's software OpenGL:

    BLENDER_USER_SCRIPTS=/tmp/ui/scripts xvfb-run -a -s "-screen 0 1280x800x24" \
        blender --factory-startup --enable-event-simulate --python tests/blender/modal_test.py -- \
        --shadowbake build/shadowbake --work /tmp/ui

Prints `modal_test: PASS` and quits Blender with exit code 0, or `modal_test: FAIL: ...` and 1.
tests/blender/run_modal_test.sh runs it for CTest (label `blender`), skipped where there is no
Blender or no xvfb-run.
"""

import argparse
import os
import shutil
import sys
import time

import bpy

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import addon_install  # noqa: E402  (beside this file)

ADDON = addon_install.ADDON
ap = argparse.ArgumentParser(prog="modal_test.py")
ap.add_argument("--shadowbake", required=True)
ap.add_argument("--work", required=True)
args = ap.parse_args(sys.argv[sys.argv.index("--") + 1:])
WORK = os.path.abspath(args.work)
OUT = os.path.join(WORK, "bake")
state = {"phase": "start", "since": time.monotonic()}


def finish(message, code):
    print(f"modal_test: {message}", flush=True)
    os._exit(code)  # quit_blender() from a timer can leave the process waiting on the window


def fail(message):
    finish(f"FAIL: {message}", 1)


def setup():
    if os.path.exists(WORK):
        shutil.rmtree(WORK)
    os.makedirs(WORK)
    addon_install.install_addon(WORK, args.shadowbake)
    scene = bpy.context.scene
    scene.world = None
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj)
    floor = bpy.data.meshes.new("Floor")
    floor.from_pydata([(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], [], [(0, 1, 2, 3)])
    floor.uv_layers.new(name="UVMap")
    for loop, uv in zip(floor.uv_layers[0].data, [(0, 0), (1, 0), (1, 1), (0, 1)]):
        loop.uv = uv
    floor.uv_layers.new(name="Lightmap")
    cube = bpy.data.meshes.new("Box")
    cube.from_pydata([(x, y, z) for z in (0, 0.5) for y in (-0.25, 0.25) for x in (-0.25, 0.25)],
                     [], [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2),
                          (1, 3, 7, 5)])
    light = bpy.data.lights.new("Panel", "AREA")
    light.size, light.energy = 0.8, 100.0
    for name, data, place in (("Floor", floor, (0, 0, 0)), ("Box", cube, (0.3, 0, 0)),
                              ("Panel", light, (0, 0, 2))):
        obj = bpy.data.objects.new(name, data)
        obj.location = place
        scene.collection.objects.link(obj)
    settings = scene.shadowbake
    settings.output_dir = OUT
    settings.resolution = 64
    settings.use_world = False


def floor_shows(mode):
    """Whether the floor's material shows its lightmap as `mode` says (MULTIPLY: into the base
    colour; EMISSION: as the surface)."""
    nodes = bpy.data.objects["Floor"].material_slots[0].material.node_tree.nodes
    socket = (nodes["Principled BSDF"].inputs["Base Color"] if mode == "MULTIPLY"
              else nodes["Material Output"].inputs["Surface"])
    return socket.is_linked and socket.links[0].from_node.name == "shadowbake_lightmap"


def check_load_undo():
    """Load is one step of Blender's undo: after a Load that switches the display to Emission,
    Edit > Undo gives back the Multiply wiring, and Redo the Emission one."""
    if not floor_shows("MULTIPLY"):
        fail("after the modal bake the floor does not show its lightmap multiplied")
    bpy.context.scene.shadowbake.preview = "EMISSION"
    _, override = viewport_override()
    with bpy.context.temp_override(**override):
        # The step a user's last edit (here: the setting) leaves before the Load; then the Load
        # as the button runs it, pushing its own step (a script's call pushes none by default).
        bpy.ops.ed.undo_push(message="Emission display")
        if bpy.ops.shadowbake.load("EXEC_DEFAULT", True) != {"FINISHED"}:
            fail("bpy.ops.shadowbake.load() failed")
        if not floor_shows("EMISSION"):
            fail("Load with the Emission display left the floor multiplied")
        if bpy.ops.ed.undo() != {"FINISHED"}:
            fail("Edit > Undo after Load failed")
        if not floor_shows("MULTIPLY") or floor_shows("EMISSION"):
            fail("Edit > Undo after Load did not give back the Multiply wiring")
        if bpy.ops.ed.redo() != {"FINISHED"}:
            fail("Edit > Redo of Load failed")
        if not floor_shows("EMISSION"):
            fail("Edit > Redo did not bring back the Load's Emission wiring")
        # Back to Multiply, as a later Load would.
        bpy.context.scene.shadowbake.preview = "MULTIPLY"
        if bpy.ops.shadowbake.load() != {"FINISHED"}:
            fail("bpy.ops.shadowbake.load() failed")
    print("modal_test: Load undone by Edit > Undo and redone by Redo", flush=True)


def viewport_override():
    window = bpy.context.window_manager.windows[0]
    area = next(a for a in window.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    return window, dict(window=window, area=area, region=region)


def step():
    try:
        return advance()
    except Exception as error:  # a timer that raises is dropped and Blender would wait forever
        import traceback
        traceback.print_exc()
        fail(f"{type(error).__name__}: {error}")


def advance():
    phase = state["phase"]
    elapsed = time.monotonic() - state["since"]
    if elapsed > 120:
        fail(f"phase {phase} took more than 120 s")
    if phase == "start":
        setup()
        state["operator"] = __import__(f"{ADDON}.operators", fromlist=["x"]).SHADOWBAKE_OT_bake
        _, override = viewport_override()
        with bpy.context.temp_override(**override):
            result = bpy.ops.shadowbake.bake("INVOKE_DEFAULT")
        if result != {"RUNNING_MODAL"}:
            fail(f"the Bake button's invoke returned {result}, not RUNNING_MODAL")
        state.update(phase="baking", since=time.monotonic())
        print("modal_test: the bake runs as a modal operator", flush=True)
    elif phase == "baking":
        if state["operator"].running:
            return 0.2
        if state["operator"].outcome != "finished":
            fail(f"the modal bake ended {state['operator'].outcome!r}")
        images = sorted(i.name for i in bpy.data.images if i.name.startswith("shadowbake"))
        if images != ["shadowbake Box", "shadowbake Floor"]:
            fail(f"after the modal bake Blender holds the images {images}")
        with open(os.path.join(OUT, "manifest.json"), "rb") as f:
            state["manifest"] = f.read()
        print(f"modal_test: the modal bake finished in {elapsed:.1f} s and loaded {images}",
              flush=True)
        check_load_undo()
        # A slow bake (reference rays, many samples) to cancel with Esc.
        bpy.context.scene.shadowbake.method = "reference"
        bpy.context.scene.shadowbake.samples = 200000
        bpy.data.objects["Box"].location.x = -0.3
        _, override = viewport_override()
        with bpy.context.temp_override(**override):
            bpy.ops.shadowbake.bake("INVOKE_DEFAULT")
        state.update(phase="to_cancel", since=time.monotonic())
    elif phase == "to_cancel":
        if not state["operator"].running:
            fail("the slow bake ended before Esc")
        if elapsed < 1.5:
            return 0.2
        window, _ = viewport_override()
        window.event_simulate(type="ESC", value="PRESS")
        window.event_simulate(type="ESC", value="RELEASE")
        state.update(phase="cancelling", since=time.monotonic())
    elif phase == "cancelling":
        if state["operator"].running:
            return 0.2
        if state["operator"].outcome != "cancelled":
            fail(f"after Esc the bake ended {state['operator'].outcome!r}, not cancelled")
        with open(os.path.join(OUT, "manifest.json"), "rb") as f:
            if f.read() != state["manifest"]:
                fail("the bake cancelled by Esc changed the folder's earlier bake")
        leftovers = [n for n in os.listdir(OUT) if n.startswith(".shadowbake-staging")]
        if leftovers:
            fail(f"the cancelled bake left {leftovers}")
        finish(f"PASS (Esc stopped the bake in {elapsed:.1f} s; the earlier bake kept)", 0)
    return 0.2


bpy.app.timers.register(step, first_interval=1.0)
