"""Blender Cycles' bake of a level file (one glTF with its lights) per light, as an independent
cross-check of `shadowbake bake LEVEL.glb --per-light` (docs/methods.md, "Levels against Cycles").

    blender -b --factory-startup -P tests/tools/cycles_level_bake.py -- LEVEL.glb --out DIR \
        [--res 256] [--samples 256] [--receivers floor,table] [--lights bulb,ceiling_panel]
        [--sun-angle 0.526]
        [--sky MAP.exr | --sky-preetham TURBIDITY [--sky-sun sun]] [--sky-strength S]

The file is imported by Blender's own glTF importer, which is not shadowbake's reader: its lamps
(KHR_lights_punctual) stay lamps, made points (shadow_soft_size 0, as shadowbake reads them) and
suns of Blender's 0.526° (or --sun-angle), and its emissive meshes stay meshes that emit, which
Cycles samples as mesh lights (so shadowbake's turning them into rectangle and disk lights is
checked too), made to
emit from their front side alone as shadowbake's do. Emitters cast no shadows (shadowbake's lights
are not blockers). For each receiver (a mesh with a second UV
set) and each light alone, the visibility V = H / H0 is baked in the lightmap UVs (channel 1):
H = Cycles' direct diffuse bake of a white receiver, H0 the same with no object casting shadows,
V = 0 where H0 = 0. Writes DIR/<receiver>.<light>.exr (row 0 is v = 1, as shadowbake writes)
and DIR/<receiver>.baked.exr (1 where Cycles baked a texel), and prints BAKE_SECONDS per bake.
Cycles averages each texel over its footprint where shadowbake takes its centre, so the two
differ most along hard shadow edges and chart borders; compare over the texels whose eight
neighbours are covered too.
"""

import argparse
import math
import os
import sys
import time

import bpy
import mathutils
import numpy

# Blender 3.4's glTF importer uses numpy.bool, which Debian 12's numpy 1.24 no longer has.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

ap = argparse.ArgumentParser(prog="cycles_level_bake.py")
ap.add_argument("level")
ap.add_argument("--out", required=True)
ap.add_argument("--res", type=int, default=256)
ap.add_argument("--samples", type=int, default=256)
ap.add_argument("--sun-angle", type=float, default=0.526,
                help="every sun's angular diameter, degrees (shadowbake's angle_deg)")
ap.add_argument("--receivers")
ap.add_argument("--lights")
ap.add_argument("--sky", help="an equirectangular map: the world's Environment Texture, baked as "
                "the light 'sky' (a scene file's shape = \"sky\" light)")
ap.add_argument("--sky-preetham", type=float, metavar="TURBIDITY",
                help="Blender's own Preetham Sky Texture of this turbidity, its sun towards the "
                "level's lamp --sky-sun, baked as the light 'sky' (shadowbake's model = "
                "\"preetham\" with sun = that lamp)")
ap.add_argument("--sky-sun", default="sun")
ap.add_argument("--sky-strength", type=float, default=1.0)
args = ap.parse_args(sys.argv[sys.argv.index("--") + 1:])

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.world = None
bpy.ops.import_scene.gltf(filepath=os.path.abspath(args.level))


def emits(obj):
    for slot in obj.material_slots:
        material = slot.material
        if material is None or not material.use_nodes:
            continue
        for node in material.node_tree.nodes:
            if node.type == "EMISSION" and node.inputs["Strength"].default_value > 0:
                return True
            if node.type == "BSDF_PRINCIPLED":
                colour = node.inputs["Emission"].default_value
                if max(colour[:3]) > 0 and node.inputs["Emission Strength"].default_value > 0:
                    return True
    return False


lamps = {o.name: o for o in scene.objects if o.type == "LIGHT"}
emitters = {o.name: o for o in scene.objects if o.type == "MESH" and emits(o)}
receivers = {o.name: o for o in scene.objects
             if o.type == "MESH" and o.name not in emitters and len(o.data.uv_layers) >= 2}
for lamp in lamps.values():
    if lamp.data.type in ("POINT", "SPOT"):
        lamp.data.shadow_soft_size = 0.0
    elif lamp.data.type == "SUN":
        lamp.data.angle = math.radians(args.sun_angle)
def front_only(obj):
    """The emitter's material made to emit from its front side alone, as shadowbake's area lights
    do (Blender's emission shaders emit from both sides): the same radiance, black behind."""
    colour, strength = (1.0, 1.0, 1.0), 1.0
    for node in obj.active_material.node_tree.nodes:
        if node.type == "BSDF_PRINCIPLED":
            colour = node.inputs["Emission"].default_value[:3]
            strength = node.inputs["Emission Strength"].default_value
        elif node.type == "EMISSION":
            colour = node.inputs["Color"].default_value[:3]
            strength = node.inputs["Strength"].default_value
    material = bpy.data.materials.new(obj.name + "_front")
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    front = nodes.new("ShaderNodeEmission")
    front.inputs["Color"].default_value = (*colour, 1.0)
    front.inputs["Strength"].default_value = strength
    back = nodes.new("ShaderNodeEmission")
    back.inputs["Strength"].default_value = 0.0
    geometry = nodes.new("ShaderNodeNewGeometry")
    mix = nodes.new("ShaderNodeMixShader")
    links.new(geometry.outputs["Backfacing"], mix.inputs["Fac"])
    links.new(front.outputs["Emission"], mix.inputs[1])
    links.new(back.outputs["Emission"], mix.inputs[2])
    links.new(mix.outputs["Shader"], out.inputs["Surface"])
    obj.data.materials.clear()
    obj.data.materials.append(material)


