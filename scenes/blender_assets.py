"""Helpers shared by the Blender scripts that make the realistic scenes under scenes/.

Each scene folder holds a `make_scene.py` run with Debian's Blender, headless:

    blender -b --factory-startup -P scenes/<name>/make_scene.py

It builds the objects the way an artist does (primitives, modifiers, smooth shading, a texture
UV map in channel 0 and a lightmap UV map made by Blender's own Lightmap Pack or Smart UV Project
in channel 1), exports each object as its own glTF 2.0 binary (.glb, Y up, as Blender's exporter
writes it) and writes scene.toml, which stands the Y-up files back up with rotate_deg = [90, 0, 0].
"""

import math
import os
import sys

import bpy


def reset():
    """An empty scene: no default cube, camera or light."""
    bpy.ops.wm.read_factory_settings(use_empty=True)


def select_only(obj):
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def apply_modifiers(obj):
    select_only(obj)
    for modifier in list(obj.modifiers):
        bpy.ops.object.modifier_apply(modifier=modifier.name)


def apply_transform(obj):
    select_only(obj)
    bpy.ops.object.transform_apply(location=True, rotation=True, scale=True)


def shade_smooth(obj, auto_smooth_deg=None):
    select_only(obj)
    bpy.ops.object.shade_smooth()
    if auto_smooth_deg is not None:
        obj.data.use_auto_smooth = True
        obj.data.auto_smooth_angle = math.radians(auto_smooth_deg)


def texture_uvs(obj, angle_deg=66.0):
    """Channel 0: a texture layout by Smart UV Project, unless the primitive already made one."""
    mesh = obj.data
    if len(mesh.uv_layers) == 0:
        mesh.uv_layers.new(name="UVMap")
        mesh.uv_layers.active_index = 0
        _in_edit_mode(obj, lambda: bpy.ops.uv.smart_project(angle_limit=math.radians(angle_deg),
                                                             island_margin=0.0))


def lightmap_uvs(obj, method="lightmap", margin=0.1):
    """Channel 1: the lightmap layout, by Lightmap Pack (one chart per quad or triangle pair)
    or Smart UV Project (angle-based charts), with Blender's island margin."""
    mesh = obj.data
    texture_uvs(obj)
    layer = mesh.uv_layers.new(name="Lightmap")
    mesh.uv_layers.active = layer
    if method == "lightmap":
        _in_edit_mode(obj, lambda: bpy.ops.uv.lightmap_pack(PREF_CONTEXT="ALL_FACES",
                                                             PREF_PACK_IN_ONE=True,
                                                             PREF_NEW_UVLAYER=False,
                                                             PREF_BOX_DIV=12,
                                                             PREF_MARGIN_DIV=margin))
    else:
        _in_edit_mode(obj, lambda: bpy.ops.uv.smart_project(angle_limit=math.radians(66.0),
                                                             island_margin=margin * 0.05))
    mesh.uv_layers.active_index = 0


def _in_edit_mode(obj, operator):
    select_only(obj)
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    operator()
    bpy.ops.object.mode_set(mode="OBJECT")


def export_glb(obj, folder, name):
    """Writes obj alone as folder/name.glb: Y up, normals and both UV maps, no materials."""
    select_only(obj)
    bpy.ops.export_scene.gltf(filepath=os.path.join(folder, name + ".glb"), export_format="GLB",
                              use_selection=True, export_yup=True, export_texcoords=True,
                              export_normals=True, export_materials="NONE",
                              export_colors=False, export_apply=True)


def triangle_count(obj):
    obj.data.calc_loop_triangles()
    return len(obj.data.loop_triangles)


def script_folder():
    """The folder of the make_scene.py Blender is running (its -P argument)."""
    argv = sys.argv
    script = argv[argv.index("-P") + 1] if "-P" in argv else argv[-1]
    return os.path.dirname(os.path.abspath(script))


# Helpers added for the corpus scenes (room, atrium, shelf, dense, hall). The ones above are
# unchanged, so suzanne/ regenerates as before.

def run_single_threaded():
    """Makes the run deterministic: unless Blender was started with `-t 1`, runs the same script
    again in a Blender started so, and exits with its status (1 if the script raised).

    Blender 3.4 sums smooth vertex normals with atomic adds across threads, so their last bits,
    and with them the exported normals and whatever is displaced along them, change from run to
    run; on one thread they do not. Call it first thing in make_scene.py; `blender -b
    --factory-startup -P scenes/<name>/make_scene.py` then writes the same bytes every time."""
    argv = sys.argv
    for flag in ("-t", "--threads"):
        if flag in argv and argv.index(flag) + 1 < len(argv) and argv[argv.index(flag) + 1] == "1":
            return
    import subprocess
    script = os.path.abspath(argv[argv.index("-P") + 1])
    print(f"blender_assets: running {script} again on one thread (-t 1), for a deterministic result",
          flush=True)
    status = subprocess.call([bpy.app.binary_path, "-b", "--factory-startup", "-t", "1",
                              "--python-exit-code", "1", "-P", script])
    sys.stdout.flush()
    os._exit(status)


