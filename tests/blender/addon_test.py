"""The Blender add-on (blender/shadowbake_blender) tested as a user would use it, headless:

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/addon_test.py -- \
        --shadowbake build/shadowbake --work DIR [--picture docs/images/blender.png]

(tests/blender/run_addon_test.sh runs it for CTest, label `blender`). It installs the add-on from
a zip it builds, makes a floor, a chair (boxes joined, texture UVs only: shadowbake generates its
lightmap UVs), a crate in a far corner (lightmap UVs of its own) and a rectangular area light,
and checks that

1. `shadowbake.bake` bakes and loads: each receiver's image in Blender is byte for byte (its file)
   and value for value (its pixels) a `shadowbake bake` of the exported level.glb and scene.toml
   into another folder, and the chair got the generated UV map;
2. the materials show the lightmap multiplied into the base colour, or as emission, which the next
   export must not carry (the bake still sees one light and reuses everything);
3. a second bake of the unchanged scene reuses every receiver (the chair's generated UVs held out
   of the export, so that shadowbake generates the same again); after the chair moves, a bake
   rebakes the chair and the floor under it and reuses the crate (manifest.json's
   `bake.reused`), still equal to a fresh bake of the new export, and replaces the images and
   materials instead of adding copies;
4. area lights as the add-on exports them are the same lights written by hand in a scene file,
   every number within 1e-6, and bake what those bake: within 1e-6 at every texel for lights
   Blender holds exactly, 1e-4 for the turned one (below, check_area_lights);
5. a bake stopped by SIGINT (what Esc sends) and a bake that fails on a mesh of no area leave the
   folder's earlier bake as it was, the failure naming the Blender object;
6. a point, a spot, a sun, an elliptic area light and the world export into a scene file that
   bakes;
7. with --picture, renders the baked scene with Cycles, the lightmaps shown as emission, to that
   PNG (the README's picture).

Exits 1 with a message on the first failure, 77 where Blender lacks what the add-on needs.
"""

import argparse
import math
import os
import shutil
import subprocess
import sys
import time

import bpy

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import addon_install  # noqa: E402  (beside this file)

try:
    import numpy
except ImportError:
    print("addon_test: SKIP: Blender's Python has no numpy, which Blender's glTF exporter needs "
          "(Debian: apt-get install python3-numpy)")
    sys.exit(77)


ap = argparse.ArgumentParser(prog="addon_test.py")
ap.add_argument("--shadowbake", required=True, help="the shadowbake executable")
ap.add_argument("--work", required=True, help="a scratch folder (emptied)")
ap.add_argument("--picture", help="also render the README's picture into this PNG")
args = ap.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
SHADOWBAKE = os.path.abspath(args.shadowbake)
WORK = os.path.abspath(args.work)
started = time.monotonic()


def fail(message):
    print(f"addon_test: FAIL: {message}", flush=True)
    sys.exit(1)


def step(message):
    print(f"addon_test: [{time.monotonic() - started:5.1f} s] {message}", flush=True)


def install_addon():
    try:
        addon_install.install_addon(WORK, SHADOWBAKE)
    except RuntimeError as error:
        fail(str(error))


def box_mesh(name, boxes, uv=True):
    """A mesh of axis-aligned boxes, each (centre, size), with texture UVs (one UV map)."""
    import bmesh
    bm = bmesh.new()
    if uv:
        bm.loops.layers.uv.new("UVMap")
    for centre, size in boxes:
        matrix = bpy_extras_matrix(centre, size)
        bmesh.ops.create_cube(bm, size=1.0, matrix=matrix, calc_uvs=uv)
    mesh = bpy.data.meshes.new(name)
    bm.to_mesh(mesh)
    bm.free()
    return mesh


def bpy_extras_matrix(centre, size):
    import mathutils
    return mathutils.Matrix.Translation(centre) @ mathutils.Matrix.Diagonal((*size, 1.0))


