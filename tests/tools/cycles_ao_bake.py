"""Blender Cycles' ambient-occlusion bake of a level file, as an independent cross-check of
`shadowbake bake LEVEL.glb --quantity ambient-occlusion` (docs/methods.md, "Ambient occlusion").

    blender -b --factory-startup -P tests/tools/cycles_ao_bake.py -- LEVEL.glb --out DIR \
        [--res 256] [--samples 256] [--distance 10] [--receivers ground,back_wall]

The file is imported by Blender's own glTF importer. Its emissive meshes are hidden (shadowbake's
lights are not blockers). For each receiver (a mesh with a second UV set) Cycles bakes AO in the
lightmap UVs (channel 1) with the world's AO distance set to --distance and --samples samples,
into DIR/<receiver>.ao.exr (Non-Color, row 0 is v = 1 as shadowbake writes) and
DIR/<receiver>.baked.exr (1 where Cycles baked a texel); prints BAKE_SECONDS per receiver.
Cycles averages each texel over its footprint where shadowbake takes its centre: compare over the
texels whose neighbours are covered too (shadowbake compare --mask).
"""

import argparse
import os
import sys
import time

import bpy
import numpy

# Blender 3.4's glTF importer uses numpy.bool, which Debian 12's numpy 1.24 no longer has.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

ap = argparse.ArgumentParser(prog="cycles_ao_bake.py")
ap.add_argument("level")
ap.add_argument("--out", required=True)
ap.add_argument("--res", type=int, default=256)
ap.add_argument("--samples", type=int, default=256)
ap.add_argument("--distance", type=float, default=10.0)
ap.add_argument("--receivers")
args = ap.parse_args(sys.argv[sys.argv.index("--") + 1:])

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.world = bpy.data.worlds.new("ao")
scene.world.light_settings.distance = args.distance
bpy.ops.import_scene.gltf(filepath=os.path.abspath(args.level))


def emits(obj):
    for slot in obj.material_slots:
        material = slot.material
        if material is None or not material.use_nodes:
            continue
        for node in material.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED":
                colour = node.inputs["Emission"].default_value
                if max(colour[:3]) > 0 and node.inputs["Emission Strength"].default_value > 0:
                    return True
    return False


for obj in scene.objects:
    if obj.type == "LIGHT" or (obj.type == "MESH" and emits(obj)):
        obj.hide_render = True
receivers = {o.name: o for o in scene.objects
             if o.type == "MESH" and not o.hide_render and len(o.data.uv_layers) >= 2}
if args.receivers:
    receivers = {n: receivers[n] for n in args.receivers.split(",")}

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = args.samples
scene.cycles.use_denoising = False
scene.cycles.use_adaptive_sampling = False
scene.render.bake.margin = 0
scene.render.bake.use_clear = True
os.makedirs(args.out, exist_ok=True)


def save(name, pixels):
    image = bpy.data.images.new(name, args.res, args.res, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    image.pixels[:] = pixels.ravel()
    image.filepath_raw = os.path.join(args.out, name + ".exr")
    image.file_format = "OPEN_EXR"
    image.save()


for name, receiver in receivers.items():
    receiver.data.uv_layers.active_index = 1
    for i, layer in enumerate(receiver.data.uv_layers):
        layer.active_render = i == 1
    material = bpy.data.materials.new(name + "_bake")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    image = bpy.data.images.new(name, args.res, args.res, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"  # the bake's values as they are
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = image
    nodes.active = texture
    receiver.data.materials.clear()
    receiver.data.materials.append(material)
    bpy.ops.object.select_all(action="DESELECT")
    receiver.select_set(True)
    bpy.context.view_layer.objects.active = receiver
    start = time.time()
    bpy.ops.object.bake(type="AO")
    print(f"BAKE_SECONDS {name} {time.time() - start:.2f}", flush=True)
    pixels = numpy.array(image.pixels[:]).reshape(args.res, args.res, 4)
    ao = numpy.ones((args.res, args.res, 4))
    ao[:, :, :3] = pixels[:, :, :3]
    save(f"{name}.ao", ao)
    baked = numpy.ones((args.res, args.res, 4))
    baked[:, :, :3] = (pixels[:, :, 3:4] > 0.5).astype(float)
    save(f"{name}.baked", baked)