def canonical_order(obj):
    """Renumbers obj's vertices, faces and face corners in an order fixed by the geometry alone.

    Some of Blender's primitives (the UV sphere among them) come out with their face corners in
    an order that changes from run to run, even on one thread, and every
    later step (subdivision sums, Smart UV Project's charts, the exporter's vertex order) follows
    that order, so the .glb would change too. Vertices are sorted by (z, y, x) (ties keep their
    order), each face starts at its lowest vertex (winding kept) and faces are sorted by their
    vertex lists; per-corner UV maps and per-face smooth flags travel with them. Call it on a
    primitive as soon as it is made and again after its modifiers are applied. (The other source
    of run-to-run change, threaded normals, is run_single_threaded's.)"""
    mesh = obj.data
    positions = [tuple(v.co) for v in mesh.vertices]
    order = sorted(range(len(positions)), key=lambda i: (positions[i][2], positions[i][1],
                                                         positions[i][0], i))
    new_index = [0] * len(order)
    for new, old in enumerate(order):
        new_index[old] = new
    uv_names = [layer.name for layer in mesh.uv_layers]
    uv_data = [[tuple(d.uv) for d in layer.data] for layer in mesh.uv_layers]
    faces = []
    for poly in mesh.polygons:
        corners = list(poly.loop_indices)
        verts = [new_index[mesh.loops[c].vertex_index] for c in corners]
        start = verts.index(min(verts))
        corners = corners[start:] + corners[:start]
        verts = verts[start:] + verts[:start]
        faces.append((verts, corners, poly.use_smooth))
    faces.sort(key=lambda face: face[0])
    rebuilt = bpy.data.meshes.new(mesh.name)
    rebuilt.from_pydata([positions[i] for i in order], [], [face[0] for face in faces])
    for name, data in zip(uv_names, uv_data):
        layer = rebuilt.uv_layers.new(name=name)
        flat = [coordinate for face in faces for c in face[1] for coordinate in data[c]]
        layer.data.foreach_set("uv", flat)
    rebuilt.polygons.foreach_set("use_smooth", [face[2] for face in faces])
    rebuilt.update()
    old = obj.data
    obj.data = rebuilt
    bpy.data.meshes.remove(old)
    rebuilt.name = obj.name


def lightmap_uvs_smart(obj, gap=0.01, angle_deg=66.0):
    """Channel 1 by Smart UV Project with margin_method='FRACTION': island_margin is a fraction
    of the final [0, 1] layout, so charts stay apart by the same number of texels whatever their
    count (gap 0.01 keeps them more than 4 texels apart at 256², 8 at 512²). Channel 0 is made
    first, as lightmap_uvs does. A lower angle_deg cuts more charts; curved, folded meshes such
    as Suzanne need about 45 degrees for charts that do not fold over themselves."""
    mesh = obj.data
    texture_uvs(obj)
    layer = mesh.uv_layers.new(name="Lightmap")
    mesh.uv_layers.active = layer
    _in_edit_mode(obj, lambda: bpy.ops.uv.smart_project(angle_limit=math.radians(angle_deg),
                                                         margin_method="FRACTION",
                                                         island_margin=gap))
    mesh.uv_layers.active_index = 0


def box(name, size, location=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0)):
    """A box of the given (x, y, z) size centred at location, transform applied; Blender's cube
    primitive, so channel 0 holds its cross-shaped texture UVs."""
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=location, rotation=rotation)
    obj = bpy.context.active_object
    obj.name = name
    obj.scale = size
    apply_transform(obj)
    canonical_order(obj)
    return obj


def box_between(name, lo, hi):
    """An axis-aligned box from corner lo to corner hi."""
    size = tuple(h - l for l, h in zip(lo, hi))
    centre = tuple((l + h) / 2 for l, h in zip(lo, hi))
    return box(name, size, centre)


def cylinder(name, radius, depth, location, vertices=32):
    """An upright cylinder of 32 segments (caps as n-gons) centred at location."""
    bpy.ops.mesh.primitive_cylinder_add(vertices=vertices, radius=radius, depth=depth,
                                        location=location)
    obj = bpy.context.active_object
    obj.name = name
    apply_transform(obj)
    canonical_order(obj)
    return obj


