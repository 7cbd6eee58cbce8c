"""Renders docs/images/blender_ao.png: the 2CylinderEngine baked with the
add-on, shown in the viewport by its skybake_ao_color attribute, with the
skybake sidebar open. Needs a display (Xvfb is enough):

    xvfb-run -a -s "-screen 0 1280x800x24" blender --factory-startup --enable-event-simulate \
        --window-geometry 0 0 1280 800 \
        --python tests/blender/screenshot.py -- --module-path build/python --out docs/images/blender_ao.png
"""
import argparse
import math
import os
import sys

import bpy
import mathutils
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ENGINE = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ap = argparse.ArgumentParser(prog="screenshot.py")
ap.add_argument("--module-path", default=os.path.join(REPO, "build", "python"))
ap.add_argument("--out", default=os.path.join(REPO, "docs", "images", "blender_ao.png"))
ap.add_argument("--rule", default="lebedev:590")
ap.add_argument("--tab-from-top", type=int, default=180, help="pixels from the sidebar's top to its skybake tab")
args = ap.parse_args(argv)
TAB_FROM_TOP = args.tab_from_top
ZOOM = 0.75

sys.path.insert(0, os.path.join(REPO, "integrations", "blender"))
import skybake_bake  # noqa: E402

skybake_bake.register()
bpy.context.preferences.view.show_splash = False
os.environ["SKYBAKE_PYTHONPATH"] = os.path.abspath(args.module_path)


def window():
    return bpy.context.window_manager.windows[0]


def view3d():
    for area in window().screen.areas:
        if area.type == "VIEW_3D":
            region = next(r for r in area.regions if r.type == "WINDOW")
            return area, region
    raise RuntimeError("no 3D viewport")


def setup():
    bpy.ops.object.select_all(action="SELECT")
    bpy.ops.object.delete()
    shimmed = "bool" not in np.__dict__  # Debian 12's glTF importer still uses np.bool
    if shimmed:
        np.bool = bool
    try:
        bpy.ops.import_scene.gltf(filepath=ENGINE)
    finally:
        if shimmed:
            del np.bool
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    for o in meshes:
        o.select_set(True)
    bpy.context.view_layer.objects.active = meshes[0]
    scene = bpy.context.scene
    scene.skybake.rule = args.rule
    win = window()
    with bpy.context.temp_override(window=win, screen=win.screen):
        result = bpy.ops.skybake.bake_ao()
    print("bake:", result, flush=True)
    area, region = view3d()
    space = area.spaces.active
    space.shading.type = "SOLID"
    space.shading.light = "FLAT"  # the baked AO alone
    space.shading.color_type = "VERTEX"
    space.overlay.show_floor = False
    space.overlay.show_axis_x = space.overlay.show_axis_y = False
    space.show_region_ui = True
    space.show_region_toolbar = False
    space.overlay.show_outline_selected = False  # keep the meshes selected (the panel counts them), unoutlined
    space.overlay.show_relationship_lines = False
    space.show_object_viewport_empty = False
    space.overlay.show_object_origins = False
    scene.view_settings.view_transform = "Standard"  # AO values as they are, not through Filmic
    space.clip_start, space.clip_end = 0.1, 100000.0  # the engine is in millimetres: 230 m long in Blender
    region_3d = space.region_3d
    region_3d.view_rotation = mathutils.Euler((math.radians(60), 0.0, math.radians(145)), "XYZ").to_quaternion()
    return None


def frame():
    area, region = view3d()
    corners = np.array([o.matrix_world @ mathutils.Vector(c) for o in bpy.context.scene.objects
                        if o.type == "MESH" for c in o.bound_box])
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    region_3d = area.spaces.active.region_3d
    region_3d.view_location = mathutils.Vector((lo + hi) / 2.0)
    region_3d.view_distance = float(np.linalg.norm(hi - lo)) * ZOOM
    return None


_drawn = []
_original_draw = skybake_bake.panel.SKYBAKE_PT_bake.draw


def _recording_draw(self, context):
    _drawn.append(True)
    _original_draw(self, context)


skybake_bake.panel.SKYBAKE_PT_bake.draw = _recording_draw
_offsets = list(range(TAB_FROM_TOP, TAB_FROM_TOP + 120, 12)) + list(range(TAB_FROM_TOP - 12, TAB_FROM_TOP - 100, -12))


def click_tab():
    """Clicks down the sidebar's tab column until the skybake panel draws (no Python API selects a tab)."""
    if _drawn:
        bpy.app.timers.register(lambda: shoot(), first_interval=1.5)
        return None
    if not _offsets:
        print("could not select the skybake tab", flush=True)
        bpy.app.timers.register(lambda: shoot(), first_interval=0.5)
        return None
    area, _ = view3d()
    ui = next(r for r in area.regions if r.type == "UI")
    x, y = ui.x + ui.width - 10, ui.y + ui.height - _offsets.pop(0)
    win = window()
    win.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x, y=y)
    win.event_simulate(type="LEFTMOUSE", value="PRESS", x=x, y=y)
    win.event_simulate(type="LEFTMOUSE", value="RELEASE", x=x, y=y)
    win.event_simulate(type="MOUSEMOVE", value="NOTHING", x=area.x + 20, y=area.y + 20)
    return 0.7


def shoot():
    area, _ = view3d()
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with bpy.context.temp_override(window=window(), screen=window().screen, area=area):
        bpy.ops.screen.screenshot_area(filepath=os.path.abspath(args.out))
    print("wrote", args.out, flush=True)
    bpy.ops.wm.quit_blender()


bpy.app.timers.register(lambda: setup(), first_interval=1.0)
bpy.app.timers.register(lambda: frame(), first_interval=10.0)
bpy.app.timers.register(click_tab, first_interval=12.0)

