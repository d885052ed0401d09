"""Brings a bake's lightmaps into Blender: an image per receiver (the same image data-block bake
after bake, reloaded), the lightmap UVs shadowbake generated where the object had none, and the
image wired into the object's materials (docs/blender.md, "Load").

Where the files are, their encodings and the UV channel of each receiver come from the bake's
manifest.json (docs/cli.md, "manifest.json"). Generated UVs come back through the bake's
`scene.glb`, whose receivers carry their lightmap UVs as TEXCOORD_1 (docs/cli.md, "glTF")."""

import json
import os

import bpy
import mathutils

from . import glb
from .names import shadowbake_name
from .scene_export import GENERATED_UV_MAP

IMAGE_NODE = "shadowbake_image"
UV_NODE = "shadowbake_uv"
GROUP_NODE = "shadowbake_lightmap"


class LoadError(Exception):
    pass


def read_manifest(folder):
    path = os.path.join(folder, "manifest.json")
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except FileNotFoundError as error:
        raise LoadError(f"{path}: no bake in this folder (bake first)") from error
    except (OSError, ValueError) as error:
        raise LoadError(f"{path}: cannot read it: {error}") from error


def _image(name, path):
    """The image data-block called `name`, now showing the file at `path` (loaded once, reloaded
    on later bakes: never a second copy)."""
    image = bpy.data.images.get(name)
    if image is None:
        image = bpy.data.images.load(path, check_existing=False)
        image.name = name
    else:
        if bpy.path.abspath(image.filepath) != path:
            image.filepath = path
        image.reload()
    # Lightmaps hold linear values (visibility, W/m²): no colour transform on the way in.
    image.colorspace_settings.name = "Non-Color"
    image["shadowbake_file"] = path
    return image


# Blender's world (Z up) into the frame of the positions in shadowbake's scene.glb. The glTF
# specification's is (x, z, −y), as Blender's exporter writes it; shadowbake 's scene.glb of a
# level (a file already Y up) was measured to hold (x, −y, −z) (the level's Y-up world turned
# once more). Both are tried and the one the triangles match is taken, so the add-on does not
# depend on which the library writes.
_FRAMES = (lambda v: mathutils.Vector((v.x, v.z, -v.y)),
           lambda v: mathutils.Vector((v.x, -v.y, -v.z)))