def uv_sphere(name, radius, location, segments=48, rings=24):
    """A UV sphere of segments x rings faces (48 x 24 = 1152)."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=segments, ring_count=rings, radius=radius,
                                         location=location)
    obj = bpy.context.active_object
    obj.name = name
    apply_transform(obj)
    canonical_order(obj)
    return obj


def join(objects, name):
    """Joins objects into the first one, renamed name, and returns it."""
    bpy.ops.object.select_all(action="DESELECT")
    for obj in objects:
        obj.select_set(True)
    bpy.context.view_layer.objects.active = objects[0]
    bpy.ops.object.join()
    joined = bpy.context.active_object
    joined.name = name
    return joined


def bevel(obj, width, segments=2, angle_deg=30.0):
    """A slight bevel on the edges sharper than angle_deg, applied."""
    modifier = obj.modifiers.new("bevel", "BEVEL")
    modifier.width = width
    modifier.segments = segments
    modifier.limit_method = "ANGLE"
    modifier.angle_limit = math.radians(angle_deg)
    apply_modifiers(obj)


def chair(name):
    """A chair at the origin, seat 0.44 m square and 0.47 m high, its back towards +y: seat, four
    legs, two back posts and a backrest, boxes joined into one object with a slight bevel."""
    seat_top, seat = 0.47, 0.04
    parts = [box_between("seat", (-0.22, -0.22, seat_top - seat), (0.22, 0.22, seat_top))]
    for i, (x, y) in enumerate(((-0.2, -0.2), (0.2, -0.2), (-0.2, 0.2), (0.2, 0.2))):
        parts.append(box_between(f"leg{i}", (x - 0.02, y - 0.02, 0.0),
                                 (x + 0.02, y + 0.02, seat_top - seat)))
    for i, x in enumerate((-0.2, 0.2)):
        parts.append(box_between(f"post{i}", (x - 0.02, 0.18, seat_top), (x + 0.02, 0.22, 0.92)))
    parts.append(box_between("backrest", (-0.22, 0.185, 0.64), (0.22, 0.215, 0.9)))
    obj = join(parts, name)
    bevel(obj, width=0.004, segments=2)
    return obj


def table(name, width, depth, height=0.76, top=0.04, leg=0.05, inset=0.06):
    """A table at the origin: a width x depth top on four square legs, joined, slightly
    bevelled."""
    parts = [box_between("top", (-width / 2, -depth / 2, height - top), (width / 2, depth / 2, height))]
    for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (-1, 1), (1, 1))):
        x, y = sx * (width / 2 - inset), sy * (depth / 2 - inset)
        parts.append(box_between(f"leg{i}", (x - leg / 2, y - leg / 2, 0.0),
                                 (x + leg / 2, y + leg / 2, height - top)))
    obj = join(parts, name)
    bevel(obj, width=0.004, segments=2)
    return obj


def place(obj, location=(0.0, 0.0, 0.0), rotation_z_deg=0.0):
    """Turns obj about Z (through its origin) and moves it, then applies the transform."""
    obj.rotation_euler = (0.0, 0.0, math.radians(rotation_z_deg))
    obj.location = location
    apply_transform(obj)


def lowest_z(obj):
    return min(v.co.z for v in obj.data.vertices)


def rest_on(obj, z=0.0):
    """Moves obj (transform applied) up or down so that its lowest vertex lies at height z."""
    dz = z - lowest_z(obj)
    for v in obj.data.vertices:
        v.co.z += dz
    obj.data.update()


def seeded_displace(obj, seed, strength, noise_scale, depth=2):
    """Displaces obj along its normals by Blender's Clouds (Perlin) texture and applies it. The
    texture has no seed of its own: the seed picks (with Python's seeded generator) where an empty,
    the texture's coordinate object, lies in the noise, so the same seed gives the same shape."""
    import random
    rng = random.Random(seed)
    texture = bpy.data.textures.new(f"noise_{obj.name}", "CLOUDS")
    texture.noise_scale = noise_scale
    texture.noise_depth = depth
    texture.noise_basis = "BLENDER_ORIGINAL"
    anchor = bpy.data.objects.new(f"noise_origin_{obj.name}", None)
    bpy.context.scene.collection.objects.link(anchor)
    anchor.location = tuple(rng.uniform(-50.0, 50.0) for _ in range(3))
    modifier = obj.modifiers.new("displace", "DISPLACE")
    modifier.texture = texture
    modifier.texture_coords = "OBJECT"
    modifier.texture_coords_object = anchor
    modifier.strength = strength
    modifier.mid_level = 0.5
    apply_modifiers(obj)
    bpy.data.objects.remove(anchor)


def toml_number(x):
    """A number as scene.toml writes it: at most 6 decimals, no trailing zeros."""
    text = f"{x:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def toml_vector(values):
    return "[" + ", ".join(toml_number(v) for v in values) + "]"


def write_scene_toml(path, comment, objects, lights, resolution=512, method="reference",
                     samples=64, texels_per_metre=None, output=()):
    """Writes a scene file. objects: dicts with name, mesh and optionally receiver, blocker, uv
    (default 1; None for a blocker without lightmap UVs, which then gets no uv key); every object gets rotate_deg = [90, 0, 0], which stands the Y-up
    .glb back up in the Z-up scene. lights: dicts with name, shape and the shape's keys
    (position, normal, up, size, radius, color, power, shadowmask_range), written in that order.
    texels_per_metre replaces resolution when given; output: lines of an [output] table."""
    lines = [line.rstrip() for line in comment.strip("\n").split("\n")]
    out = [("# " + line if line else "#") for line in lines]
    size = (f"texels_per_metre = {toml_number(texels_per_metre)}" if texels_per_metre
            else f"resolution = {resolution}")
    out += ["", "[bake]", size, f'method = "{method}"', f"samples = {samples}"]
    if output:
        out += ["", "[output]"] + list(output)
    for obj in objects:
        out += ["", "[[object]]", f'name = "{obj["name"]}"', f'mesh = "{obj["mesh"]}"']
        receiver = obj.get("receiver", True)
        if not receiver:
            out.append("receiver = false")
        if not obj.get("blocker", True):
            out.append("blocker = false")
        if obj.get("uv", 1) is not None:
            out.append(f"uv = {obj.get('uv', 1)}")
        out.append("rotate_deg = [90, 0, 0]")
    for light in lights:
        out += ["", "[[light]]", f'name = "{light["name"]}"', f'shape = "{light["shape"]}"']
        for key in ("position", "normal", "up", "size"):
            if key in light:
                out.append(f"{key} = {toml_vector(light[key])}")
        if "radius" in light:
            out.append(f"radius = {toml_number(light['radius'])}")
        if "color" in light:
            out.append(f"color = {toml_vector(light['color'])}")
        out.append(f"power = {toml_number(light['power'])}")
        if "shadowmask_range" in light:
            out.append(f"shadowmask_range = {toml_number(light['shadowmask_range'])}")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def sky_world(sky_type):
    """A new world of the current scene whose Background (Strength 1) is a Sky Texture of
    `sky_type` ("NISHITA", "PREETHAM", ...). Returns the Sky Texture node, to be set."""
    scene = bpy.context.scene
    world = bpy.data.worlds.new("sky")
    scene.world = world
    world.use_nodes = True
    nodes = world.node_tree.nodes
    sky = nodes.new("ShaderNodeTexSky")
    sky.sky_type = sky_type
    world.node_tree.links.new(sky.outputs["Color"], nodes["Background"].inputs["Color"])
    nodes["Background"].inputs["Strength"].default_value = 1.0
    return sky


def render_world_equirectangular(path, width, height, samples, color_depth="16", filter_width=None):
    """The scene's world through Cycles' equirectangular camera, looking along +X with +Z up (the
    image's middle column +X, its top row the zenith, as Cycles maps a direction), written to
    `path` as a ZIP-compressed float EXR of `color_depth` bits ("16" or "32"). With
    `filter_width` (pixels), Cycles' pixel filter. Rendered to a scratch file, then written again
    from its pixels alone: Cycles puts its render times in the file's header, which would change
    its bytes on every run. Returns the pixels (RGBA, bottom row first)."""
    scene = bpy.context.scene
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    camera.data.type = "PANO"
    if hasattr(camera.data, "panorama_type"):
        camera.data.panorama_type = "EQUIRECTANGULAR"
    else:
        camera.data.cycles.panorama_type = "EQUIRECTANGULAR"
    camera.rotation_euler = (math.radians(90.0), 0.0, math.radians(-90.0))
    scene.camera = camera
    scene.render.engine = "CYCLES"
    scene.cycles.samples = samples
    scene.cycles.device = "CPU"
    scene.cycles.use_denoising = False
    if filter_width is not None:
        scene.cycles.filter_width = filter_width
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = color_depth
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.exr_codec = "ZIP"
    scene.view_settings.view_transform = "Standard"
    scratch = path + ".render.exr"
    scene.render.filepath = scratch
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scratch)
    pixels = list(image.pixels)
    clean = bpy.data.images.new("world", width, height, float_buffer=True)
    clean.colorspace_settings.name = "Non-Color"
    clean.pixels[:] = pixels
    clean.save_render(path, scene=scene)
    os.remove(scratch)
    bpy.data.objects.remove(camera)
    return pixels
