"""A furnished hall as an artist blocks it out: a 10 x 6 m room 3.5 m high (floor, four walls and
a ceiling slab, thin boxes) holding 20 objects: two tables, four chairs (boxes joined, slightly
bevelled), six crates (two stacked), four cylinders (two barrels, a stool and a pillar from floor
to ceiling, 32 segments) and four smooth UV spheres (one on a table). Nine lights of all three
shapes: three ceiling panels and a disk downlight flush under the ceiling (1.5 cm below it), two
disk sconces 5 cm off the walls, a rectangular panel on the east wall, a sphere pendant over a
table and a sphere glowing 0.3 m above the floor. Every object has lightmap UVs (Smart UV
Project) in channel 1 and Blender's own texture UVs in channel 0 and is exported as Y-up glTF
binary; twelve of them are receivers (the room, the tables, a chair, a crate, the pillar, a
sphere), the rest blockers only, to keep the bake short.

    blender -b --factory-startup -P scenes/hall/make_scene.py
"""

import math
import os
import random
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-P") + 1])), ".."))
import blender_assets as ba  # noqa: E402
import bpy  # noqa: E402

ba.run_single_threaded()
here = ba.script_folder()
ba.reset()
rng = random.Random(5)

# The room: inside x in [-4.85, 4.85], y in [-2.85, 2.85], z in [0, 3.5]; walls 0.15 m thick.
W, D, H, T = 5.0, 3.0, 3.5, 0.15
bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0, 0, 0))
floor = bpy.context.active_object
floor.name = "floor"
floor.scale = (2 * W, 2 * D, 1.0)
ba.apply_transform(floor)
room = [floor,
        ba.box_between("wall_north", (-W, D - T, 0.0), (W, D, H)),
        ba.box_between("wall_south", (-W, -D, 0.0), (W, -D + T, H)),
        ba.box_between("wall_west", (-W, -D + T, 0.0), (-W + T, D - T, H)),
        ba.box_between("wall_east", (W - T, -D + T, 0.0), (W, D - T, H)),
        ba.box_between("ceiling", (-W, -D, H), (W, D, H + 0.15))]


def turned(x, y, cx, cy, deg):
    """(x, y) turned by deg about (cx, cy)."""
    a = math.radians(deg)
    return (cx + x * math.cos(a) - y * math.sin(a), cy + x * math.sin(a) + y * math.cos(a))


furniture = []

# Tables and chairs; a chair's back is towards +y before it is turned, so it faces -y.
for name, (cx, cy), (width, depth), deg in (("table_1", (-2.6, 0.6), (1.4, 0.8), 0.0),
                                           ("table_2", (1.8, -0.9), (1.2, 0.7), 15.0)):
    table = ba.table(name, width, depth)
    ba.place(table, location=(cx, cy, 0.0), rotation_z_deg=deg)
    furniture.append(table)
chair_spots = [((-2.75, 1.28), 0.0 + 4.0), ((-2.35, -0.08), 180.0 - 6.0),
               (turned(0.15, 0.62, 1.8, -0.9, 15.0), 15.0 + 10.0),
               (turned(-0.2, -0.63, 1.8, -0.9, 15.0), 195.0)]
for i, ((x, y), deg) in enumerate(chair_spots):
    chair = ba.chair(f"chair_{i + 1}")
    ba.place(chair, location=(x, y, 0.0), rotation_z_deg=deg)
    furniture.append(chair)

# Crates, each turned by a seeded angle; box_2 sits on box_1.
crates = [("box_1", (0.6, 0.6, 0.6), (3.9, 2.15, 0.0)),
          ("box_2", (0.45, 0.45, 0.45), (3.9, 2.15, 0.6)),
          ("box_3", (0.8, 0.5, 0.4), (-4.2, -2.2, 0.0)),
          ("box_4", (0.4, 0.4, 0.4), (-0.7, -2.25, 0.0)),
          ("box_5", (0.7, 0.7, 1.0), (4.2, -2.05, 0.0)),
          ("box_6", (0.35, 0.35, 0.35), (-0.4, 2.35, 0.0))]
for name, size, (x, y, z) in crates:
    crate = ba.box(name, size, (0.0, 0.0, size[2] / 2))
    ba.place(crate, location=(x, y, z), rotation_z_deg=rng.uniform(-25.0, 25.0))
    furniture.append(crate)

# Cylinders: two barrels, a stool, and a pillar from the floor to the ceiling.
for name, radius, height, (x, y) in (("cylinder_1", 0.28, 0.9, (3.0, 2.3)),
                                     ("cylinder_2", 0.28, 0.9, (-4.2, 1.9)),
                                     ("cylinder_3", 0.2, H, (0.0, 0.0)),
                                     ("cylinder_4", 0.18, 0.45, (-1.2, -1.5))):
    furniture.append(ba.cylinder(name, radius=radius, depth=height, location=(x, y, height / 2)))

# Spheres resting on the floor, one on table_1.
for name, radius, (x, y, z) in (("sphere_1", 0.3, (0.9, 1.4, 0.0)),
                                ("sphere_2", 0.2, (-3.6, -0.9, 0.0)),
                                ("sphere_3", 0.12, (-2.3, 0.5, 0.76)),
                                ("sphere_4", 0.35, (3.2, 0.9, 0.0))):
    furniture.append(ba.uv_sphere(name, radius=radius, location=(x, y, z + radius)))

objects = room + furniture
receivers = {"floor", "wall_north", "wall_south", "wall_west", "wall_east", "ceiling",
             "table_1", "table_2", "chair_1", "box_1", "cylinder_3", "sphere_1"}
