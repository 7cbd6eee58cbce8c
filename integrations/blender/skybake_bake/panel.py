"""The sidebar panels (3D Viewport > N > skybake)."""

import bpy

from . import job, mesh_convert, module_loader


class SKYBAKE_PT_bake(bpy.types.Panel):
    bl_label = "Bake AO"
    bl_idname = "SKYBAKE_PT_bake"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "skybake"

    def draw(self, context):
        layout = self.layout
        if module_loader.get() is None:
            layout.label(text=module_loader.problem(), icon="ERROR")
            layout.operator("preferences.addon_show", text="Open add-on preferences").module = __package__
            return
        s = context.scene.skybake
        col = layout.column()
        col.use_property_split = True
        col.use_property_decorate = False
        col.prop(s, "rule")
        if s.rule == "CUSTOM":
            col.prop(s, "rule_custom", text="Custom")
        col.prop(s, "backend")
        col.prop(s, "back_faces")
        col.prop(s, "max_distance")
        col.prop(s, "offset")
        meshes = [o for o in context.selected_objects if o.type == "MESH"]
        row = layout.row()
        row.scale_y = 1.4
        if job.running is not None:
            row.label(text=f"skybake is busy: {100.0 * job.running.fraction:.0f}%, Esc cancels", icon="TIME")
        else:
            row.operator("skybake.bake_ao", icon="RENDER_STILL",
                         text=f"Bake {len(meshes)} object{'s' if len(meshes) != 1 else ''}")
        obj = context.active_object
        if obj is not None and obj.type == "MESH" and mesh_convert.AO in obj.data.attributes:
            attr = obj.data.attributes[mesh_convert.AO]
            layout.label(text=f"{obj.name}: {mesh_convert.AO} ({attr.domain.lower()})", icon="CHECKMARK")


class SKYBAKE_PT_sky(bpy.types.Panel):
    bl_label = "Sky World"
    bl_idname = "SKYBAKE_PT_sky"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "skybake"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        if module_loader.get() is None:
            layout.label(text=module_loader.problem(), icon="ERROR")
            return
        s = context.scene.skybake
        col = layout.column()
        col.use_property_split = True
        col.use_property_decorate = False
        col.prop(s, "sun_elevation_deg")
        col.prop(s, "sun_azimuth_deg")
        col.prop(s, "sky_strength")
        col.prop(s, "sky_width")
        col.prop(s, "atmosphere")
        op = layout.operator("skybake.sky_world", icon="WORLD")
        op.sun_elevation_deg = s.sun_elevation_deg
        op.sun_azimuth_deg = s.sun_azimuth_deg
        op.strength = s.sky_strength
        op.width = s.sky_width
        op.atmosphere = s.atmosphere
