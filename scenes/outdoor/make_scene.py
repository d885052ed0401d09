"""An outdoor level as an artist exports it: a courtyard under a sun and a sky.

courtyard.glb (Y up, metres, Blender's glTF exporter), every object with texture UVs in channel 0
and lightmap UVs (Smart UV Project) in channel 1:
- ground: a 24 x 24 m paved court (the receiver to bake at 4096²);
- back_wall (16 m, 4 m tall, three window openings) and side_wall (12 m, 3 m tall);
- arcade: six columns in front of the back wall under a 2 m deep roof slab;
- pergola: four posts under nine slender beams, whose shadows stripe the ground;
- tree_a, tree_b, tree_c: trunks under lumpy crowns (displaced icospheres);
- fence: posts every metre and two rails;
- lights: a sun (KHR_lights_punctual directional, 0.526°), an emissive 0.6 x 0.3 m panel under
  the arcade roof facing down and an emissive disc lamp of radius 0.15 m on a post.

sky.exr: the sky that goes with the sun, Blender's Nishita sky texture (sun disc off: the sun is
its own light) rendered by Cycles through an equirectangular camera at 512 x 256, the map a
`shape = "sky"` light reads. The sun lamp is aimed from the sky's brightest pixel, so the glow
and the shadows agree.

scene.toml bakes the courtyard with the sky; scene_preetham.toml with Preetham's analytic sky
around the level's sun instead of the map; scene_sun.toml bakes the ground alone at 4096² under
the sun alone (the convolution's own case, issue "outdoor light").

    blender -b --factory-startup -P scenes/outdoor/make_scene.py
"""

import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-P") + 1])), ".."))
import blender_assets as ba  # noqa: E402
import bpy  # noqa: E402

ba.run_single_threaded()
here = ba.script_folder()

SUN_ELEVATION_DEG = 38.0
SUN_ROTATION_DEG = 215.0  # Nishita's sun rotation about +Z


def material(name, emission=None, strength=1.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.7, 0.7, 0.7, 1.0)
    if emission:
        bsdf.inputs["Emission"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    return m


def render_sky(path):
    """The Nishita sky without its sun disc, through an equirectangular camera, as a float EXR.
    Returns the direction (Z up) of its brightest pixel, by Cycles' equirectangular mapping."""
    ba.reset()
    scene = bpy.context.scene
    sky = ba.sky_world("NISHITA")
    sky.sun_disc = False
    sky.sun_elevation = math.radians(SUN_ELEVATION_DEG)
    sky.sun_rotation = math.radians(SUN_ROTATION_DEG)
    w, h = 512, 256
    pixels = ba.render_world_equirectangular(path, w, h, samples=16)
    best, best_i = -1.0, 0
    for i in range(w * h):
        lum = 0.2126 * pixels[4 * i] + 0.7152 * pixels[4 * i + 1] + 0.0722 * pixels[4 * i + 2]
        if lum > best:
            best, best_i = lum, i
    x, y_up = best_i % w, best_i // w  # Blender's pixels start at the bottom row
    u, v = (x + 0.5) / w, (y_up + 0.5) / h
    phi, elevation = (0.5 - u) * 2 * math.pi, (v - 0.5) * math.pi
    scene.world = None
    return (math.cos(phi) * math.cos(elevation), math.sin(phi) * math.cos(elevation),
            math.sin(elevation))


def wall_with_windows(name, length, height, thickness, windows, sill=1.0, top=2.4, width=1.2):
    """A wall along +x from x = -length/2, its base on z = 0, `windows` openings evenly spaced:
    the piers between them and the parts under and over each, boxes joined."""
    parts = []
    x0 = -length / 2
    pitch = length / windows
    for i in range(windows):
        left, right = x0 + i * pitch, x0 + (i + 1) * pitch
        mid = (left + right) / 2
        parts.append(ba.box_between(f"{name}_pl{i}", (left, 0, 0), (mid - width / 2, thickness, height)))
        parts.append(ba.box_between(f"{name}_pr{i}", (mid + width / 2, 0, 0), (right, thickness, height)))
        parts.append(ba.box_between(f"{name}_u{i}", (mid - width / 2, 0, 0), (mid + width / 2, thickness, sill)))
        parts.append(ba.box_between(f"{name}_o{i}", (mid - width / 2, 0, top), (mid + width / 2, thickness, height)))
    return ba.join(parts, name)


def tree(name, location, seed, height=2.6, crown=1.3):
    trunk = ba.cylinder(f"{name}_trunk", 0.14, height, (0.0, 0.0, height / 2), vertices=12)
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=crown,
                                          location=(0.0, 0.0, height + 0.6 * crown))
    top = bpy.context.active_object
    top.name = f"{name}_crown"
    ba.apply_transform(top)
    ba.seeded_displace(top, seed, strength=0.45 * crown, noise_scale=0.8)
    obj = ba.join([trunk, top], name)
    ba.place(obj, location)
    return obj


