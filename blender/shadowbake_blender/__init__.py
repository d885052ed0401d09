"""shadowbake for Blender: bakes the open scene's lightmaps with the `shadowbake` executable and
shows them on the objects (docs/blender.md)."""

bl_info = {
    "name": "shadowbake",
    "author": "shadowbake",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport > Sidebar > shadowbake",
    "description": "Bake soft-shadow lightmaps with shadowbake and load them onto the objects",
    "category": "Lighting",
}

import bpy  # noqa: E402

from . import operators  # noqa: E402

_METHODS = [("backprojection", "Backprojection", "Closed-form per texel: no noise (the default)"),
            ("convolution", "Convolution", "Soler and Sillion's soft shadows by FFT convolution"),
            ("reference", "Reference", "Ray traced, Samples per texel: the ground truth"),
            ("accumulation", "Accumulation", "Hard shadows from points over each light, averaged"),
            ("pcf", "PCF", "Percentage-closer filtering of a shadow map"),
            ("pcss", "PCSS", "Percentage-closer soft shadows"),
            ("adaptive-pcf", "Adaptive PCF", "PCF with a filter sized per texel"),
            ("erosion", "Erosion", "The hard shadow eroded by the penumbra's width"),
            ("chun-oh", "Chun-Oh", "Chun and Oh's soft shadow map")]


class ShadowbakePreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    executable: bpy.props.StringProperty(
        name="shadowbake executable", subtype="FILE_PATH", default="",
        description="Path of the shadowbake executable; empty: `shadowbake` found on PATH")

    def draw(self, context):
        self.layout.prop(self, "executable")


class ShadowbakeSettings(bpy.types.PropertyGroup):
    output_dir: bpy.props.StringProperty(
        name="Output", subtype="DIR_PATH", default="//shadowbake",
        description="Folder of the bake: the lightmaps, manifest.json and the cache that lets the "
        "next bake reuse what did not change; the export goes into its blender-export/")
    size_mode: bpy.props.EnumProperty(
        name="Size", default="RESOLUTION",
        items=[("RESOLUTION", "Resolution", "Every receiver's lightmap has the same side"),
               ("DENSITY", "Texel Density", "Each lightmap sized by its surface: texels per metre")])
    resolution: bpy.props.IntProperty(name="Resolution", default=256, min=1, max=16384,
                                      description="Texels per side of each lightmap")
    texels_per_metre: bpy.props.FloatProperty(name="Texels per Metre", default=32.0, min=0.01,
                                              max=100000.0)
    method: bpy.props.EnumProperty(name="Method", items=_METHODS, default="backprojection")
    preset: bpy.props.EnumProperty(
        name="Preset", default="final",
        items=[("final", "Final", "The bake these settings ask for"),
               ("preview", "Preview", "A look in seconds: a quarter of the texels per side, 16 "
                "rays per texel, the lightmaps alone")])
    quantity: bpy.props.EnumProperty(
        name="Quantity", default="visibility",
        items=[("visibility", "Visibility", "Shadow: the fraction of the lights that reaches, 0-1"),
               ("irradiance", "Irradiance", "The direct light, W/m²"),
               ("ambient-occlusion", "Ambient Occlusion", "No lights: the open hemisphere, 0-1")])
    samples: bpy.props.IntProperty(name="Samples", default=64, min=1, max=1 << 20,
                                   description="Rays per texel (Reference, Ambient Occlusion)")
    per_light: bpy.props.BoolProperty(name="Per-Light Images", default=False,
                                      description="Also write each light's own image")
    shadowmask: bpy.props.BoolProperty(name="Shadow Masks", default=False,
                                       description="Also write RGBA shadow masks (4 lights)")
    receivers: bpy.props.EnumProperty(
        name="Receivers", default="ALL",
        items=[("ALL", "All Visible", "Every visible mesh gets a lightmap"),
               ("SELECTED", "Selected", "The selected meshes get lightmaps; the others only "
                "cast shadows"),
               ("MARKED", "Marked", "Meshes whose Receives Lightmap box is ticked")])
    use_world: bpy.props.BoolProperty(name="World Light", default=True,
                                      description="Bake the world's background as a sky light")
    preview: bpy.props.EnumProperty(
        name="Show", default="MULTIPLY",
        items=[("MULTIPLY", "Multiply", "The lightmap multiplies each material's base colour"),
               ("EMISSION", "Emission", "The lightmap alone, as emission: the baked light as is")])
    preview_strength: bpy.props.FloatProperty(name="Strength", default=1.0, min=0.0,
                                              description="Scale of the lightmap as shown")


class SHADOWBAKE_PT_panel(bpy.types.Panel):
    bl_label = "shadowbake"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "shadowbake"

    def draw(self, context):
        settings = context.scene.shadowbake
        layout = self.layout
        layout.use_property_split = True
        layout.prop(settings, "output_dir")
        layout.prop(settings, "size_mode")
        if settings.size_mode == "DENSITY":
            layout.prop(settings, "texels_per_metre")
        else:
            layout.prop(settings, "resolution")
        layout.prop(settings, "quantity")
        row = layout.row()
        row.enabled = settings.quantity != "ambient-occlusion"
        row.prop(settings, "method")
        if settings.method == "reference" or settings.quantity == "ambient-occlusion":
            layout.prop(settings, "samples")
        layout.prop(settings, "preset")
        layout.prop(settings, "per_light")
        layout.prop(settings, "shadowmask")
        layout.prop(settings, "use_world")
        layout.prop(settings, "receivers")
        obj = context.active_object
        if settings.receivers == "MARKED" and obj is not None and obj.type == "MESH":
            layout.prop(obj, "shadowbake_receiver", text=f"{obj.name} Receives")
        layout.prop(settings, "preview")
        layout.prop(settings, "preview_strength")
        row = layout.row(align=True)
        row.operator(operators.SHADOWBAKE_OT_bake.bl_idname, icon="RENDER_STILL")
        row.operator(operators.SHADOWBAKE_OT_load.bl_idname, icon="IMAGE_DATA")


_CLASSES = (ShadowbakePreferences, ShadowbakeSettings, operators.SHADOWBAKE_OT_bake,
            operators.SHADOWBAKE_OT_load, SHADOWBAKE_PT_panel)


def register():
    for cls in _CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.shadowbake = bpy.props.PointerProperty(type=ShadowbakeSettings)
    bpy.types.Object.shadowbake_receiver = bpy.props.BoolProperty(
        name="Receives Lightmap", default=True,
        description="With Receivers: Marked, whether this mesh gets a lightmap (it casts "
        "shadows either way)")


def unregister():
    del bpy.types.Object.shadowbake_receiver
    del bpy.types.Scene.shadowbake
    for cls in reversed(_CLASSES):
        bpy.utils.unregister_class(cls)
