"""Installs the add-on as a user does, for the tests in this folder: a zip of
blender/shadowbake_blender/ (the package folder at its root) through Blender's own
preferences.addon_install, then enabled and pointed at the shadowbake executable."""

import os
import zipfile

import bpy

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
ADDON = "shadowbake_blender"


def install_addon(work, shadowbake):
    """Builds WORK/shadowbake_blender.zip and installs and enables it; raises RuntimeError
    when the add-on does not come up."""
    package = os.path.join(work, f"{ADDON}.zip")
    source = os.path.join(REPO, "blender", ADDON)
    with zipfile.ZipFile(package, "w", zipfile.ZIP_DEFLATED) as z:
        for name in sorted(os.listdir(source)):
            if name.endswith(".py"):
                z.write(os.path.join(source, name), f"{ADDON}/{name}")
    bpy.ops.preferences.addon_install(filepath=package, overwrite=True)
    bpy.ops.preferences.addon_enable(module=ADDON)
    if ADDON not in bpy.context.preferences.addons or not hasattr(bpy.ops.shadowbake, "bake"):
        raise RuntimeError(f"the add-on {package} did not enable")
    bpy.context.preferences.addons[ADDON].preferences.executable = os.path.abspath(shadowbake)
