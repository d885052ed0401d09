"""Helpers shared by the Blender scripts that make the realistic scenes under scenes/.

Each scene folder holds a `make_scene.py` run with Debian's Blender, headless:

    blender -b --factory-startup -P scenes/<name>/make_scene.py

It builds the objects the way an artist does (primitives, modifiers, smooth shading, a texture
UV map in channel 0 and a lightmap UV map made by Blender's own Lightmap Pack or Smart UV Project
in channel 1), exports each object as its own glTF 2.0 binary (.glb, Y up, as Blender's exporter
writes it) and writes scene.toml, which stands the Y-up files back up with rotate_deg = [90, 0, 0].
"""

import math
import os
import sys

import bpy


def reset():
    """An empty scene: no default cube, camera or light."""
    bpy.ops.wm.read_factory_settings(use_empty=True)


def select_only(obj):
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def apply_modifiers(obj):
    select_only(obj)
    for modifier in list(obj.modifiers):
        bpy.ops.object.modifier_apply(modifier=modifier.name)


def apply_transform(obj):
    select_only(obj)
    bpy.ops.object.transform_apply(location=True, rotation=True, scale=True)


def shade_smooth(obj, auto_smooth_deg=None):
    select_only(obj)
    bpy.ops.object.shade_smooth()
    if auto_smooth_deg is not None:
        obj.data.use_auto_smooth = True
        obj.data.auto_smooth_angle = math.radians(auto_smooth_deg)


def texture_uvs(obj, angle_deg=66.0):
    """Channel 0: a texture layout by Smart UV Project, unless the primitive already made one."""
    mesh = obj.data
    if len(mesh.uv_layers) == 0:
        mesh.uv_layers.new(name="UVMap")
        mesh.uv_layers.active_index = 0
        _in_edit_mode(obj, lambda: bpy.ops.uv.smart_project(angle_limit=math.radians(angle_deg),
                                                             island_margin=0.0))


def lightmap_uvs(obj, method="lightmap", margin=0.1):
    """Channel 1: the lightmap layout, by Lightmap Pack (one chart per quad or triangle pair)
    or Smart UV Project (angle-based charts), with Blender's island margin."""
    mesh = obj.data
    texture_uvs(obj)
    layer = mesh.uv_layers.new(name="Lightmap")
    mesh.uv_layers.active = layer
    if method == "lightmap":
        _in_edit_mode(obj, lambda: bpy.ops.uv.lightmap_pack(PREF_CONTEXT="ALL_FACES",
                                                             PREF_PACK_IN_ONE=True,
                                                             PREF_NEW_UVLAYER=False,
                                                             PREF_BOX_DIV=12,
                                                             PREF_MARGIN_DIV=margin))
    else:
        _in_edit_mode(obj, lambda: bpy.ops.uv.smart_project(angle_limit=math.radians(66.0),
                                                             island_margin=margin * 0.05))
    mesh.uv_layers.active_index = 0


def _in_edit_mode(obj, operator):
    select_only(obj)
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    operator()
    bpy.ops.object.mode_set(mode="OBJECT")


def export_glb(obj, folder, name):
    """Writes obj alone as folder/name.glb: Y up, normals and both UV maps, no materials."""
    select_only(obj)
    bpy.ops.export_scene.gltf(filepath=os.path.join(folder, name + ".glb"), export_format="GLB",
                              use_selection=True, export_yup=True, export_texcoords=True,
                              export_normals=True, export_materials="NONE",
                              export_colors=False, export_apply=True)


def triangle_count(obj):
    obj.data.calc_loop_triangles()
    return len(obj.data.loop_triangles)


def script_folder():
    """The folder of the make_scene.py Blender is running (its -P argument)."""
    argv = sys.argv
    script = argv[argv.index("-P") + 1] if "-P" in argv else argv[-1]
    return os.path.dirname(os.path.abspath(script))
