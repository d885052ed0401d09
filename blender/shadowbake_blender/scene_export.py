"""The open Blender scene as shadowbake reads it: a glTF binary of the meshes and a scene file
beside it for what glTF cannot carry (docs/blender.md, "What is exported").

Which light goes where. glTF's KHR_lights_punctual knows points, spots and suns but no area
lights, radii or sun angles, and Blender's exporter converts watts to candela on the way
(io_scene_gltf2, gather_lights: W / 4π · 683 / 4π), which shadowbake converts back (scene-format.md,
"Levels"). So the meshes go through glTF with `export_lights=False` and every light, of every
type, is written as a `[[light]]` table of the scene file, in Blender's own units: each light is
counted once, in watts, with its radius, angle and shape.

Frames. Blender is Z up; its glTF exporter (`export_yup`, the default) writes (x, y, z) as
(x, z, −y) (io_scene_gltf2/blender/com/gltf2_blender_conversion.py, convert_swizzle_location).
A level's world is its file's, so the `[[light]]` tables of a scene file that imports it are in
glTF's Y-up frame (scene-format.md, "Levels": "its lights, and any [[light]] a scene file adds to
it, are in Y-up coordinates"). `to_level` below is that map, applied to every position and
direction the scene file gets; it is a rotation, so lengths and areas are kept.

Units. shadowbake's lengths are metres and a light's `power` watts (scene-format.md,
"Conventions"); Blender's are its units (the glTF exporter writes them as metres, whatever the
scene's unit scale) and a light's Power is watts too, emitted as shadowbake emits it: an area
light's from its one side, exitance power / area (scene-format.md, `power`); a point's or spot's
as a point of that power (a spot's `power` is the point light's it is cut from, as Blender counts
it); a sun's Strength is the irradiance on a surface facing it, W/m² (`irradiance`); the world's
Background Strength is the sky's radiance scale (`strength`, "Blender's Background Strength").
"""

import array
import math
import os
import struct

import bpy
import mathutils

from .names import NameMap

GENERATED_UV_MAP = "shadowbake"  # the UV map the load puts generated lightmap UVs in


def to_level(v):
    """A Blender world point or direction in the glTF level's Y-up frame."""
    return (v[0], v[2], -v[1])


def _float32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def _number(x):
    """`x` in the fewest digits that give back its 32-bit float: Blender keeps its values (and
    mathutils computes) in 32 bits, so 0.2 is written 0.2, not 0.20000000298023224."""
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(f"not a finite number: {x}")
    if abs(x) >= 3e38:
        return repr(x)
    target = _float32(x)
    for digits in range(6, 10):
        text = f"{x:.{digits}g}"
        if _float32(float(text)) == target:
            break
    return text if any(c in text for c in ".e") else text + ".0"  # a TOML float


def _vector(v):
    return "[" + ", ".join(_number(x) for x in v) + "]"


def _string(text):
    """A TOML basic string."""
    out = ['"']
    for c in text:
        if c in '"\\':
            out.append("\\" + c)
        elif ord(c) < 0x20 or ord(c) == 0x7F:
            out.append(f"\\u{ord(c):04X}")
        else:
            out.append(c)
    out.append('"')
    return "".join(out)


class ExportError(Exception):
    """A scene the add-on cannot export; the message names the Blender object."""


class Export:
    """What one export wrote and what the load needs to map shadowbake's names back."""

    def __init__(self, folder):
        self.folder = folder
        self.glb = os.path.join(folder, "level.glb")
        self.toml = os.path.join(folder, "scene.toml")
        self.names = NameMap()
        self.receivers = []  # Blender names of the objects that get a lightmap
        self.lights = []     # Blender names of the lights written
        self.warnings = []


def exported_meshes(context):
    """The objects the glTF export writes as meshes: the visible mesh objects of the view layer."""
    return [o for o in context.view_layer.objects if o.type == "MESH" and o.visible_get()]


def exported_lights(context):
    return [o for o in context.view_layer.objects if o.type == "LIGHT" and o.visible_get()]


def is_receiver(obj, settings):
    if settings.receivers == "SELECTED":
        return obj.select_get()
    if settings.receivers == "MARKED":
        return obj.shadowbake_receiver
    return True


def _axes(obj):
    """The light's world frame: its position, where it shines (local −Z, Blender's light
    direction) and its local X and Y, each with the length the object's scale gives it."""
    m = obj.matrix_world
    basis = m.to_3x3()
    x = basis @ mathutils.Vector((1, 0, 0))
    y = basis @ mathutils.Vector((0, 1, 0))
    z = basis @ mathutils.Vector((0, 0, 1))
    return m.translation.copy(), -z.normalized(), x, y


