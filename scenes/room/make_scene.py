"""A room corner as an artist blocks it out: a 4 x 4 m floor, a back wall and a side wall (thin
boxes, 2.5 m tall), a chair (seat, four legs, two back posts and a backrest: boxes joined into
one object, slightly bevelled) and a smooth ball (UV sphere, 48 x 24 = 1152 faces) resting on
the floor. Lightmap UVs (Smart UV Project, charts a fixed fraction of the atlas apart) in channel
1, Blender's own texture UVs in channel 0, each object exported as Y-up glTF binary.

The light is a tilted 1 x 0.5 m "window" panel 2.2 m up, 0.3 m in front of the back wall, facing
down into the room: the wall runs up to 2.5 m, so its top crosses the light's plane and lies
behind it. scene_disk.toml is the same scene lit by a 0.25 m-radius disk lamp in the panel's place.

    blender -b --factory-startup -P scenes/room/make_scene.py
"""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-P") + 1])), ".."))
import blender_assets as ba  # noqa: E402
import bpy  # noqa: E402

ba.run_single_threaded()
here = ba.script_folder()
ba.reset()

# Floor x, y in [-2, 2]; the back wall's inner face at y = 1.9, the side wall's at x = -1.9.
bpy.ops.mesh.primitive_plane_add(size=4.0, location=(0, 0, 0))
floor = bpy.context.active_object
floor.name = "floor"

back_wall = ba.box_between("back_wall", (-2.0, 1.9, 0.0), (2.0, 2.0, 2.5))
side_wall = ba.box_between("side_wall", (-2.0, -2.0, 0.0), (-1.9, 1.9, 2.5))

# The chair (seat 0.44 m square, 0.47 m high, back towards +y), built at the origin, then turned.
chair = ba.chair("chair")
ba.place(chair, location=(0.55, 0.35, 0.0), rotation_z_deg=-25.0)
ba.canonical_order(chair)

ball = ba.uv_sphere("ball", radius=0.3, location=(-0.75, -0.45, 0.3), segments=48, rings=24)

ba.shade_smooth(chair, auto_smooth_deg=30.0)
ba.shade_smooth(ball)
for obj in (floor, back_wall, side_wall, chair, ball):
    ba.lightmap_uvs_smart(obj, gap=0.01)

objects = (floor, back_wall, side_wall, chair, ball)
total = 0
for obj in objects:
    ba.export_glb(obj, here, obj.name)
    total += ba.triangle_count(obj)
    print(f"{obj.name}: {ba.triangle_count(obj)} triangles")
print(f"total: {total} triangles")

scene_objects = [{"name": obj.name, "mesh": obj.name + ".glb"} for obj in objects]
window = {"position": (0.2, 1.6, 2.2), "normal": (0.0, -0.6, -1.0)}
header = """written by scenes/room/make_scene.py (Blender); edit that script, not this file.
A room corner: 4 x 4 m floor, back and side walls 2.5 m tall (thin boxes), a bevelled chair and a
smooth ball, all receivers, glTF binaries exported Y up with lightmap UVs in channel 1 (Smart UV
Project); rotate_deg stands them back up in this Z-up scene.
"""
ba.write_scene_toml(
    os.path.join(here, "scene.toml"),
    header + "Lit by a tilted 1 x 0.5 m window panel 2.2 m up near the back wall, whose top crosses\n"
    "the panel's plane.",
    scene_objects,
    [dict(name="window", shape="rectangle", up=(0, 1, 0), size=(1.0, 0.5), power=150.0, **window)])
ba.write_scene_toml(
    os.path.join(here, "scene_disk.toml"),
    header + "Lit by a 0.25 m-radius disk lamp where scene.toml has its window panel.",
    scene_objects,
    [dict(name="lamp", shape="disk", radius=0.25, power=150.0, **window)])
