"""Suzanne on a floor, as an artist hands it over: a smooth, subdivided Suzanne whose lightmap
UVs (Blender's Lightmap Pack) are in UV channel 1, with seams unlike those of its texture UVs in
channel 0, exported as Y-up glTF binary. The asset of the channel-1 import test
(tests/scene/mesh_import_test.cpp) and a scene of the corpus.

    blender -b --factory-startup -P scenes/suzanne/make_scene.py
"""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-P") + 1])), ".."))
import blender_assets as ba  # noqa: E402
import bpy  # noqa: E402

ba.run_single_threaded()
here = ba.script_folder()
ba.reset()

bpy.ops.mesh.primitive_monkey_add(size=1.0, location=(0, 0, 0.4), rotation=(0.35, 0, 0.6))
suzanne = bpy.context.active_object
suzanne.name = "suzanne"
subdivision = suzanne.modifiers.new("subdivision", "SUBSURF")
subdivision.levels = 1
subdivision.render_levels = 1
ba.apply_modifiers(suzanne)
ba.apply_transform(suzanne)
ba.shade_smooth(suzanne)
ba.lightmap_uvs(suzanne, method="lightmap", margin=0.1)

bpy.ops.mesh.primitive_plane_add(size=3.0, location=(0, 0, 0))
floor = bpy.context.active_object
floor.name = "floor"
ba.lightmap_uvs(floor, method="lightmap", margin=0.05)

for obj in (suzanne, floor):
    ba.export_glb(obj, here, obj.name)
    print(f"{obj.name}: {ba.triangle_count(obj)} triangles")

# Suzanne's lowest point rests just above the floor; the light is a tilted panel above.
with open(os.path.join(here, "scene.toml"), "w") as f:
    f.write("""# written by scenes/suzanne/make_scene.py (Blender); edit that script, not this file.
# A smooth Suzanne on a 3 x 3 m floor, both glTF binaries exported Y up with their lightmap UVs
# in channel 1 (Blender's Lightmap Pack); rotate_deg stands them back up in this Z-up scene.

[bake]
resolution = 512
method = "reference"
samples = 64

[[object]]
name = "floor"
mesh = "floor.glb"
uv = 1
rotate_deg = [90, 0, 0]

[[object]]
name = "suzanne"
mesh = "suzanne.glb"
uv = 1
rotate_deg = [90, 0, 0]

[[light]]
name = "panel"
shape = "rectangle"
position = [0.4, -0.3, 2.0]
normal = [-0.2, 0.15, -1.0]
size = [0.8, 0.5]
power = 100.0
""")
