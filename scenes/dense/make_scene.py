"""A dense blocker over a floor: a (2, 3) torus knot tube (256 x 14 quads, built from its
parametric curve with a Frenet frame), subdivided (level 2) and displaced by a seeded Clouds
texture, shade smooth: 114,688 triangles. It is a blocker only (receiver = false, texture UVs in
channel 0 only), so the bake's cost is the floor's texels against many triangles. The 4 x 4 m
floor (lightmap UVs in channel 1) is the receiver; the light a 0.6 x 0.6 m panel 3 m up. Each object
exported as Y-up glTF binary.

    blender -b --factory-startup -P scenes/dense/make_scene.py
"""

import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-P") + 1])), ".."))
import blender_assets as ba  # noqa: E402
import bpy  # noqa: E402
from mathutils import Vector  # noqa: E402

ba.run_single_threaded()
here = ba.script_folder()
ba.reset()

# The knot's centre line, p = 2 turns around the axis and q = 3 through the hole, scaled to about
# 1.8 m across; the tube's ring at each sample lies in the plane of the normal and binormal.
P, Q, SCALE, TUBE = 2, 3, 0.3, 0.085
ALONG, AROUND = 256, 14


def curve(t):
    r = math.cos(Q * t) + 2.0
    return Vector((r * math.cos(P * t), r * math.sin(P * t), -math.sin(Q * t))) * SCALE


step = 2.0 * math.pi / ALONG
centres = [curve(i * step) for i in range(ALONG)]
verts, faces, uvs = [], [], []
for i in range(ALONG):
    previous, here_c, following = centres[i - 1], centres[i], centres[(i + 1) % ALONG]
    tangent = (following - previous).normalized()
    normal = (following - 2.0 * here_c + previous)
    normal = (normal - tangent * normal.dot(tangent)).normalized()
    binormal = tangent.cross(normal)
    for j in range(AROUND):
        a = 2.0 * math.pi * j / AROUND
        verts.append(tuple(here_c + (normal * math.cos(a) + binormal * math.sin(a)) * TUBE))
for i in range(ALONG):
    for j in range(AROUND):
        i1, j1 = (i + 1) % ALONG, (j + 1) % AROUND
        faces.append((i * AROUND + j, i1 * AROUND + j, i1 * AROUND + j1, i * AROUND + j1))
        # Texture UVs: u along the knot (8 repeats), v around the tube; seams where they wrap.
        u0, u1 = 8.0 * i / ALONG, 8.0 * (i + 1) / ALONG
        v0, v1 = j / AROUND, (j + 1) / AROUND
        uvs += [u0, v0, u1, v0, u1, v1, u0, v1]
mesh = bpy.data.meshes.new("knot")
mesh.from_pydata(verts, [], faces)
mesh.uv_layers.new(name="UVMap").data.foreach_set("uv", uvs)
mesh.update()
knot = bpy.data.objects.new("knot", mesh)
bpy.context.scene.collection.objects.link(knot)
knot.rotation_euler = (math.radians(18.0), math.radians(-8.0), 0.0)
knot.location = (0.1, -0.05, 1.05)
ba.apply_transform(knot)
ba.canonical_order(knot)
subdivision = knot.modifiers.new("subdivision", "SUBSURF")
subdivision.levels = 2
subdivision.render_levels = 2
ba.apply_modifiers(knot)
ba.canonical_order(knot)
ba.seeded_displace(knot, seed=11, strength=0.03, noise_scale=0.12)
ba.canonical_order(knot)
ba.shade_smooth(knot)

bpy.ops.mesh.primitive_plane_add(size=4.0, location=(0, 0, 0))
floor = bpy.context.active_object
floor.name = "floor"
ba.lightmap_uvs_smart(floor, gap=0.01)

total = 0
for obj in (floor, knot):
    ba.export_glb(obj, here, obj.name)
    total += ba.triangle_count(obj)
    print(f"{obj.name}: {ba.triangle_count(obj)} triangles, lowest point {ba.lowest_z(obj):.3f} m")
print(f"total: {total} triangles")

ba.write_scene_toml(
    os.path.join(here, "scene.toml"),
    """written by scenes/dense/make_scene.py (Blender); edit that script, not this file.
A subdivided, displaced torus knot (114,688 triangles, a blocker only) over a 4 x 4 m floor (the
receiver), glTF binaries exported Y up, the floor's lightmap UVs in channel 1 (Smart UV Project);
rotate_deg stands them back up in this Z-up scene. Lit by a 0.6 x 0.6 m panel 3 m up.""",
    [{"name": "floor", "mesh": "floor.glb"},
     {"name": "knot", "mesh": "knot.glb", "receiver": False}],
    [dict(name="panel", shape="rectangle", position=(-0.2, 0.15, 3.0), normal=(0.1, -0.05, -1.0),
          up=(0, 1, 0), size=(0.6, 0.6), power=150.0)])