def build():
    ba.reset()
    stone = material("stone")
    objects = []

    bpy.ops.mesh.primitive_plane_add(size=24.0)
    ground = bpy.context.active_object
    ground.name = "ground"
    objects.append(ground)

    back_wall = wall_with_windows("back_wall", 16.0, 4.0, 0.3, windows=3)
    ba.place(back_wall, (0.0, 8.0, 0.0))
    side_wall = ba.box_between("side_wall", (-8.3, -4.0, 0.0), (-8.0, 8.3, 3.0))
    objects += [back_wall, side_wall]

    columns = [ba.cylinder(f"column{i}", 0.2, 3.2, (-6.25 + 2.5 * i, 6.2, 1.6), vertices=16)
               for i in range(6)]
    roof = ba.box_between("roof", (-7.0, 5.9, 3.2), (7.0, 8.0, 3.45))
    arcade = ba.join(columns + [roof], "arcade")
    objects.append(arcade)

    posts = [ba.box_between(f"ppost{i}", (x - 0.08, y - 0.08, 0.0), (x + 0.08, y + 0.08, 2.6))
             for i, (x, y) in enumerate(((3.0, -5.0), (7.0, -5.0), (3.0, -1.0), (7.0, -1.0)))]
    beams = [ba.box_between(f"beam{i}", (2.8, -5.2 + 0.5 * i, 2.6), (7.2, -5.1 + 0.5 * i, 2.8))
             for i in range(9)]
    rails = [ba.box_between(f"prail{i}", (x - 0.06, -5.3, 2.45), (x + 0.06, -0.7, 2.6))
             for i, x in enumerate((3.0, 7.0))]
    pergola = ba.join(posts + beams + rails, "pergola")
    objects.append(pergola)

    objects += [tree("tree_a", (-4.0, -4.5, 0.0), 1), tree("tree_b", (-1.0, -8.0, 0.0), 2, 3.0, 1.6),
                tree("tree_c", (9.0, 3.0, 0.0), 3, 2.2, 1.1)]

    fence_parts = [ba.box_between(f"fpost{i}", (-6.0 + i - 0.04, -10.0, 0.0),
                                  (-6.0 + i + 0.04, -9.92, 1.2)) for i in range(13)]
    fence_parts += [ba.box_between(f"frail{i}", (-6.05, -10.0, z), (6.05, -9.95, z + 0.08))
                    for i, z in enumerate((0.45, 0.95))]
    objects.append(ba.join(fence_parts, "fence"))

    lamp_post = ba.cylinder("lamp_post", 0.05, 2.2, (4.0, 3.0, 1.1), vertices=12)
    objects.append(lamp_post)

    for obj in objects:
        obj.data.materials.clear()
        obj.data.materials.append(stone)
        ba.lightmap_uvs_smart(obj, gap=0.004 if obj is ground else 0.02)

    # The panel under the arcade roof, facing down, and the disc lamp over the post.
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 7.0, 3.15), rotation=(math.pi, 0.0, 0.0))
    panel = bpy.context.active_object
    panel.name = "arcade_panel"
    panel.scale = (0.6, 0.3, 1.0)
    panel.data.materials.append(material("panel_emission", emission=(1.0, 0.85, 0.6), strength=40.0))
    bpy.ops.mesh.primitive_circle_add(vertices=32, radius=0.15, fill_type="NGON",
                                      location=(4.0, 3.0, 2.25), rotation=(math.pi, 0.0, 0.0))
    disc = bpy.context.active_object
    disc.name = "post_lamp"
    disc.data.materials.append(material("lamp_emission", emission=(1.0, 0.9, 0.75), strength=60.0))
    return objects


sun_from = render_sky(os.path.join(here, "sky.exr"))
objects = build()
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
sun.data.energy = 4.0
sun.data.angle = math.radians(0.526)
bpy.context.collection.objects.link(sun)
# A sun lamp shines along its local -Z: turn -Z onto the direction away from the sun.
to_sun = sun_from
sun.rotation_mode = "QUATERNION"
from mathutils import Vector  # noqa: E402
sun.rotation_quaternion = Vector((0.0, 0.0, -1.0)).rotation_difference(-Vector(to_sun))
print("sun from", tuple(round(c, 4) for c in to_sun))

bpy.ops.object.select_all(action="SELECT")
bpy.ops.export_scene.gltf(filepath=os.path.join(here, "courtyard.glb"), export_format="GLB",
                          use_selection=False, export_yup=True, export_texcoords=True,
                          export_normals=True, export_materials="EXPORT", export_colors=False,
                          export_apply=False, export_lights=True)
for obj in objects:
    print(f"{obj.name}: {ba.triangle_count(obj)} triangles")