def _copy_generated_uvs(obj, triangles):
    """Puts the UVs of `triangles` (scene.glb's, for this object) into the object's UV map
    GENERATED_UV_MAP, corner by corner, matching Blender's triangles to them by position. A
    warning (a string) where they cannot be matched, else None."""
    mesh = obj.data
    if mesh.users > 1:
        return (f'"{obj.name}" shares its mesh with other objects, whose generated lightmap UVs '
                "may differ: give it lightmap UVs of its own (a second UV map)")
    if not triangles:
        return f'"{obj.name}": the bake\'s scene.glb has no lightmap UVs for it'
    mesh.calc_loop_triangles()
    world = obj.matrix_world
    corners = [[world @ mesh.vertices[v].co for v in t.vertices] for t in mesh.loop_triangles]
    if not corners:
        return None
    size = max((max(abs(c) for c in p) for tri in corners for p in tri), default=1.0)
    tolerance = 1e-4 * max(size, 1.0)
    tree = mathutils.kdtree.KDTree(len(triangles))
    for i, (positions, _) in enumerate(triangles):
        tree.insert((positions[0] + positions[1] + positions[2]) / 3, i)
    tree.balance()

    def misfit(frame):
        sample = corners[:: max(1, len(corners) // 64)]
        return sum(tree.find(frame(sum(tri, mathutils.Vector()) / 3))[2] for tri in sample)

    frame = min(_FRAMES, key=misfit)
    uv_layer = mesh.uv_layers.get(GENERATED_UV_MAP) or mesh.uv_layers.new(name=GENERATED_UV_MAP)
    if uv_layer is None:
        return f'"{obj.name}": it has 8 UV maps, Blender\'s most; no room for the generated one'
    # The export leaves this map out (scene_export._hold_generated_uvs), so that shadowbake
    # generates the same UVs again and reuses the receiver.
    mesh["shadowbake_generated_uvs"] = True
    unmatched = 0
    for triangle, tri in zip(mesh.loop_triangles, corners):
        mapped = [frame(p) for p in tri]
        _, index, distance = tree.find(sum(mapped, mathutils.Vector()) / 3)
        if distance > tolerance:
            unmatched += 1
            continue
        positions, uvs = triangles[index]
        for loop, p in zip(triangle.loops, mapped):
            k = min(range(3), key=lambda k: (positions[k] - p).length)
            u, v = uvs[k]
            uv_layer.data[loop].uv = (u, 1.0 - v)  # glTF's v runs down, Blender's up
    if unmatched:
        return (f'"{obj.name}": {unmatched} of its {len(corners)} triangles are not in the bake\'s '
                "mesh (a modifier changes them?), so their generated lightmap UVs are missing: "
                "apply the modifiers or give it lightmap UVs (a second UV map)")
    return None


def _lightmap_group(name, image, uv_map):
    """The object's node group `name`: its lightmap `image` read through `uv_map`, multiplying
    a colour (output Multiplied) or emitted alone (output Emission). The image lives inside the
    group because Blender's glTF exporter reads only a material's top-level nodes: the next
    export then writes the material as it was, without the lightmap as its base colour texture
    and without an Emission node, which shadowbake would take for a light. Made once, updated
    on later loads."""
    group = bpy.data.node_groups.get(name)
    if group is None:
        group = bpy.data.node_groups.new(name, "ShaderNodeTree")
        group.inputs.new("NodeSocketColor", "Color").default_value = (0.8, 0.8, 0.8, 1.0)
        group.inputs.new("NodeSocketFloat", "Strength").default_value = 1.0
        group.outputs.new("NodeSocketColor", "Multiplied")
        group.outputs.new("NodeSocketShader", "Emission")
        nodes, links = group.nodes, group.links
        inputs = nodes.new("NodeGroupInput")
        outputs = nodes.new("NodeGroupOutput")
        uv_node = nodes.new("ShaderNodeUVMap")
        uv_node.name = UV_NODE
        image_node = nodes.new("ShaderNodeTexImage")
        image_node.name = IMAGE_NODE
        image_node.interpolation = "Linear"
        image_node.extension = "EXTEND"
        links.new(uv_node.outputs["UV"], image_node.inputs["Vector"])
        scaled = nodes.new("ShaderNodeMixRGB")  # lightmap × strength
        scaled.blend_type = "MULTIPLY"
        scaled.inputs["Fac"].default_value = 1.0
        links.new(image_node.outputs["Color"], scaled.inputs["Color1"])
        links.new(inputs.outputs["Strength"], scaled.inputs["Color2"])
        multiplied = nodes.new("ShaderNodeMixRGB")
        multiplied.blend_type = "MULTIPLY"
        multiplied.inputs["Fac"].default_value = 1.0
        links.new(inputs.outputs["Color"], multiplied.inputs["Color1"])
        links.new(scaled.outputs["Color"], multiplied.inputs["Color2"])
        links.new(multiplied.outputs["Color"], outputs.inputs["Multiplied"])
        emission = nodes.new("ShaderNodeEmission")
        links.new(scaled.outputs["Color"], emission.inputs["Color"])
        links.new(emission.outputs["Emission"], outputs.inputs["Emission"])
        for k, node in enumerate((uv_node, image_node, inputs, scaled, multiplied, emission,
                                  outputs)):
            node.location = (220 * k - 700, 0)
    group.nodes[IMAGE_NODE].image = image
    group.nodes[UV_NODE].uv_map = uv_map
    return group


def _object_material(obj, slot):
    """The material of `slot` made the object's own (a copy linked to the object, so that objects
    sharing a material each show their own lightmap); the same copy on later loads."""
    current = slot.material
    if current is not None and "shadowbake_object" in current and current.users <= 1:
        current["shadowbake_object"] = obj.name
        return current
    if current is None:
        material = bpy.data.materials.new(f"shadowbake {obj.name}")
        material.use_nodes = True
    else:
        material = current.copy()
        material.name = f"{current.name} {obj.name}"
        material["shadowbake_base"] = current.name
    material["shadowbake_object"] = obj.name
    slot.link = "OBJECT"
    slot.material = material
    return material


def _link_from(tree, socket, node_name, output_name):
    node = tree.nodes.get(node_name) if node_name else None
    if node is None or output_name not in node.outputs:
        return False
    tree.links.new(node.outputs[output_name], socket)
    return True


def _wire(material, lightmap_group, mode, strength):
    """Wires the object's lightmap group into the material: MULTIPLY over the Principled
    BSDF's base colour, or EMISSION, the lightmap alone as the surface. The original links are
    kept on the group node, so the mode can change back and forth. A warning or None."""
    material.use_nodes = True
    tree = material.node_tree
    nodes, links = tree.nodes, tree.links
    output = next((n for n in nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output), None)
    if output is None:
        output = nodes.new("ShaderNodeOutputMaterial")
    principled = next((n for n in nodes if n.type == "BSDF_PRINCIPLED"), None)
    group = nodes.get(GROUP_NODE)
    if group is None:
        group = nodes.new("ShaderNodeGroup")
        group.name = group.label = GROUP_NODE
        group.node_tree = lightmap_group
        group.location = (output.location.x - 250, output.location.y - 300)
        surface = output.inputs["Surface"]
        if surface.is_linked:
            group["surface_from"] = [surface.links[0].from_node.name,
                                     surface.links[0].from_socket.name]
        if principled is not None:
            base = principled.inputs["Base Color"]
            if base.is_linked:
                group["base_from"] = [base.links[0].from_node.name, base.links[0].from_socket.name]
            group.inputs["Color"].default_value = base.default_value
    group.node_tree = lightmap_group
    group.inputs["Strength"].default_value = strength
    base_from = group.get("base_from")
    surface_from = group.get("surface_from")
    warning = None
    if mode == "MULTIPLY" and principled is None:
        warning = (f'material "{material.name}" has no Principled BSDF to multiply: the lightmap '
                   "is shown as emission")
        mode = "EMISSION"
    if principled is not None:
        base = principled.inputs["Base Color"]
        for link in list(base.links):
            links.remove(link)
        if mode == "MULTIPLY":
            if base_from:
                _link_from(tree, group.inputs["Color"], *base_from)
            links.new(group.outputs["Multiplied"], base)
        elif base_from:
            _link_from(tree, base, *base_from)
    surface = output.inputs["Surface"]
    if mode == "EMISSION":
        links.new(group.outputs["Emission"], surface)
    else:
        for link in list(surface.links):
            links.remove(link)
        if surface_from:
            _link_from(tree, surface, *surface_from)
    return warning


def load(context, settings, folder):
    """Loads the bake in `folder` into the scene's objects. ([(object, image)], [warnings],
    manifest). Raises LoadError when there is no bake to load."""
    folder = os.path.abspath(folder)
    manifest = read_manifest(folder)
    objects = {shadowbake_name(o.name): o for o in context.scene.objects if o.type == "MESH"}
    generated = None
    loaded, warnings = [], []
    for receiver in manifest.get("receivers", []):
        name = receiver["name"]
        obj = objects.get(name)
        if obj is None:
            warnings.append(f'receiver "{name}" of the bake is no object of this scene; not loaded')
            continue
        files = receiver.get("files")
        if not files or "lightmap" not in files:
            warnings.append(f'"{obj.name}": its lightmap is in an atlas, which the add-on does '
                            "not load")
            continue
        lightmap = files["lightmap"]
        path = os.path.join(folder, lightmap["file"])
        if not os.path.isfile(path):
            warnings.append(f'"{obj.name}": its lightmap {path} is missing')
            continue
        mesh = obj.data
        if receiver.get("uv_layout", {}).get("generated"):
            if generated is None:
                if "gltf" not in manifest:
                    raise LoadError(f"{folder}: the bake generated lightmap UVs but wrote no "
                                    "scene.glb to carry them (bake with gltf)")
                generated = glb.node_triangles(os.path.join(folder, manifest["gltf"]), 1)
            problem = _copy_generated_uvs(obj, generated.get(name, []))
            if problem:
                warnings.append(problem)
            uv_map = GENERATED_UV_MAP
        else:
            # The export's UV channels: the mesh's UV maps less the generated one it holds back.
            exported = [layer.name for layer in mesh.uv_layers
                        if layer.name != GENERATED_UV_MAP or not mesh.get("shadowbake_generated_uvs")]
            channel = receiver.get("uv_channel", 1)
            if channel >= len(exported):
                warnings.append(f'"{obj.name}": the bake read UV channel {channel}, which it no '
                                "longer has; bake again")
                continue
            uv_map = exported[channel]
        image = _image(f"shadowbake {name}", path)
        # An 8-bit irradiance lightmap holds value / scale (docs/cli.md, "Encodings").
        strength = settings.preview_strength * float(lightmap.get("scale", 1.0))
        if not obj.material_slots:
            # A material of the mesh's own (an empty slot would trip Blender's glTF exporter).
            material = bpy.data.materials.new(f"shadowbake {obj.name}")
            material.use_nodes = True
            material["shadowbake_object"] = obj.name
            mesh.materials.append(material)
        lightmap_group = _lightmap_group(f"shadowbake {name}", image, uv_map)
        for slot in obj.material_slots:
            material = _object_material(obj, slot)
            warning = _wire(material, lightmap_group, settings.preview, strength)
            if warning:
                warnings.append(f'"{obj.name}": {warning}')
        loaded.append((obj, image))
    return loaded, warnings, manifest
