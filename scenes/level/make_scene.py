"""A level as an artist exports it: one glTF binary holding a furnished room, its lights and its
lightmap UVs, with the object transforms, parenting and linked duplicates Blender keeps.

level.glb (Y up, metres, as Blender's glTF exporter writes it):
- floor (5 x 4 m plane), back_wall and side_wall (thin boxes, 2.6 m tall), a table, two chairs
  that are linked duplicates of one mesh (chair_a, chair_b: one glTF mesh, two nodes), a shelf
  parented to the back wall, and two books parented to the shelf (linked duplicates again), all
  placed by their object transforms (not applied), each with texture UVs in channel 0 and
  lightmap UVs (Smart UV Project) in channel 1;
- lights of each kind: an emissive 1 x 0.5 m ceiling panel (a quad whose material emits, facing
  down), an emissive disc of radius 0.2 m, a point light, a spot light and a sun
  (KHR_lights_punctual).

lamp.glb is a second level whose only lights are emissive meshes of other shapes (mesh lights):
a paper lantern and a wall tube over a table and a chair in a corner (build_lamps).

level.fbx is level.glb exported as FBX with Blender's defaults (Y up, unit scale applied).

level_mm.glb uses an engine's conventions instead: the same room modelled in millimetres under a
root empty scaled by 0.001, and the emissive ceiling panel as its only light.

objects/<name>.glb hold each object of level.glb alone (its world transform on its node), and
scene_objects.toml bakes them as one file per object with the level's lights written out: the
same scene as `shadowbake bake level.glb`, for tests that compare the two.

    blender -b --factory-startup -P scenes/level/make_scene.py
"""

import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-P") + 1])), ".."))
import blender_assets as ba  # noqa: E402
import bpy  # noqa: E402
from mathutils import Matrix  # noqa: E402

ba.run_single_threaded()
here = ba.script_folder()


def material(name, emission=None, strength=1.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    if emission:
        bsdf.inputs["Emission"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    return m


def at_origin(obj):
    """Moves obj's origin to the centre of its bounding box's base, keeping it in place, so that
    its object transform (not its vertices) says where it is."""
    xs = [v.co.x for v in obj.data.vertices]
    ys = [v.co.y for v in obj.data.vertices]
    zs = [v.co.z for v in obj.data.vertices]
    centre = ((min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2, min(zs))
    for v in obj.data.vertices:
        v.co.x -= centre[0]
        v.co.y -= centre[1]
        v.co.z -= centre[2]
    obj.location = centre


def corner(width, depth, height):
    """A floor of width x depth metres centred on the origin, a back wall along its far edge and
    a side wall along its left one, 0.1 m thick and `height` tall, each placed by its origin."""
    bpy.ops.mesh.primitive_plane_add(size=1.0)
    floor = bpy.context.active_object
    floor.name = "floor"
    floor.scale = (width, depth, 1.0)
    ba.apply_transform(floor)
    x, y = width / 2, depth / 2
    back_wall = ba.box_between("back_wall", (-x, y - 0.1, 0.0), (x, y, height))
    side_wall = ba.box_between("side_wall", (-x, -y, 0.0), (-x + 0.1, y - 0.1, height))
    at_origin(back_wall)
    at_origin(side_wall)
    return floor, back_wall, side_wall


def build(unit=1.0, lights=True):
    """The room, in units of `unit` metres (1: metres, 0.001: millimetres): built in metres, then
    its mesh data and locations scaled by 1 / unit under a root empty scaled by unit. Returns its
    objects."""
    ba.reset()
    surface = material("plaster")
    floor, back_wall, side_wall = corner(5.0, 4.0, 2.6)

    table = ba.table("table", 1.2, 0.8)
    table.location = (0.3, 0.2, 0.0)
    table.rotation_euler = (0.0, 0.0, math.radians(8.0))

    chair_a = ba.chair("chair_a")
    chair_a.location = (0.35, -0.45, 0.0)
    chair_a.rotation_euler = (0.0, 0.0, math.radians(170.0))
    chair_b = chair_a.copy()  # a linked duplicate: the same mesh data
    chair_b.name = "chair_b"
    bpy.context.collection.objects.link(chair_b)
    chair_b.location = (0.2, 0.85, 0.0)
    chair_b.rotation_euler = (0.0, 0.0, math.radians(-10.0))

    shelf = ba.box_between("shelf", (-0.6, -0.15, -0.02), (0.6, 0.15, 0.02))
    shelf.parent = back_wall
    shelf.location = (1.0, 1.75, 1.4)  # relative to the wall's origin (its base)
    shelf.location.x -= back_wall.location.x
    shelf.location.y -= back_wall.location.y
    book_a = ba.box_between("book_a", (-0.02, -0.1, 0.0), (0.02, 0.1, 0.28))
    book_a.parent = shelf
    book_a.location = (-0.3, 0.0, 0.02)
    book_a.rotation_euler = (0.0, math.radians(12.0), 0.0)
    book_b = book_a.copy()
    book_b.name = "book_b"
    bpy.context.collection.objects.link(book_b)
    book_b.location = (0.25, 0.0, 0.02)
    book_b.rotation_euler = (0.0, 0.0, 0.0)

    objects = [floor, back_wall, side_wall, table, chair_a, chair_b, shelf, book_a, book_b]
    for obj in objects:
        obj.data.materials.clear()
        obj.data.materials.append(surface)
    for obj in (floor, back_wall, side_wall, table, chair_a, shelf, book_a):
        ba.lightmap_uvs_smart(obj, gap=0.01)

    # The ceiling panel: a 1 x 0.5 m quad 2.4 m up, its front (the emitting side) facing down.
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.4, 0.3, 2.4),
                                     rotation=(math.pi, 0.0, 0.0))
    panel = bpy.context.active_object
    panel.name = "ceiling_panel"
    panel.scale = (1.0, 0.5, 1.0)
    panel.data.materials.append(material("panel_emission", emission=(1.0, 0.95, 0.85),
                                         strength=6.0))
    emitters = [panel]
    if lights:
        bpy.ops.mesh.primitive_circle_add(vertices=32, radius=0.2, fill_type="NGON",
                                          location=(-1.6, -1.2, 2.0), rotation=(math.pi, 0.0, 0.0))
        disc = bpy.context.active_object
        disc.name = "disc_lamp"
        disc.data.materials.append(material("disc_emission", emission=(0.9, 0.9, 1.0),
                                            strength=4.0))
        emitters.append(disc)

        point = bpy.data.objects.new("bulb", bpy.data.lights.new("bulb", "POINT"))
        point.data.energy = 150.0
        point.location = (1.6, -1.3, 1.8)
        spot = bpy.data.objects.new("spot", bpy.data.lights.new("spot", "SPOT"))
        spot.data.energy = 300.0
        spot.data.spot_size = math.radians(70.0)
        spot.location = (-1.4, 1.2, 2.4)
        sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
        sun.data.energy = 3.0
        sun.rotation_euler = (math.radians(40.0), 0.0, math.radians(30.0))
        for light in (point, spot, sun):
            bpy.context.collection.objects.link(light)
    if unit != 1.0:
        scaled = set()
        for obj in objects + emitters:
            if obj.data.name not in scaled:
                obj.data.transform(Matrix.Scale(1.0 / unit, 4))
                scaled.add(obj.data.name)
            obj.location = obj.location / unit
        root = bpy.data.objects.new("level_root", None)
        bpy.context.collection.objects.link(root)
        root.scale = (unit, unit, unit)
        for obj in objects + emitters:
            if obj.parent is None:
                obj.parent = root
    return objects


def export_level(path):
    bpy.ops.object.select_all(action="SELECT")
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", use_selection=False,
                              export_yup=True, export_texcoords=True, export_normals=True,
                              export_materials="EXPORT", export_colors=False,
                              export_apply=False, export_lights=True)