total = 0
for obj in objects:
    ba.canonical_order(obj)
    if obj.name.startswith(("table", "chair", "cylinder")):
        ba.shade_smooth(obj, auto_smooth_deg=30.0)
    elif obj.name.startswith("sphere"):
        ba.shade_smooth(obj)
    ba.lightmap_uvs_smart(obj, gap=0.01)
    ba.export_glb(obj, here, obj.name)
    total += ba.triangle_count(obj)
    print(f"{obj.name}: {ba.triangle_count(obj)} triangles")
print(f"{len(objects)} objects ({len(furniture)} in the room), total: {total} triangles")

down, z_flush = (0, 0, -1), H - 0.015
lights = [
    dict(name="ceiling_panel_1", shape="rectangle", position=(-2.6, 0.6, z_flush), normal=down,
         up=(0, 1, 0), size=(1.2, 0.6), power=150.0),
    dict(name="ceiling_panel_2", shape="rectangle", position=(1.8, -0.9, z_flush), normal=down,
         up=(0, 1, 0), size=(1.2, 0.6), power=150.0),
    dict(name="ceiling_panel_3", shape="rectangle", position=(3.0, 1.6, z_flush), normal=down,
         up=(0, 1, 0), size=(0.6, 0.6), power=80.0),
    dict(name="downlight", shape="disk", position=(-1.0, -1.6, z_flush), normal=down,
         radius=0.1, power=40.0),
    dict(name="sconce_north", shape="disk", position=(-0.8, D - T - 0.05, 2.1), normal=(0, -1, 0),
         radius=0.12, color=(1.0, 0.85, 0.7), power=30.0),
    dict(name="sconce_west", shape="disk", position=(-W + T + 0.05, -0.6, 2.1), normal=(1, 0, 0),
         radius=0.12, color=(1.0, 0.85, 0.7), power=30.0),
    dict(name="wall_panel_east", shape="rectangle", position=(W - T - 0.02, 0.3, 1.7),
         normal=(-1, 0, 0), up=(0, 0, 1), size=(0.8, 1.2), color=(0.8, 0.9, 1.0), power=120.0),
    dict(name="pendant", shape="sphere", position=(-2.6, 0.6, 2.3), radius=0.08,
         color=(1.0, 0.8, 0.6), power=25.0),
    dict(name="floor_glow", shape="sphere", position=(4.2, 0.0, 0.3), radius=0.1,
         color=(1.0, 0.7, 0.5), power=20.0),
]
ba.write_scene_toml(
    os.path.join(here, "scene.toml"),
    """written by scenes/hall/make_scene.py (Blender); edit that script, not this file.
A furnished 10 x 6 x 3.5 m hall: floor, four walls, ceiling slab and 20 objects (2 tables, 4
chairs, 6 crates, 4 cylinders, 4 spheres), glTF binaries exported Y up with lightmap UVs in
channel 1 (Smart UV Project); rotate_deg stands them back up in this Z-up scene. 12 receivers,
the rest blockers only. Nine lights: three ceiling panels and a disk downlight 1.5 cm under the
ceiling, two disk sconces 5 cm off the walls, a panel on the east wall, a sphere pendant over
table_1 and a sphere 0.3 m above the floor.""",
    [{"name": obj.name, "mesh": obj.name + ".glb", "receiver": obj.name in receivers}
     for obj in objects],
    lights)

# The hall as a level for an engine: every object a receiver, each lightmap sized by its surface
# (40 texels per metre), packed into 2048² atlases, with per-light images, shadow masks and a
# glTF binary. Each light's shadow mask reaches only as far as its shadowmask_range, so lights far
# apart share a channel.
ranges = {"ceiling_panel_1": 3.5, "ceiling_panel_2": 3.5, "ceiling_panel_3": 3.0,
          "downlight": 2.5, "sconce_north": 2.5, "sconce_west": 2.5, "wall_panel_east": 3.0,
          "pendant": 2.0, "floor_glow": 2.0}
ba.write_scene_toml(
    os.path.join(here, "scene_level.toml"),
    """written by scenes/hall/make_scene.py (Blender); edit that script, not this file.
The hall of scene.toml as a level for an engine: all 26 objects are receivers, each lightmap
sized by its surface at 40 texels per metre and packed into 2048 x 2048 atlases (2 texels of
padding), with each light's own visibility, RGBA shadow masks (each light's channel reaches its
shadowmask_range, metres from its centre) and scene.glb with the atlases bound (MOZ_lightmap).""",
    [{"name": obj.name, "mesh": obj.name + ".glb"} for obj in objects],
    [dict(light, shadowmask_range=ranges[light["name"]]) for light in lights],
    samples=16, texels_per_metre=40,
    output=["atlas = { size = 2048, padding = 2 }", "per_light = true", "shadowmask = true",
            "gltf = true"])

# Six lights whose light meets everywhere on the floor: a shadow mask holds four of them, and the
# bake says which two it leaves out.
six = [light for light in lights if light["name"] in (
    "ceiling_panel_1", "ceiling_panel_2", "ceiling_panel_3", "downlight", "sconce_north",
    "sconce_west")]
ba.write_scene_toml(
    os.path.join(here, "scene_six_lights.toml"),
    """written by scenes/hall/make_scene.py (Blender); edit that script, not this file.
The hall of scene.toml (its 12 receivers) under six of its lights, the three ceiling panels, the
downlight and the two sconces, all of which reach the floor: shadow masks hold four of them (R,
G, B, A, in scene order), and the bake warns that the two sconces are left out.""",
    [{"name": obj.name, "mesh": obj.name + ".glb", "receiver": obj.name in receivers}
     for obj in objects],
    six, resolution=256, samples=16,
    output=["shadowmask = true", "per_light = true"])
