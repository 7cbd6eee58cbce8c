"""skybake for Blender: bakes ambient occlusion, the shading coefficient and
bent normals on the selected meshes into attributes, and sets the World
background to a skybake sky. Pure Python over the compiled `skybake` module
(see docs/blender.md).
"""

bl_info = {
    "name": "skybake",
    "author": "skybake developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport > Sidebar (N) > skybake",
    "description": "Bake per-vertex ambient occlusion, shading coefficients and bent normals; skybake sky worlds",
    "category": "Lighting",
}

if "bpy" in locals():  # F8 / script reload: pick up edited sub-modules
    import importlib

    for _name in ("module_loader", "job", "mesh_convert", "preferences", "properties", "bake_op", "sky_op", "panel"):
        if _name in locals():
            importlib.reload(locals()[_name])

import bpy  # noqa: E402

from . import bake_op, job, module_loader, mesh_convert, panel, preferences, properties, sky_op  # noqa: E402,F401

_classes = (
    preferences.SkybakePreferences,
    properties.SkybakeSettings,
    bake_op.SKYBAKE_OT_bake_ao,
    sky_op.SKYBAKE_OT_sky_world,
    panel.SKYBAKE_PT_bake,
    panel.SKYBAKE_PT_sky,
)


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.skybake = bpy.props.PointerProperty(type=properties.SkybakeSettings)


def unregister():
    job.cancel_running()
    del bpy.types.Scene.skybake
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
