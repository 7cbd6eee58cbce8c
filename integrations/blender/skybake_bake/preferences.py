"""Add-on preferences: where the compiled skybake module lives."""

import bpy

from . import module_loader


def _module_path_changed(self, context):
    module_loader.reset()


class SkybakePreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    module_path: bpy.props.StringProperty(
        name="Module folder",
        description=("Folder holding the compiled 'skybake' Python package (e.g. <build>/python). "
                     "Used when a plain 'import skybake' fails; SKYBAKE_PYTHONPATH is tried last"),
        subtype="DIR_PATH",
        default="",
        update=_module_path_changed,
    )

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "module_path")
        sb = module_loader.get()
        if sb is None:
            layout.label(text=module_loader.problem(), icon="ERROR")
        else:
            layout.label(text=f"skybake {sb.__version__} from {sb.__file__}", icon="CHECKMARK")
