"""The add-on's operators: Bake (`shadowbake.bake`) and Load (`shadowbake.load`);
docs/blender.md documents both."""

import os

import bpy

from . import bake_process, glb, lightmaps, scene_export

EXPORT_FOLDER = "blender-export"  # inside the output folder: level.glb and scene.toml


def output_folder(context):
    """The output folder as an absolute path, or raises ValueError."""
    settings = context.scene.shadowbake
    if settings.output_dir.startswith("//") and not bpy.data.filepath:
        raise ValueError("the output folder is relative to the .blend file, which is not saved: "
                         "save it, or choose an absolute folder")
    if not settings.output_dir:
        raise ValueError("no output folder set")
    return os.path.abspath(bpy.path.abspath(settings.output_dir))


def _load_and_report(operator, context, folder):
    settings = context.scene.shadowbake
    try:
        loaded, warnings, manifest = lightmaps.load(context, settings, folder)
    except (lightmaps.LoadError, glb.GlbError, OSError, ValueError, KeyError) as error:
        operator.report({"ERROR"}, f"shadowbake: {error}")
        return None
    for warning in warnings:
        operator.report({"WARNING"}, f"shadowbake: {warning}")
    return loaded, manifest


class SHADOWBAKE_OT_load(bpy.types.Operator):
    """Load the lightmaps of the output folder's bake into the objects' materials"""
    bl_idname = "shadowbake.load"
    bl_label = "Load Lightmaps"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        try:
            folder = output_folder(context)
        except ValueError as error:
            self.report({"ERROR"}, f"shadowbake: {error}")
            return {"CANCELLED"}
        result = _load_and_report(self, context, folder)
        if result is None:
            return {"CANCELLED"}
        self.report({"INFO"}, f"shadowbake: loaded {len(result[0])} lightmap(s) from {folder}")
        return {"FINISHED"}


class SHADOWBAKE_OT_bake(bpy.types.Operator):
    """Export the visible scene, bake its lightmaps with shadowbake and load them.
    Esc cancels and keeps the earlier bake"""
    bl_idname = "shadowbake.bake"
    bl_label = "Bake Lightmaps"
    bl_options = {"REGISTER", "UNDO"}

    running = False  # one bake at a time
    # How the last bake ended: "finished", "cancelled" (Esc), or "failed: <message>"; for scripts
    # and tests/blender/modal_test.py, which cannot read Blender's reports.
    outcome = ""

    def _start(self, context):
        """Exports and starts the bake; False (after a report) when it cannot."""
        SHADOWBAKE_OT_bake.outcome = "failed: not started"
        settings = context.scene.shadowbake
        preferences = context.preferences.addons[__package__].preferences
        executable = bake_process.find_executable(preferences.executable)
        if executable is None:
            self.report({"ERROR"}, "shadowbake: executable not found: set its path in the "
                        "add-on's preferences, or put `shadowbake` on PATH"
                        + (f" ({preferences.executable} is not an executable file)"
                           if preferences.executable else ""))
            return False
        try:
            self.folder = output_folder(context)
            self.export = scene_export.write_scene(context, settings,
                                                   os.path.join(self.folder, EXPORT_FOLDER))
        except (ValueError, scene_export.ExportError, OSError) as error:
            self.report({"ERROR"}, f"shadowbake: {error}")
            return False
        for warning in self.export.warnings:
            self.report({"WARNING"}, f"shadowbake: {warning}")
        cmd = bake_process.command(executable, self.export.toml, self.folder, settings.preset)
        try:
            self.process = bake_process.BakeProcess(cmd)
        except OSError as error:
            self.report({"ERROR"}, f"shadowbake: cannot start {executable}: {error}")
            return False
        return True

    def _finish(self, context):
        process = self.process
        for warning in process.warnings:
            self.report({"WARNING"}, "shadowbake: " +
                        bake_process.in_blender_words(warning, self.export.names))
        if process.returncode != 0:
            message = process.failure(self.export.names)
            SHADOWBAKE_OT_bake.outcome = f"failed: {message}"
            self.report({"ERROR"}, f"shadowbake: {message} (the folder keeps its earlier bake)")
            return {"CANCELLED"}
        result = _load_and_report(self, context, self.folder)
        if result is None:
            SHADOWBAKE_OT_bake.outcome = "failed: the load failed"
            return {"CANCELLED"}
        SHADOWBAKE_OT_bake.outcome = "finished"
        loaded, manifest = result
        receivers = manifest.get("receivers", [])
        reused = sum(1 for r in receivers if r.get("bake", {}).get("reused"))
        self.report({"INFO"}, f"shadowbake: baked {len(receivers)} receiver(s), {reused} of them "
                    f"unchanged and reused, into {self.folder}; loaded {len(loaded)}")
        return {"FINISHED"}

    def execute(self, context):
        """Bakes to completion before it returns (scripts, `blender -b`)."""
        if not self._start(context):
            return {"CANCELLED"}
        background = bpy.app.background

        def show(fraction):
            if background:
                print(f"shadowbake: {100 * fraction:.0f}%", flush=True)
        self.process.wait(show)
        return self._finish(context)

    def invoke(self, context, event):
        if bpy.app.background or SHADOWBAKE_OT_bake.running:
            if SHADOWBAKE_OT_bake.running:
                self.report({"ERROR"}, "shadowbake: a bake is already running")
                return {"CANCELLED"}
            return self.execute(context)
        if not self._start(context):
            return {"CANCELLED"}
        SHADOWBAKE_OT_bake.running = True
        wm = context.window_manager
        self.timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        self._status(context, 0.0)
        return {"RUNNING_MODAL"}

    def _status(self, context, fraction):
        context.window_manager.progress_update(100 * fraction)
        if context.workspace:
            context.workspace.status_text_set(
                f"shadowbake: baking {100 * fraction:.0f}% (Esc cancels)")

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self.timer)
        wm.progress_end()
        if context.workspace:
            context.workspace.status_text_set(None)
        SHADOWBAKE_OT_bake.running = False

    def cancel(self, context):
        """Blender ends the modal operator (the window closes, another file loads): the bake
        is stopped as by Esc."""
        self.process.cancel()
        self._end(context)

    def modal(self, context, event):
        if event.type == "ESC":
            self.process.cancel()
            self._end(context)
            SHADOWBAKE_OT_bake.outcome = "cancelled"
            self.report({"WARNING"}, "shadowbake: bake cancelled; the folder keeps its earlier "
                        "bake")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        fraction = self.process.poll()
        if self.process.returncode is None:
            self._status(context, fraction)
            return {"PASS_THROUGH"}
        self._end(context)
        return self._finish(context)