def build_scene():
    scene = bpy.context.scene
    scene.world = None
    collection = scene.collection
    floor_mesh = bpy.data.meshes.new("Floor")
    floor_mesh.from_pydata([(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], [], [(0, 1, 2, 3)])
    floor_mesh.uv_layers.new(name="UVMap")
    for loop, uv in zip(floor_mesh.uv_layers[0].data, [(0, 0), (1, 0), (1, 1), (0, 1)]):
        loop.uv = uv
    floor_mesh.uv_layers.new(name="Lightmap")  # a copy of UVMap: the floor's lightmap UVs
    floor = bpy.data.objects.new("Floor", floor_mesh)
    # The chair: a seat, four legs and a back, 0.45 m high, texture UVs only.
    legs = [((x, y, 0.2), (0.05, 0.05, 0.4)) for x in (-0.2, 0.2) for y in (-0.2, 0.2)]
    chair_mesh = box_mesh("Chair", legs + [((0, 0, 0.425), (0.5, 0.5, 0.05)),
                                           ((0, 0.225, 0.75), (0.5, 0.05, 0.6))])
    chair = bpy.data.objects.new("Chair seat", chair_mesh)  # a name shadowbake changes
    chair.location = (0.1, 0.2, 0.0)
    chair.rotation_euler = (0, 0, math.radians(15))
    crate_mesh = box_mesh("Crate", [((0, 0, 0.2), (0.4, 0.4, 0.4))])
    crate_mesh.uv_layers.new(name="Lightmap")
    crate = bpy.data.objects.new("Crate", crate_mesh)
    crate.location = (-1.6, 1.6, 0.0)
    light_data = bpy.data.lights.new("Panel", "AREA")
    light_data.shape = "RECTANGLE"
    light_data.size, light_data.size_y = 1.0, 0.6
    light_data.energy = 200.0
    light = bpy.data.objects.new("Panel", light_data)
    light.location = (0.2, 0.3, 2.2)
    light.rotation_euler = (math.radians(20), 0, math.radians(90))
    for obj in (floor, chair, crate, light):
        collection.objects.link(obj)
    settings = scene.shadowbake
    settings.output_dir = os.path.join(WORK, "bake")
    settings.resolution = 64
    settings.use_world = False
    return floor, chair, crate, light


def bake():
    before = time.monotonic()
    result = bpy.ops.shadowbake.bake()
    if result != {"FINISHED"}:
        fail(f"bpy.ops.shadowbake.bake() returned {result}")
    step(f"bpy.ops.shadowbake.bake() finished in {time.monotonic() - before:.1f} s")
    import json
    with open(os.path.join(WORK, "bake", "manifest.json")) as f:
        return json.load(f)


def cli_bake(scene_file, out):
    if os.path.exists(out):
        shutil.rmtree(out)
    run = subprocess.run([SHADOWBAKE, "bake", scene_file, "-o", out, "-q"], capture_output=True,
                         text=True)
    if run.returncode != 0:
        fail(f"shadowbake bake {scene_file} exited {run.returncode}: {run.stderr.strip()}")


def pixels(image):
    values = numpy.empty(len(image.pixels), dtype=numpy.float32)
    image.pixels.foreach_get(values)
    return values


def file_pixels(path):
    image = bpy.data.images.load(path, check_existing=False)
    image.colorspace_settings.name = "Non-Color"
    values = pixels(image)
    bpy.data.images.remove(image)
    return values


def check_equal_to_cli(manifest, cli_out):
    """Every receiver's image in Blender against the CLI's bake of the exported files."""
    for receiver in manifest["receivers"]:
        name = receiver["name"]
        image = bpy.data.images.get(f"shadowbake {name}")
        if image is None:
            fail(f"no image 'shadowbake {name}' in Blender after the bake")
        loaded = bpy.path.abspath(image.filepath)
        theirs = os.path.join(cli_out, receiver["files"]["lightmap"]["file"])
        with open(loaded, "rb") as a, open(theirs, "rb") as b:
            if a.read() != b.read():
                fail(f"{loaded} differs from the CLI's {theirs}")
        if not numpy.array_equal(pixels(image), file_pixels(theirs)):
            fail(f"image 'shadowbake {name}' in Blender holds other values than {theirs}")
        if image.size[0] != receiver["resolution"][0]:
            fail(f"image 'shadowbake {name}' is {image.size[0]} wide, the bake "
                 f"{receiver['resolution'][0]}")


def check_wired(obj, mode="MULTIPLY"):
    """The object's materials show its lightmap: multiplied into the Principled BSDF's base
    colour, or (EMISSION) as the surface itself."""
    image = bpy.data.images.get(f"shadowbake {obj.name.replace(' ', '_')}")
    for slot in obj.material_slots:
        nodes = slot.material.node_tree.nodes
        group = nodes.get("shadowbake_lightmap")
        if group is None or group.node_tree.nodes["shadowbake_image"].image != image:
            fail(f'material "{slot.material.name}" of "{obj.name}" does not show its lightmap')
        base = nodes["Principled BSDF"].inputs["Base Color"]
        surface = nodes["Material Output"].inputs["Surface"]
        wanted = {"MULTIPLY": (base, "Multiplied"), "EMISSION": (surface, "Emission")}[mode]
        socket, output = wanted
        if not socket.is_linked or socket.links[0].from_node != group or \
                socket.links[0].from_socket.name != output:
            fail(f'material "{slot.material.name}" of "{obj.name}" is not wired for {mode}')
        if mode == "EMISSION" and base.is_linked:
            fail(f'material "{slot.material.name}": Emission left the base colour multiplied')


# The light of build_scene written by hand in glTF's Y-up frame, where Blender's (x, y, z) is
# (x, z, -y) (docs/blender.md). Its rotation is Rz(90°) · Rx(20°): Blender's light shines along
# its local -Z, which Rx(20°) turns to (0, sin 20°, -cos 20°) and Rz(90°) to (-sin 20°, 0,
# -cos 20°), in Y-up (-sin 20°, -cos 20°, 0); its local Y, the rectangle's height (Size Y), goes
# to (0, cos 20°, sin 20°), then (-cos 20°, 0, sin 20°), in Y-up (-cos 20°, sin 20°, 0). Size X
# (1 m) is the width, along up × normal.
TURNED_BY_HAND = """\
[[light]]
name = "Panel"
shape = "rectangle"
position = [0.2, 2.2, -0.3]
normal = [-0.3420201433256687, -0.9396926207859084, 0]
up = [-0.9396926207859084, 0.3420201433256687, 0]
size = [1.0, 0.6]
power = 200.0
"""

# Lights whose every number Blender holds exactly (its floats are 32-bit: 0.2 is not, and
# neither are the sine and cosine of a turn other than a half turn): a rectangle turned half a
# turn about Z (the quaternion (0, 0, 0, 1)), so that its local Y, its height, runs along world
# -Y, in Y-up (0, 0, 1); a disk 0.25 m across scaled twice, radius 0.25 m. Both shine along -Z,
# in Y-up (0, -1, 0).
EXACT_BY_HAND = """\
[[light]]
name = "Panel"
shape = "rectangle"
position = [0.25, 2.25, 0.375]
normal = [0, -1, 0]
up = [0, 0, 1]
size = [1.0, 0.625]
power = 200.0

[[light]]
name = "Disk"
shape = "disk"
position = [-0.5, 1.75, -0.5]
normal = [0, -1, 0]
radius = 0.25
power = 50.0
"""


def make_lights_exact(light):
    light.location = (0.25, -0.375, 2.25)
    light.rotation_mode = "QUATERNION"
    light.rotation_quaternion = (0.0, 0.0, 0.0, 1.0)
    light.data.size, light.data.size_y = 1.0, 0.625
    disk_data = bpy.data.lights.new("Disk", "AREA")
    disk_data.shape = "DISK"
    disk_data.size = 0.25
    disk_data.energy = 50.0
    disk = bpy.data.objects.new("Disk", disk_data)
    disk.location = (-0.5, 0.5, 1.75)
    disk.scale = (2.0, 2.0, 2.0)
    bpy.context.scene.collection.objects.link(disk)


def hand_written_difference(manifest, lights, label):
    """The largest difference, over every receiver's texels, between the add-on's last bake and
    a bake of its level.glb with `lights` written by hand."""
    folder = os.path.join(WORK, label)
    os.makedirs(folder, exist_ok=True)
    glb = os.path.join(WORK, "bake", "blender-export", "level.glb")
    scene_file = os.path.join(folder, "scene.toml")
    with open(scene_file, "w") as f:
        f.write(f'[bake]\nresolution = 64\nmethod = "backprojection"\nquantity = "visibility"\n\n'
                f'[[import]]\nfile = "{glb}"\nlights = false\n\n{lights}')
    cli_bake(scene_file, os.path.join(folder, "out"))
    worst = 0.0
    for receiver in manifest["receivers"]:
        file = receiver["files"]["lightmap"]["file"]
        ours = file_pixels(os.path.join(WORK, "bake", file))
        theirs = file_pixels(os.path.join(folder, "out", file))
        worst = max(worst, float(numpy.abs(ours - theirs).max()))
    return worst


def exported_light_difference(by_hand):
    """The largest difference between the numbers of the add-on's exported [[light]] tables and
    the same lights written by hand (`by_hand`); a word that differs fails."""
    import tomllib
    with open(os.path.join(WORK, "bake", "blender-export", "scene.toml"), "rb") as f:
        exported = {light["name"]: light for light in tomllib.load(f).get("light", [])}
    worst = 0.0
    for hand in tomllib.loads(by_hand)["light"]:
        ours = exported.get(hand["name"])
        if ours is None:
            fail(f'the add-on exported no light "{hand["name"]}"')
        for key, value in hand.items():
            if key not in ours:
                fail(f'the exported light "{hand["name"]}" has no {key}')
            if isinstance(value, str):
                if ours[key] != value:
                    fail(f'the exported light "{hand["name"]}" has {key} {ours[key]!r}, by hand '
                         f'{value!r}')
                continue
            pairs = zip(ours[key], value) if isinstance(value, list) else [(ours[key], value)]
            worst = max([worst] + [abs(float(a) - float(b)) for a, b in pairs])
    return worst


def check_against_hand(manifest, by_hand, what, bake_bound):
    """The exported `what` against the same lights written by hand (`by_hand`): every number
    within 1e-6 (Blender's 32-bit floats are about 1e-8 from the decimals), and its bake within
    `bake_bound` at every texel."""
    numbers = exported_light_difference(by_hand)
    baked = hand_written_difference(manifest, by_hand, "hand_" + what.replace(" ", "_"))
    step(f"the {what} as exported against the same by hand: numbers {numbers:.3g}, bake "
         f"{baked:.3g} apart at most")
    if numbers > 1e-6:
        fail(f"the exported {what}'s numbers are {numbers:.3g} from the hand-written (> 1e-6)")
    if baked > bake_bound:
        fail(f"the exported {what} bakes {baked:.3g} away from the hand-written (> {bake_bound:g}):"
             " its position, normal, up or size is exported wrong")


def check_area_lights(manifest, light):
    # The turned light: its normal and up come from Blender's 32-bit sines and cosines of 32-bit
    # angles, 1e-8 from the decimals written by hand. Measured: one chair texel moves by 1.9e-5
    # at the default 32 light rows and by 3.6e-6 at 64, the same with 4096 samples and max_cell
    # = 1 (chair RMSE 6e-7; floor 6e-8 at most, crate 0): as a blocker edge that crosses a
    # row's line would, the backprojection's midpoint rule across rows (scene-format.md,
    # `light_rows`). So its bake is held to 1e-4, which a wrong axis, size or sign exceeds by
    # far, and the lights below, whose every number Blender holds exactly, to 1e-6.
    check_against_hand(manifest, TURNED_BY_HAND, "turned rectangle", 1e-4)
    make_lights_exact(light)
    check_against_hand(bake(), EXACT_BY_HAND, "exact rectangle and disk", 1e-6)


def render_picture(path, light):
    """The baked scene rendered by Cycles with the lightmaps as emission, what the viewport
    shows (background mode has no OpenGL for a viewport picture): irradiance, exposed by the
    bake's own white point (manifest.json's png_white_point), lit by the turned panel alone."""
    import json
    import mathutils
    scene = bpy.context.scene
    bpy.data.objects.remove(bpy.data.objects["Disk"])
    light.rotation_mode = "XYZ"
    light.rotation_euler = (math.radians(-25), 0, math.radians(90))
    light.location = (-0.6, 1.0, 1.5)
    light.data.size, light.data.size_y = 0.6, 0.4
    settings = scene.shadowbake
    settings.output_dir = os.path.join(WORK, "picture")
    settings.size_mode = "DENSITY"
    settings.texels_per_metre = 96
    settings.quantity = "irradiance"
    settings.preview = "EMISSION"
    if bpy.ops.shadowbake.bake() != {"FINISHED"}:
        fail("the picture's bake failed")
    with open(os.path.join(WORK, "picture", "manifest.json")) as f:
        settings.preview_strength = 1.0 / json.load(f)["png_white_point"]
    if bpy.ops.shadowbake.load() != {"FINISHED"}:
        fail("bpy.ops.shadowbake.load() failed")
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.location = (3.2, -3.4, 2.6)
    direction = mathutils.Vector((-0.3, 0.3, 0.3)) - camera.location
    camera.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    camera.data.lens = 35
    scene.camera = camera
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 16
    scene.cycles.use_denoising = False
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_x, scene.render.resolution_y = 800, 500
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = os.path.abspath(path)
    bpy.ops.render.render(write_still=True)
    step(f"wrote {path}")


def folder_state(folder):
    """The names and bytes of the files of a bake's folder (the export and the cache aside)."""
    state = {}
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if os.path.isfile(path):
            with open(path, "rb") as f:
                state[name] = f.read()
        elif name != "blender-export":
            state[name] = "folder"
    return state


def check_cancel():
    """Esc's path: the bake stopped by SIGINT mid-way leaves the earlier bake as it was."""
    from shadowbake_blender import bake_process
    folder = os.path.join(WORK, "bake")
    before = folder_state(folder)
    cmd = bake_process.command(SHADOWBAKE, os.path.join(folder, "blender-export", "scene.toml"),
                               folder, "final") + ["--method", "reference", "--samples", "200000"]
    process = bake_process.BakeProcess(cmd)
    deadline = time.monotonic() + 20
    while process.poll() <= 0 and process.returncode is None and time.monotonic() < deadline:
        time.sleep(0.05)
    if process.returncode is not None:
        fail(f"the slow bake ended (exit code {process.returncode}) before it could be cancelled")
    process.cancel()
    # shadowbake cleans up, then ends by the signal itself (a shell's 130; Popen's -2).
    if process.returncode not in (-2, 130):
        fail(f"the cancelled bake exited {process.returncode}, not by SIGINT")
    if folder_state(folder) != before:
        fail("the cancelled bake changed the folder's earlier bake")
    step("a bake cancelled by SIGINT at progress "
         f"{process.progress:.2f} left the earlier bake as it was")


def check_error_names_object():
    """A bad object: the operator fails with shadowbake's error naming the Blender object."""
    mesh = bpy.data.meshes.new("Bad wedge")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (2, 0, 0)], [], [(0, 1, 2)])  # no area
    mesh.uv_layers.new(name="UVMap")
    bad = bpy.data.objects.new("Bad wedge", mesh)
    bpy.context.scene.collection.objects.link(bad)
    folder = os.path.join(WORK, "bake")
    before = folder_state(folder)
    try:
        bpy.ops.shadowbake.bake()
    except RuntimeError as error:
        message = str(error)
    else:
        fail("the bake of a scene with a mesh of no area succeeded")
    if 'object "Bad wedge"' not in message:
        fail(f"the error does not name the Blender object \"Bad wedge\": {message}")
    if folder_state(folder) != before:
        fail("the failed bake changed the folder's earlier bake")
    bpy.data.objects.remove(bad)
    step(f"a failed bake reports {message.strip()!r} and keeps the earlier bake")