def _area_light(obj, light, name, export):
    position, normal, x, y = _axes(obj)
    lines = []
    if abs(x.normalized().dot(y.normalized())) > 1e-4:
        export.warnings.append(f'Light "{obj.name}": its object is sheared; baked as the rectangle '
                               "its local X and Y span, made square to each other")
    width = light.size * x.length
    height = (light.size if light.shape in ("SQUARE", "DISK") else light.size_y) * y.length
    if light.spread < math.pi - 1e-6:
        export.warnings.append(f'Light "{obj.name}": its spread ({math.degrees(light.spread):.0f}°) '
                               "is not exported; shadowbake's area lights emit over the whole "
                               "hemisphere (180°)")
    if light.shape in ("SQUARE", "RECTANGLE"):
        # shadowbake's height runs along `up`, its width along up × normal (scene-format.md,
        # `size`); Blender's Size X along local X, Size Y along local Y. With up = local Y and
        # normal = local −Z, up × normal = −X: the same rectangle (mirrored, which a light without
        # a texture does not show).
        lines += ['shape = "rectangle"',
                  f"position = {_vector(to_level(position))}",
                  f"normal = {_vector(to_level(normal))}",
                  f"up = {_vector(to_level(y.normalized()))}",
                  f"size = {_vector((width, height))}"]
    else:  # DISK, ELLIPSE
        aspect = max(width, height) / min(width, height)
        if aspect <= 1 + 1e-6:
            lines += ['shape = "disk"', f"radius = {_number(width / 2)}"]
        elif aspect <= 1.5:
            # shadowbake has no ellipse: a disk of the same area is the nearest shape.
            radius = math.sqrt(width * height) / 2
            lines += ['shape = "disk"', f"radius = {_number(radius)}"]
            export.warnings.append(
                f'Light "{obj.name}": an ellipse of {width:.3g} × {height:.3g} m is baked as a '
                f"disk of the same area (radius {radius:.3g} m); shadowbake has no ellipses")
        else:
            # An elongated ellipse is nearer the rectangle of its area and proportions.
            k = math.sqrt(math.pi) / 2
            lines += ['shape = "rectangle"', f"up = {_vector(to_level(y.normalized()))}",
                      f"size = {_vector((width * k, height * k))}"]
            export.warnings.append(
                f'Light "{obj.name}": an ellipse of {width:.3g} × {height:.3g} m is baked as a '
                f"rectangle of the same area and proportions ({width * k:.3g} × "
                f"{height * k:.3g} m); shadowbake has no ellipses")
        lines.insert(1, f"position = {_vector(to_level(position))}")
        lines.insert(2, f"normal = {_vector(to_level(normal))}")
    lines.append(f"power = {_number(light.energy)}")
    return lines


def _light_table(obj, export):
    """The `[[light]]` lines of a Blender light, or None when it cannot be baked (a warning)."""
    light = obj.data
    name = export.names.add(obj.name)
    if light.energy <= 0:
        export.warnings.append(f'Light "{obj.name}": it has no power and is left out')
        return None
    if max(light.color) <= 0:
        export.warnings.append(f'Light "{obj.name}": it is black and is left out')
        return None
    if light.use_nodes:
        export.warnings.append(f'Light "{obj.name}": its shader nodes are not exported; its '
                               "Power and Color are")
    lines = [f"name = {_string(name)}"]
    position, direction, _, _ = _axes(obj)
    if light.type == "AREA":
        lines += _area_light(obj, light, name, export)
    elif light.type == "POINT":
        lines += ['shape = "sphere"', f"position = {_vector(to_level(position))}",
                  f"radius = {_number(light.shadow_soft_size)}", f"power = {_number(light.energy)}"]
    elif light.type == "SPOT":
        cone = math.degrees(light.spot_size)
        if cone >= 179.9:
            export.warnings.append(f'Light "{obj.name}": a spot of {cone:.1f}° is baked as one of '
                                   "179.9°, the widest shadowbake takes")
            cone = 179.9
        lines += ['shape = "spot"', f"position = {_vector(to_level(position))}",
                  f"direction = {_vector(to_level(direction))}", f"cone_deg = {_number(cone)}",
                  f"blend = {_number(light.spot_blend)}",
                  f"radius = {_number(light.shadow_soft_size)}", f"power = {_number(light.energy)}"]
    elif light.type == "SUN":
        # shadowbake's suns are 0 to 10° across (scene-format.md, `angle_deg`).
        angle = math.degrees(light.angle)
        if angle > 10:
            export.warnings.append(f'Light "{obj.name}": a sun {angle:.1f}° across is baked as one '
                                   "of 10°, the widest shadowbake takes")
            angle = 10.0
        angle = max(angle, 1e-3)  # Blender's 0° (a hard shadow): shadowbake needs an angle > 0
        lines += ['shape = "sun"', f"direction = {_vector(to_level(direction))}",
                  f"angle_deg = {_number(angle)}", f"irradiance = {_number(light.energy)}"]
    else:
        export.warnings.append(f'Light "{obj.name}": lights of type {light.type} are not exported')
        return None
    if tuple(light.color) != (1.0, 1.0, 1.0):
        lines.append(f"color = {_vector(light.color)}")
    return lines


