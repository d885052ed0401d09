"""Objects whose lightmaps show their UV seams: a smooth cylinder (32 segments, auto smooth 30°,
so its side is one smooth surface cut by a seam and its caps are hard edges) and a bevelled box
(0.8 x 0.6 x 0.5 m, 4-segment bevel of 6 cm, auto smooth 35°, so every bevel is smooth and every
flat face meets it along a chart border), standing on a 3 x 3 m floor. Lightmap UVs in channel 1:
Smart UV Project for the cylinder, the box and the floor, and a second box, box_lightmap_pack,
by Lightmap Pack (a chart per quad: a seam along almost every edge; margin 0.5). A 1 x 0.6 m panel lights
them from above and one side, the cylinder's penumbra falling across the box, so that the light
changes across every seam.

    blender -b --factory-startup -P scenes/seams/make_scene.py
"""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-P") + 1])), ".."))
import blender_assets as ba  # noqa: E402
import bpy  # noqa: E402

ba.run_single_threaded()
here = ba.script_folder()
ba.reset()

bpy.ops.mesh.primitive_plane_add(size=3.0, location=(0, 0, 0))
floor = bpy.context.active_object
floor.name = "floor"

cylinder = ba.cylinder("cylinder", radius=0.3, depth=1.0, location=(-0.6, 0.3, 0.5))
ba.shade_smooth(cylinder, auto_smooth_deg=30.0)

box = ba.box("box", (0.8, 0.6, 0.5), location=(0.5, -0.2, 0.25))
ba.bevel(box, 0.06, segments=4, angle_deg=30.0)
ba.canonical_order(box)
ba.shade_smooth(box, auto_smooth_deg=35.0)

packed = ba.box("box_lightmap_pack", (0.5, 0.5, 0.4), location=(0.3, 0.9, 0.2))
ba.bevel(packed, 0.05, segments=4, angle_deg=30.0)
ba.canonical_order(packed)
ba.shade_smooth(packed, auto_smooth_deg=35.0)

for obj in (floor, cylinder, box):
    ba.lightmap_uvs_smart(obj, gap=0.01)
ba.lightmap_uvs(packed, method="lightmap", margin=0.5)

objects = (floor, cylinder, box, packed)
for obj in objects:
    ba.export_glb(obj, here, obj.name)
    print(f"{obj.name}: {ba.triangle_count(obj)} triangles")

ba.write_scene_toml(
    os.path.join(here, "scene.toml"),
    """written by scenes/seams/make_scene.py (Blender); edit that script, not this file.
A smooth cylinder and two bevelled, smooth-shaded boxes on a floor, all receivers, glTF binaries
exported Y up with lightmap UVs in channel 1 (Smart UV Project; Lightmap Pack for
box_lightmap_pack); rotate_deg stands them back up in this Z-up scene. A panel lights them from
above and one side, the cylinder shadowing the box, so the light changes across every UV seam.""",
    [{"name": obj.name, "mesh": obj.name + ".glb"} for obj in objects],
    [dict(name="panel", shape="rectangle", position=(-1.8, 1.0, 1.7), normal=(0.9, -0.5, -0.7),
          up=(0, 1, 0), size=(1.0, 0.6), power=200.0)],
    resolution=256, samples=64)