objects = build()
export_level(os.path.join(here, "level.glb"))
os.makedirs(os.path.join(here, "objects"), exist_ok=True)
for obj in objects:
    ba.select_only(obj)
    bpy.ops.export_scene.gltf(filepath=os.path.join(here, "objects", obj.name + ".glb"),
                              export_format="GLB", use_selection=True, export_yup=True,
                              export_texcoords=True, export_normals=True,
                              export_materials="NONE", export_colors=False, export_apply=False)
    print(f"{obj.name}: {ba.triangle_count(obj)} triangles")

build(unit=0.001, lights=False)
export_level(os.path.join(here, "level_mm.glb"))

# The metre level again, as FBX (Blender's defaults: Y up, -Z forward, unit scale applied), for
# the FBX route through Assimp.
build()
bpy.ops.object.select_all(action="SELECT")
bpy.ops.export_scene.fbx(filepath=os.path.join(here, "level.fbx"), use_selection=False,
                         object_types={"MESH", "LIGHT", "EMPTY"}, use_mesh_modifiers=True,
                         mesh_smooth_type="FACE", bake_anim=False)


def build_lamps():
    """lamp.glb: a reading corner lit only by emissive meshes that are no rectangle or disc, so
    mesh lights: a paper lantern (a UV sphere of 16 segments and 8 rings, radius 0.25 m) hanging
    above a table, and a wall tube (a cylinder of 16 sides, 1 m long, radius 0.03 m, capped)
    along the back wall; their outsides emit."""
    ba.reset()
    surface = material("plaster")
    floor, back_wall, side_wall = corner(3.0, 3.0, 2.4)
    table = ba.table("table", 1.0, 0.7)
    table.location = (0.0, 0.3, 0.0)
    table.rotation_euler = (0.0, 0.0, math.radians(-6.0))
    chair = ba.chair("chair")
    chair.location = (0.1, -0.35, 0.0)
    chair.rotation_euler = (0.0, 0.0, math.radians(175.0))
    objects = [floor, back_wall, side_wall, table, chair]
    for obj in objects:
        obj.data.materials.clear()
        obj.data.materials.append(surface)
        ba.lightmap_uvs_smart(obj, gap=0.01)

    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8, radius=0.25,
                                         location=(0.1, 0.3, 1.6))
    lantern = bpy.context.active_object
    lantern.name = "lantern"
    lantern.data.materials.append(material("lantern_emission", emission=(1.0, 0.85, 0.6),
                                           strength=3.0))
    bpy.ops.mesh.primitive_cylinder_add(vertices=16, radius=0.03, depth=1.0,
                                        end_fill_type="NGON", location=(-0.6, 1.3, 1.9),
                                        rotation=(0.0, math.pi / 2, 0.0))
    tube = bpy.context.active_object
    tube.name = "wall_tube"
    tube.data.materials.append(material("tube_emission", emission=(0.85, 0.9, 1.0),
                                        strength=20.0))
    return objects


build_lamps()
export_level(os.path.join(here, "lamp.glb"))