for emitter in emitters.values():
    emitter.visible_shadow = False
    front_only(emitter)
all_lights = dict(lamps, **emitters)
# A sky: the world's Environment Texture, as Cycles maps it (the mapping shadowbake follows), or
# Blender's Preetham sky around the level's sun lamp (a lamp shines along its local -Z).
sky_world = None
if args.sky or args.sky_preetham:
    sky_world = bpy.data.worlds.new("sky")
    sky_world.use_nodes = True
    nodes = sky_world.node_tree.nodes
    if args.sky:
        environment = nodes.new("ShaderNodeTexEnvironment")
        environment.image = bpy.data.images.load(os.path.abspath(args.sky))
        environment.image.colorspace_settings.name = "Linear"
    else:
        environment = nodes.new("ShaderNodeTexSky")
        environment.sky_type = "PREETHAM"
        environment.turbidity = args.sky_preetham
        lamp = lamps[args.sky_sun]
        towards = lamp.matrix_world.to_3x3() @ mathutils.Vector((0.0, 0.0, 1.0))
        environment.sun_direction = towards.normalized()
    sky_world.node_tree.links.new(environment.outputs["Color"], nodes["Background"].inputs["Color"])
    nodes["Background"].inputs["Strength"].default_value = args.sky_strength
    all_lights["sky"] = sky_world
lights = all_lights
if args.receivers:
    receivers = {n: receivers[n] for n in args.receivers.split(",")}
if args.lights:
    lights = {n: lights[n] for n in args.lights.split(",")}

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = args.samples
scene.cycles.use_denoising = False
scene.cycles.use_adaptive_sampling = False
scene.cycles.light_sampling_threshold = 0.0
scene.cycles.max_bounces = 0
scene.render.bake.margin = 0
scene.render.bake.use_clear = True
os.makedirs(args.out, exist_ok=True)


def bake_direct(image):
    bpy.ops.object.bake(type="DIFFUSE", pass_filter={"DIRECT"})
    return numpy.array(image.pixels[:]).reshape(args.res, args.res, 4).copy()


def save(name, pixels):
    image = bpy.data.images.new(name, args.res, args.res, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"  # written as it is, linear
    image.pixels[:] = pixels.ravel()
    image.filepath_raw = os.path.join(args.out, name + ".exr")
    image.file_format = "OPEN_EXR"
    image.save()


for name, receiver in receivers.items():
    receiver.data.uv_layers.active_index = 1
    for i, layer in enumerate(receiver.data.uv_layers):
        layer.active_render = i == 1
    material = bpy.data.materials.new(name + "_white")
    material.use_nodes = True
    nodes = material.node_tree.nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (1, 1, 1, 1)
    material.node_tree.links.new(diffuse.outputs["BSDF"], out.inputs["Surface"])
    # Non-Color: the bake's values as they are. (A float image's default, scene-linear, came
    # out of Blender 3.4's bake of a level as display-encoded values, V ≈ V_true^0.45.)
    image = bpy.data.images.new(name, args.res, args.res, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = image
    nodes.active = texture
    receiver.data.materials.clear()
    receiver.data.materials.append(material)
    bpy.ops.object.select_all(action="DESELECT")
    receiver.select_set(True)
    bpy.context.view_layer.objects.active = receiver
    for light_name, light in lights.items():
        for other in all_lights.values():
            if other is not sky_world:
                other.hide_render = other is not light
        scene.world = sky_world if light is sky_world else None
        start = time.time()
        shadowed = bake_direct(image)
        # Unshadowed: no object casts shadows, and none stops the rays Cycles draws by the
        # receiver's BSDF either (multiple importance sampling counts those too: for a sky, a
        # large share of H0).
        casting = {o.name: (o.visible_shadow, o.visible_diffuse) for o in scene.objects}
        for o in scene.objects:
            o.visible_shadow = False
            if o is not receiver and o.type == "MESH" and o.name not in emitters:
                o.visible_diffuse = False  # (a light's own diffuse visibility is its light)
        unshadowed = bake_direct(image)
        for o in scene.objects:
            o.visible_shadow, o.visible_diffuse = casting[o.name]
        print(f"BAKE_SECONDS {name} {light_name} {time.time() - start:.2f}", flush=True)
        h, h0 = shadowed[:, :, :3], unshadowed[:, :, :3]
        pixels = numpy.ones((args.res, args.res, 4))
        pixels[:, :, :3] = numpy.where(h0 > 0, h / numpy.maximum(h0, 1e-30), 0.0)
        save(f"{name}.{light_name}", pixels)
    # The texels Cycles baked (alpha 1; the rest keep the cleared alpha 0): those whose centre a
    # triangle covers. shadowbake also bakes the texels a chart's border only touches, which
    # Cycles leaves black: compare over this mask (shadowbake compare --mask).
    baked = numpy.ones((args.res, args.res, 4))
    baked[:, :, :3] = (unshadowed[:, :, 3:4] > 0.5).astype(float)
    save(f"{name}.baked", baked)
