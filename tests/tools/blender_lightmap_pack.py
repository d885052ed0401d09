"""Blender's Lightmap Pack of every receiver of corpus scenes, for comparing UV layouts
(docs/methods.md, "Generated lightmap UVs").

    blender -b --factory-startup -P tests/tools/blender_lightmap_pack.py -- OUT_DIR SCENE.toml...

For each scene file, each receiver's mesh (a glTF binary) is imported, its triangles joined back
into the quads they were made from (tris_convert_to_quads), and its UV channel 1 replaced by
Lightmap Pack (Blender's defaults: a chart per quad, margin division 0.1, packed in one layout);
it is written to OUT_DIR/<scene folder>/<file>, and a copy of the scene file beside it names the
new files for receivers and the original files, by absolute path, for the rest. Bake that copy
and the original (or the original with uv = "auto") and compare their manifests' uv_layout with
tests/tools/uv_layout_table.py.
"""

import os
import re
import sys
import tomllib

import bpy
import numpy

# Blender 3.4's glTF importer uses numpy.bool, which Debian 12's numpy 1.24 no longer has.
if not hasattr(numpy, "bool"):
    numpy.bool = bool

MARGIN_DIV = 0.1  # Blender's default


def lightmap_pack(source, target):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=source)
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    bpy.ops.object.select_all(action="DESELECT")
    for obj in meshes:
        obj.select_set(True)
    bpy.context.view_layer.objects.active = meshes[0]
    if len(meshes) > 1:
        bpy.ops.object.join()
    obj = bpy.context.view_layer.objects.active
    uv_layers = obj.data.uv_layers
    while len(uv_layers) < 2:
        uv_layers.new(name="Lightmap")
    uv_layers.active_index = 1
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    bpy.ops.mesh.tris_convert_to_quads()
    bpy.ops.uv.lightmap_pack(PREF_CONTEXT="ALL_FACES", PREF_PACK_IN_ONE=True,
                             PREF_NEW_UVLAYER=False, PREF_BOX_DIV=12, PREF_MARGIN_DIV=MARGIN_DIV)
    bpy.ops.object.mode_set(mode="OBJECT")
    uv_layers.active_index = 0
    bpy.ops.export_scene.gltf(filepath=target, export_format="GLB", use_selection=True,
                              export_yup=True, export_texcoords=True, export_normals=True,
                              export_materials="NONE", export_colors=False, export_apply=True)


def main():
    args = sys.argv[sys.argv.index("--") + 1:]
    out_dir, scenes = args[0], args[1:]
    for scene in scenes:
        folder = os.path.dirname(os.path.abspath(scene))
        target_folder = os.path.join(out_dir, os.path.basename(folder))
        os.makedirs(target_folder, exist_ok=True)
        with open(scene, "rb") as f:
            parsed = tomllib.load(f)
        packed = {}
        for obj in parsed.get("object", []):
            mesh = obj["mesh"]
            if obj.get("receiver", True) and mesh not in packed:
                packed[mesh] = os.path.join(target_folder, os.path.basename(mesh))
                lightmap_pack(os.path.join(folder, mesh), packed[mesh])

        def renamed(match):
            mesh = match.group(1)
            return 'mesh = "%s"' % packed.get(mesh, os.path.join(folder, mesh))

        with open(scene) as f:
            text = re.sub(r'^mesh = "([^"]+)"', renamed, f.read(), flags=re.M)
        text = re.sub(r'^uv = \d+', "uv = 1", text, flags=re.M)
        with open(os.path.join(target_folder, os.path.basename(scene)), "w") as f:
            f.write(text)


main()
