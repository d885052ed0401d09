"""What Cycles' AO bake gives the faces of a two-sided sheet (docs/methods.md, "Ambient
occlusion"): a 1 m card of two coplanar faces back to back, in one mesh and as two objects, and
one face alone, baked at 1 m, 64 samples, 64².

    blender -b --factory-startup -P tests/tools/cycles_two_sided_card.py

Prints CARD <case> <mean AO over each face's texels, 2 texels in from its chart's edges>.
"""

import bmesh
import bpy
import numpy

RES = 64


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.world = bpy.data.worlds.new("ao")
    scene.world.light_settings.distance = 1.0
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 64
    scene.cycles.use_denoising = False
    scene.render.bake.margin = 0


def mesh_object(name, quads):
    """quads: (four corners counter-clockwise seen from the front, UV rectangle u0 v0 u1 v1)."""
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    uv = bm.loops.layers.uv.new("uv")
    for corners, (u0, v0, u1, v1) in quads:
        face = bm.faces.new([bm.verts.new(c) for c in corners])
        for loop, st in zip(face.loops, [(u0, v0), (u1, v0), (u1, v1), (u0, v1)]):
            loop[uv].uv = st
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def bake(obj):
    material = bpy.data.materials.new(obj.name)
    material.use_nodes = True
    image = bpy.data.images.new(obj.name, RES, RES, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    texture = material.node_tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    material.node_tree.nodes.active = texture
    obj.data.materials.append(material)
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.bake(type="AO")
    return numpy.array(image.pixels[:]).reshape(RES, RES, 4)[..., 0]


def mean(ao, rect):
    u0, v0, u1, v1 = rect
    return ao[int(v0 * RES) + 2:int(v1 * RES) - 2, int(u0 * RES) + 2:int(u1 * RES) - 2].mean()


A, B, C, D = (0, -0.5, 0), (0, 0.5, 0), (0, 0.5, 1), (0, -0.5, 1)  # the front faces +x
FRONT, BACK, WHOLE = (0, 0, 0.5, 1), (0.5, 0, 1, 1), (0, 0, 1, 1)

reset()
ao = bake(mesh_object("one_mesh", [([A, B, C, D], FRONT), ([B, A, D, C], BACK)]))
print(f"CARD one-mesh front {mean(ao, FRONT):.3f} back {mean(ao, BACK):.3f}")
reset()
front = mesh_object("front", [([A, B, C, D], WHOLE)])
back = mesh_object("back", [([B, A, D, C], WHOLE)])
print(f"CARD two-objects front {mean(bake(front), WHOLE):.3f} back {mean(bake(back), WHOLE):.3f}")
reset()
print(f"CARD one-face {mean(bake(mesh_object('alone', [([A, B, C, D], WHOLE)])), WHOLE):.3f}")