def check_every_light_type():
    """Every kind of Blender light, and the world, exports into a scene file shadowbake bakes."""
    scene = bpy.context.scene
    added = []
    for name, kind, place in (("Bulb", "POINT", (1.0, -1.0, 1.5)), ("Spot", "SPOT", (-1, -1, 2)),
                              ("Sun", "SUN", (0, 0, 5)), ("Oval", "AREA", (1, 1, 2))):
        data = bpy.data.lights.new(name, kind)
        data.energy = 10.0 if kind != "SUN" else 2.0
        obj = bpy.data.objects.new(name, data)
        obj.location = place
        scene.collection.objects.link(obj)
        added.append(obj)
    bpy.data.lights["Spot"].shadow_soft_size = 0.1
    bpy.data.lights["Sun"].angle = math.radians(3)
    bpy.data.lights["Oval"].shape = "ELLIPSE"
    bpy.data.lights["Oval"].size, bpy.data.lights["Oval"].size_y = 0.4, 0.3
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.5
    scene.world = world
    scene.shadowbake.use_world = True
    # Preview bakes a quarter of the side: 64², as the other bakes. (At 32² the chair's 36
    # generated charts do not fit even as points: an error naming the object.)
    scene.shadowbake.preset = "preview"
    scene.shadowbake.resolution = 256
    manifest = bake()
    lights = sorted(light["name"] for light in manifest["lights"])
    if lights != ["Bulb", "Disk", "Oval", "Panel", "Spot", "Sun", "world"]:
        fail(f"the bake of every light type has the lights {lights}")
    with open(os.path.join(WORK, "bake", "blender-export", "scene.toml")) as f:
        text = f.read()
    for line in ('shape = "sphere"', 'shape = "spot"', 'shape = "sun"', 'shape = "disk"',
                 'shape = "sky"', "angle_deg = 3.0", "cone_deg = 45.0"):
        if line not in text:
            fail(f"the exported scene file has no line {line!r}:\n{text}")
    for obj in added:
        bpy.data.objects.remove(obj)
    scene.world = None
    scene.shadowbake.use_world = False
    scene.shadowbake.preset = "final"
    scene.shadowbake.resolution = 64
    step("a point, a spot, a sun, an ellipse and the world export and bake")


