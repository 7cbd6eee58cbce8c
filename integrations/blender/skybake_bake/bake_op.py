"""The bake operator: AO, shading coefficient and bent normals of the
selected meshes, baked together in world space.

invoke() (the panel's button, F3) runs the bake in a background thread and
returns to Blender at once: a timer polls the bake's progress into the
status bar and the window manager's progress cursor, and Esc cancels it.
execute() (scripts, `blender -b`, the redo panel) bakes in place and
blocks. Either way the results are written on the main thread only, in
one undo step.
"""

import bpy

from . import job, mesh_convert, module_loader, properties

_error_text = job.error_text


class BakeJob(job.Job):
    """One skybake.bake_ao call, runnable in a thread, that a flag cancels."""

    def __init__(self, sb, mesh, options):
        self.sb, self.mesh, self.options = sb, mesh, options
        super().__init__(lambda progress: sb.bake_ao(mesh, progress=progress, **options))


def show_in_viewport(context):
    """Solid shading coloured by the active colour attribute, in every 3D view and Workbench renders."""
    try:
        context.scene.display.shading.color_type = "VERTEX"
    except (AttributeError, TypeError):
        pass
    wm = context.window_manager
    for window in getattr(wm, "windows", []):
        for area in window.screen.areas:
            if area.type != "VIEW_3D":
                continue
            for space in area.spaces:
                if space.type == "VIEW_3D":
                    if space.shading.type == "WIREFRAME":
                        space.shading.type = "SOLID"
                    space.shading.color_type = "VERTEX"  # shown as "Attribute" in 3.4
            area.tag_redraw()


class SKYBAKE_OT_bake_ao(job.ModalJob, bpy.types.Operator):
    """Bake ambient occlusion, shading coefficient and bent normals of the selected meshes into attributes
    (the selected objects occlude each other)"""

    bl_idname = "skybake.bake_ao"
    bl_label = "Bake AO"
    bl_options = {"REGISTER", "UNDO"}

    # Empty / negative: use the scene's skybake settings (the panel's).
    rule: bpy.props.StringProperty(name="Rule", default="", options={"SKIP_SAVE"},
                                   description="Sphere rule, e.g. lebedev:590 (empty: the panel's)")
    backend: bpy.props.StringProperty(name="Backend", default="", options={"SKIP_SAVE"},
                                      description="embree, brute, raster, cuda (empty: the panel's)")
    max_distance: bpy.props.FloatProperty(name="Max distance", default=-1.0, options={"SKIP_SAVE"},
                                          description="World units; 0: unlimited; negative: the panel's")
    offset: bpy.props.FloatProperty(name="Offset", default=-1.0, options={"SKIP_SAVE"},
                                    description="World units; negative: the panel's")
    back_faces: bpy.props.StringProperty(name="Back faces", default="", options={"SKIP_SAVE"},
                                         description="occlude or ignore (empty: the panel's)")

    @classmethod
    def poll(cls, context):
        if job.running is not None:
            cls.poll_message_set("a skybake job is running (Esc cancels it)")
            return False
        if context.mode != "OBJECT":
            cls.poll_message_set("switch to Object Mode to bake")
            return False
        if not any(o.type == "MESH" for o in context.selected_objects):
            cls.poll_message_set("select one or more mesh objects")
            return False
        return True

    # -- shared steps -------------------------------------------------------------------------

    def _options(self, context):
        s = context.scene.skybake
        max_distance = self.max_distance if self.max_distance >= 0.0 else properties.max_distance(s)
        if max_distance == 0.0:
            max_distance = float("inf")
        return {
            "rule": self.rule.strip() or properties.rule_spec(s),
            "backend": self.backend.strip() or s.backend,
            "max_distance": max_distance,
            "offset": self.offset if self.offset >= 0.0 else s.offset,
            "back_faces": self.back_faces.strip() or s.back_faces,
        }

    def _prepare(self, context):
        """(bake job, scene, objects) or None after reporting why."""
        sb = module_loader.get()
        if sb is None:
            self.report({"ERROR"}, module_loader.problem())
            return None
        objects = [o for o in context.selected_objects if o.type == "MESH"]
        if not objects:
            self.report({"ERROR"}, "skybake: select one or more mesh objects to bake")
            return None
        try:
            scene = mesh_convert.gather(objects, context.evaluated_depsgraph_get())
            mesh = scene.to_skybake(sb)
        except mesh_convert.ConversionError as e:
            self.report({"ERROR"}, f"skybake: {e}")
            return None
        except sb.Error as e:
            self.report({"ERROR"}, f"skybake: {_error_text(e)}")
            return None
        return BakeJob(sb, mesh, self._options(context)), scene, [o.name for o in objects]

    def _finish(self, context, bake, scene, names):
        if bake.cancelled:
            self.report({"WARNING"}, "skybake: bake cancelled, nothing written")
            return {"CANCELLED"}
        if bake.error is not None:
            self.report({"ERROR"}, f"skybake: {_error_text(bake.error)}")
            return {"CANCELLED"}
        r = bake.result
        written, fallbacks, separated = [], [], []
        seen_meshes = set()
        for name, part in zip(names, scene.parts):
            obj = bpy.data.objects.get(name)
            if obj is None or obj.type != "MESH":
                self.report({"WARNING"}, f"skybake: object '{name}' went away during the bake; skipped")
                continue
            # Linked duplicates (one mesh, several objects: glTF instances, Alt+D) see different
            # occlusion: each gets a mesh of its own to hold its values.
            if obj.data.users > 1 or obj.data.as_pointer() in seen_meshes:
                obj.data = obj.data.copy()
                separated.append(name)
            seen_meshes.add(obj.data.as_pointer())
            domain, nearest = mesh_convert.write_back(obj, part, r.ao, r.shading, r.bent_normal)
            written.append(f"{name} ({domain.lower()})")
            if nearest:
                fallbacks.append(name)
        if fallbacks:
            self.report({"WARNING"}, "skybake: the modifiers of " + ", ".join(fallbacks) + " change the topology; "
                        "values were mapped to the nearest evaluated vertex")
        if separated:
            self.report({"INFO"}, f"skybake: {len(separated)} linked duplicate(s) got a mesh of their own: "
                        + ", ".join(separated[:8]) + (", ..." if len(separated) > 8 else ""))
        show_in_viewport(context)
        listed = ", ".join(written[:4]) + (f" and {len(written) - 4} more" if len(written) > 4 else "")
        self.report({"INFO"}, f"skybake: baked {scene.vertex_count} vertices, {scene.triangle_count} triangles "
                    f"({r.rule}, {r.backend}) in {r.seconds:.2f} s: {listed}")
        return {"FINISHED"}

    # -- blocking (scripts, background mode, redo) --------------------------------------------

    def execute(self, context):
        prepared = self._prepare(context)
        if prepared is None:
            return {"CANCELLED"}
        bake, scene, names = prepared
        bake.run()
        return self._finish(context, bake, scene, names)

    # -- modal (UI): a thread, a timer, Esc ---------------------------------------------------

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        prepared = self._prepare(context)
        if prepared is None:
            return {"CANCELLED"}
        bake, self._scene, self._names = prepared
        return self._start_modal(context, bake)

    def _describe(self):
        return f"baking AO ({self._scene.vertex_count} vertices)"

    def _done(self, context):
        return self._finish(context, self._job, self._scene, self._names)
