"""An atrium corner as an artist blocks it out: a 6 x 6 m floor, two walls and a ceiling slab at
3 m, four 32-segment columns, a bevelled bench, a smooth Suzanne (subdivision level 2, 15,744
triangles) on a box plinth and a 20,480-triangle blob (an icosphere displaced by a seeded Clouds
texture, applied). Lightmap UVs (Smart UV Project, charts a fixed fraction of the atlas apart) in
channel 1, Blender's own texture UVs in channel 0, each object exported as Y-up glTF binary.

Three scene files share the meshes:
  scene.toml         a 1.5 x 0.8 m ceiling panel 1.5 cm under the ceiling slab, facing down;
  scene_sconce.toml  a 0.12 m-radius disk sconce 5 cm off the back wall, facing out of it;
  scene_bulb.toml    a 0.1 m-radius sphere bulb 0.3 m above the floor among the objects.
The ceiling is a blocker only under the panel (it lies wholly behind it) and a receiver too
under the sconce and the bulb, which light it.

    blender -b --factory-startup -P scenes/atrium/make_scene.py
"""

import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-P") + 1])), ".."))
import blender_assets as ba  # noqa: E402
import bpy  # noqa: E402

ba.run_single_threaded()
here = ba.script_folder()
ba.reset()

# Floor x, y in [-3, 3]; the back wall's inner face at y = 2.85, the left wall's at x = -2.85;
# the ceiling slab's underside at z = 3.
bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0, 0, 0))
floor = bpy.context.active_object
floor.name = "floor"
wall_back = ba.box_between("wall_back", (-3.0, 2.85, 0.0), (3.0, 3.0, 3.0))
wall_left = ba.box_between("wall_left", (-3.0, -3.0, 0.0), (-2.85, 2.85, 3.0))
ceiling = ba.box_between("ceiling", (-3.0, -3.0, 3.0), (3.0, 3.0, 3.1))

columns = [ba.cylinder(f"column_{i + 1}", radius=0.18, depth=3.0, location=(x, y, 1.5))
           for i, (x, y) in enumerate(((-1.6, -1.6), (1.6, -1.6), (-1.6, 1.6), (1.6, 1.6)))]

# The bench: a seat on two slab legs, built at the origin, bevelled, then placed.
bench = ba.join([ba.box_between("seat", (-0.75, -0.2, 0.42), (0.75, 0.2, 0.47)),
                 ba.box_between("leg_1", (-0.68, -0.18, 0.0), (-0.62, 0.18, 0.42)),
                 ba.box_between("leg_2", (0.62, -0.18, 0.0), (0.68, 0.18, 0.42))], "bench")
ba.bevel(bench, width=0.005, segments=2)
ba.place(bench, location=(0.3, -1.3, 0.0), rotation_z_deg=8.0)
ba.canonical_order(bench)

plinth = ba.box_between("plinth", (-1.25, 0.75, 0.0), (-0.75, 1.25, 0.9))

bpy.ops.mesh.primitive_monkey_add(size=0.45, location=(-1.0, 1.0, 1.2),
                                  rotation=(math.radians(10.0), 0.0, math.radians(-30.0)))
suzanne = bpy.context.active_object
suzanne.name = "suzanne"
ba.canonical_order(suzanne)
subdivision = suzanne.modifiers.new("subdivision", "SUBSURF")
subdivision.levels = 2
subdivision.render_levels = 2
ba.apply_modifiers(suzanne)
ba.apply_transform(suzanne)
ba.rest_on(suzanne, 0.9)  # its chin on the plinth
ba.canonical_order(suzanne)

bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=6, radius=0.42, location=(1.05, 0.65, 0.5))
blob = bpy.context.active_object
blob.name = "blob"
ba.apply_transform(blob)
ba.canonical_order(blob)
ba.seeded_displace(blob, seed=2024, strength=0.22, noise_scale=0.35)
ba.rest_on(blob, -0.01)  # sunk 1 cm into the floor, as artists do so that nothing floats
ba.canonical_order(blob)

for obj in columns:
    ba.shade_smooth(obj, auto_smooth_deg=30.0)  # smooth sides, flat caps
ba.shade_smooth(bench, auto_smooth_deg=30.0)
ba.shade_smooth(suzanne)
ba.shade_smooth(blob)

objects = [floor, wall_back, wall_left, ceiling, *columns, bench, plinth, suzanne, blob]
for obj in objects:
    ba.lightmap_uvs_smart(obj, gap=0.01, angle_deg=45.0 if obj is suzanne else 66.0)

total = 0
for obj in objects:
    ba.export_glb(obj, here, obj.name)
    total += ba.triangle_count(obj)
    print(f"{obj.name}: {ba.triangle_count(obj)} triangles")
print(f"total: {total} triangles")


def scene_objects(ceiling_receives):
    return [{"name": obj.name, "mesh": obj.name + ".glb",
             "receiver": obj is not ceiling or ceiling_receives} for obj in objects]


header = """written by scenes/atrium/make_scene.py (Blender); edit that script, not this file.
An atrium corner: 6 x 6 m floor, two walls and a ceiling slab at 3 m, four columns, a bench, a
smooth Suzanne on a plinth and a displaced blob, glTF binaries exported Y up with lightmap UVs in
channel 1 (Smart UV Project); rotate_deg stands them back up in this Z-up scene.
"""
ba.write_scene_toml(
    os.path.join(here, "scene.toml"),
    header + "Lit by a 1.5 x 0.8 m ceiling panel 1.5 cm under the ceiling slab (a blocker only: it lies\n"
    "wholly behind the panel).",
    scene_objects(False),
    [dict(name="ceiling_panel", shape="rectangle", position=(0.0, 0.0, 2.985), normal=(0, 0, -1),
          up=(0, 1, 0), size=(1.5, 0.8), power=200.0)])
ba.write_scene_toml(
    os.path.join(here, "scene_sconce.toml"),
    header + "Lit by a 0.12 m-radius disk sconce 5 cm off the back wall, facing out of it, among the\n"
    "walls and columns; the ceiling is a receiver too.",
    scene_objects(True),
    [dict(name="sconce", shape="disk", position=(0.6, 2.8, 1.9), normal=(0, -1, 0), radius=0.12,
          color=(1.0, 0.85, 0.7), power=40.0)])
ba.write_scene_toml(
    os.path.join(here, "scene_bulb.toml"),
    header + "Lit by a 0.1 m-radius sphere bulb 0.3 m above the floor among the objects; the ceiling is a\n"
    "receiver too.",
    scene_objects(True),
    [dict(name="bulb", shape="sphere", position=(0.05, 0.2, 0.3), radius=0.1,
          color=(1.0, 0.9, 0.75), power=40.0)])