def check_unit_scale_warning():
    """A Unit Scale other than 1 is said: shadowbake bakes a Blender unit as a metre."""
    export_module = __import__(f"{addon_install.ADDON}.scene_export", fromlist=["x"])
    units = bpy.context.scene.unit_settings
    units.system, units.scale_length = "METRIC", 0.01
    try:
        export = export_module.write_scene(bpy.context, bpy.context.scene.shadowbake,
                                           os.path.join(WORK, "unit-scale"))
    finally:
        units.scale_length = 1.0
    if not any("Unit Scale is 0.01" in warning for warning in export.warnings):
        fail(f"a Unit Scale of 0.01 exported without a warning: {export.warnings}")
    step("a Unit Scale other than 1 is a warning")


def main():
    if os.path.exists(WORK):
        shutil.rmtree(WORK)
    os.makedirs(WORK)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    install_addon()
    floor, chair, crate, light = build_scene()
    step("scene built; first bake")
    manifest = bake()
    export = os.path.join(WORK, "bake", "blender-export", "scene.toml")
    cli_bake(export, os.path.join(WORK, "cli1"))
    check_equal_to_cli(manifest, os.path.join(WORK, "cli1"))
    for obj in (floor, chair, crate):
        check_wired(obj)
    if "shadowbake" not in chair.data.uv_layers:
        fail('the chair has no UV map "shadowbake" after the bake generated its lightmap UVs')
    uvs = numpy.empty(2 * len(chair.data.loops), dtype=numpy.float32)
    chair.data.uv_layers["shadowbake"].data.foreach_get("uv", uvs)
    if uvs.min() < 0 or uvs.max() > 1 or uvs.max() - uvs.min() < 0.5:
        fail(f"the chair's generated UVs span [{uvs.min()}, {uvs.max()}], not the unit square")
    step("first bake: every lightmap in Blender is byte for byte the CLI's bake of the export")

    manifest = bake()
    if not all(r["bake"]["reused"] for r in manifest["receivers"]):
        fail("a second bake of the unchanged scene rebaked " + ", ".join(
            f"{r['name']} ({r['bake']['why']})" for r in manifest["receivers"]
            if not r["bake"]["reused"]))
    check_equal_to_cli(manifest, os.path.join(WORK, "cli1"))
    step("bake again, nothing changed: every receiver reused, the chair's generated UVs too")

    # The Emission display, which shadowbake would read as emissive meshes (lights) were the
    # export to see it: a bake in that state must find the same one light and reuse everything.
    bpy.context.scene.shadowbake.preview = "EMISSION"
    if bpy.ops.shadowbake.load() != {"FINISHED"}:
        fail("bpy.ops.shadowbake.load() failed")
    for obj in (floor, chair, crate):
        check_wired(obj, "EMISSION")
    manifest = bake()
    lights = [light["name"] for light in manifest["lights"]]
    if lights != ["Panel"] or not all(r["bake"]["reused"] for r in manifest["receivers"]):
        fail(f"with the Emission display the bake saw the lights {lights} and rebaked " +
             ", ".join(r["name"] for r in manifest["receivers"] if not r["bake"]["reused"]))
    bpy.context.scene.shadowbake.preview = "MULTIPLY"
    if bpy.ops.shadowbake.load() != {"FINISHED"}:
        fail("bpy.ops.shadowbake.load() failed")
    for obj in (floor, chair, crate):
        check_wired(obj, "MULTIPLY")
    step("Emission display and back: the export sees no emitters, the bake reuses everything")

    chair.location.x += 0.3
    manifest = bake()
    rebaked = sorted(r["name"] for r in manifest["receivers"] if not r["bake"]["reused"])
    reused = sorted(r["name"] for r in manifest["receivers"] if r["bake"]["reused"])
    step(f"second bake: rebaked {rebaked}, reused {reused}")
    if rebaked != ["Chair_seat", "Floor"] or reused != ["Crate"]:
        fail(f"after moving the chair, rebaked {rebaked} and reused {reused}; expected the "
             "chair and the floor rebaked, the crate reused (why: " +
             "; ".join(f"{r['name']}: {r['bake']['why']}" for r in manifest["receivers"]) + ")")
    cli_bake(export, os.path.join(WORK, "cli2"))
    check_equal_to_cli(manifest, os.path.join(WORK, "cli2"))
    images = sorted(i.name for i in bpy.data.images if i.name.startswith("shadowbake"))
    if images != ["shadowbake Chair_seat", "shadowbake Crate", "shadowbake Floor"]:
        fail(f"after three bakes Blender holds the images {images}, not one per receiver")
    materials = sorted(m.name for m in bpy.data.materials)
    if len(materials) != 3:
        fail(f"after three bakes Blender holds the materials {materials}, not one per object")
    for obj in (floor, chair, crate):
        check_wired(obj)
    step("second bake: images replaced in place, still the CLI's bytes")

    check_area_lights(manifest, light)
    check_cancel()
    check_error_names_object()
    check_every_light_type()
    check_unit_scale_warning()
    if args.picture:
        render_picture(args.picture, light)
    print(f"addon_test: PASS in {time.monotonic() - started:.1f} s", flush=True)


main()