def _linked_node(socket):
    return socket.links[0].from_node if socket.is_linked else None


def _world_table(world, export):
    """The sky a world gives (a `[[light]]` of shape "sky"), or None for a black world."""
    if world is None:
        return None
    if not world.use_nodes or world.node_tree is None:
        colour, strength, source = tuple(world.color), 1.0, None
    else:
        output = next((n for n in world.node_tree.nodes
                       if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
        background = _linked_node(output.inputs["Surface"]) if output else None
        if background is None:
            return None
        if background.type != "BACKGROUND":
            export.warnings.append(f'World "{world.name}": a {background.type} node on its output '
                                   "is not exported (only a Background node is)")
            return None
        strength_socket = background.inputs["Strength"]
        if strength_socket.is_linked:
            export.warnings.append(f'World "{world.name}": its Background Strength is driven by '
                                   "nodes; its value as set is exported")
        strength = strength_socket.default_value
        source = _linked_node(background.inputs["Color"])
        colour = tuple(background.inputs["Color"].default_value)[:3]
    if strength <= 0:
        return None
    name = "world"
    while name in export.names.to_blender:  # a Blender light may have that name already
        name += "_sky"
    lines = [f"name = {_string(name)}", 'shape = "sky"', "up = [0.0, 1.0, 0.0]",  # Y up
             f"strength = {_number(strength)}"]
    if source is None:
        if max(colour) <= 0:
            return None
        lines.append(f"color = {_vector(colour)}")
    elif source.type == "TEX_ENVIRONMENT" and source.image is not None:
        path = bpy.path.abspath(source.image.filepath, library=source.image.library)
        if not path or not os.path.isfile(path):
            export.warnings.append(f'World "{world.name}": its environment image '
                                   f'"{source.image.name}" is not a file on disk; left out')
            return None
        if source.inputs["Vector"].is_linked:
            export.warnings.append(f'World "{world.name}": the mapping of its environment image '
                                   "is not exported; it is baked unturned")
        lines.append(f"map = {_string(os.path.abspath(path))}")
    elif source.type == "TEX_SKY" and source.sky_type == "PREETHAM":
        lines += ['model = "preetham"', f"turbidity = {_number(source.turbidity)}",
                  # The node's sun_direction points at the sun; shadowbake's at where it shines.
                  f"sun_direction = {_vector(to_level(-mathutils.Vector(source.sun_direction)))}"]
    else:
        export.warnings.append(f'World "{world.name}": a {source.type} node on its Background '
                               "colour is not exported (a colour, an Environment Texture or a "
                               "Preetham Sky Texture are)")
        return None
    return lines


def write_scene(context, settings, folder):
    """Exports the visible scene into `folder` (level.glb and scene.toml); an Export.

    Raises ExportError for a scene shadowbake could not read back as its objects."""
    os.makedirs(folder, exist_ok=True)
    export = Export(folder)
    # shadowbake reads lengths as metres; the glTF exporter and the lights here write Blender
    # units as they are, so a Unit Scale other than 1 changes only the irradiance's scale (power
    # over area), which the user should know.
    unit_scale = context.scene.unit_settings.scale_length
    if context.scene.unit_settings.system != "NONE" and abs(unit_scale - 1.0) > 1e-6:
        export.warnings.append(f'Scene "{context.scene.name}": its Unit Scale is {unit_scale:g}; '
                               "shadowbake bakes one Blender unit as one metre")
    meshes = exported_meshes(context)
    receivers = []
    try:
        for obj in meshes:
            name = export.names.add(obj.name)
            if is_receiver(obj, settings):
                receivers.append((obj.name, name))
        light_tables = []
        for obj in exported_lights(context):
            table = _light_table(obj, export)
            if table is not None:
                light_tables.append(table)
                export.lights.append(obj.name)
    except ValueError as error:
        raise ExportError(str(error)) from error
    if settings.use_world:
        sky = _world_table(context.scene.world, export)
        if sky is not None:
            light_tables.append(sky)
    if not receivers:
        raise ExportError("no visible mesh object receives a lightmap (see the panel's "
                          "Receivers)")
    ambient_occlusion = settings.quantity == "ambient-occlusion"
    if not light_tables and not ambient_occlusion:
        raise ExportError("the scene has no visible light with power (and no world light)")
    export.receivers = [blender for blender, _ in receivers]

    held = _hold_generated_uvs(meshes)
    try:
        _export_glb(context, export.glb)
    finally:
        _restore_generated_uvs(held)

    lines = ["# Written by the shadowbake Blender add-on (blender/, docs/blender.md) from "
             f"{bpy.data.filepath or 'an unsaved file'}, scene {context.scene.name}.",
             "# Positions and directions are in glTF's Y-up frame: Blender's (x, y, z) is "
             "(x, z, -y) here.",
             "# Baked as: shadowbake bake scene.toml -o <the output folder>"
             + ("" if settings.preset == "final" else f" --preset {settings.preset}"),
             "", "[bake]"]
    if settings.size_mode == "DENSITY":
        lines.append(f"texels_per_metre = {_number(settings.texels_per_metre)}")
    else:
        lines.append(f"resolution = {settings.resolution}")
    # Ambient occlusion is a quantity and a method at once (scene-format.md, `quantity`).
    method = "ambient-occlusion" if ambient_occlusion else settings.method
    lines += [f"method = {_string(method)}", f"quantity = {_string(settings.quantity)}"]
    if method in ("reference", "ambient-occlusion"):
        lines.append(f"samples = {settings.samples}")
    lines += ["", "[output]", f"per_light = {str(settings.per_light).lower()}",
              f"shadowmask = {str(settings.shadowmask).lower()}",
              "gltf = true  # carries the lightmap UVs shadowbake generates back to Blender", "",
              "[[import]]", f"file = {_string(os.path.basename(export.glb))}",
              "lights = false  # every light is a [[light]] below"]
    receiver_names = {name for _, name in receivers}
    for obj in meshes:
        name = export.names.add(obj.name)
        if name not in receiver_names:
            lines += ["", "[[import.object]]", f"name = {_string(name)}", "receiver = false"]
    for table in light_tables:
        lines += ["", "[[light]]"] + table
    with open(export.toml, "w", encoding="utf-8") as out:
        out.write("\n".join(lines) + "\n")
    return export


def _hold_generated_uvs(meshes):
    """Takes the UV maps that hold UVs shadowbake generated (GENERATED_UV_MAP on a mesh
    the load marked) out of their meshes until the export is written, so that the export
    is the one shadowbake generated them from: it generates the same UVs again and its cache
    reuses the receiver, instead of reading them back as new lightmap UVs and baking it anew."""
    held = []
    for mesh in {obj.data for obj in meshes}:
        layer = mesh.uv_layers.get(GENERATED_UV_MAP)
        if layer is None or not mesh.get("shadowbake_generated_uvs"):
            continue
        uvs = array.array("f", [0.0]) * (2 * len(mesh.loops))
        layer.data.foreach_get("uv", uvs)
        held.append((mesh, uvs, layer.active, layer.active_render))
        mesh.uv_layers.remove(layer)
    return held


def _restore_generated_uvs(held):
    for mesh, uvs, active, active_render in held:
        layer = mesh.uv_layers.new(name=GENERATED_UV_MAP, do_init=False)
        layer.data.foreach_set("uv", uvs)
        layer.active = active
        layer.active_render = active_render


def _export_glb(context, path):
    # Blender 3.4's glTF add-on uses numpy.bool, which numpy 1.24 (Debian 12) no longer has.
    import numpy
    if not hasattr(numpy, "bool"):
        numpy.bool = bool
    result = bpy.ops.export_scene.gltf(
        filepath=path, export_format="GLB", use_visible=True, export_lights=False,
        export_cameras=False, export_apply=True, export_animations=False,
        export_image_format="NONE", export_texcoords=True, export_normals=True,
        export_colors=False, export_extras=False, export_yup=True, will_save_settings=False)
    if "FINISHED" not in result:
        raise ExportError(f"Blender's glTF export of {path} failed")
