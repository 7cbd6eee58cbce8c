"""The interactive path of the bake operator, in a real Blender window
(Xvfb is enough): invoke() starts a threaded modal bake with a status-bar
progress, Esc cancels it and writes nothing, and a second bake runs to the
end, writes the attributes and switches the viewport to Attribute colours.

    xvfb-run -a -s "-screen 0 1280x800x24" blender --factory-startup --enable-event-simulate \
        --window-geometry 0 0 1280 800 --python tests/blender/test_modal_ui.py -- --module-path build/python

Exits 0 when every check passes, 1 otherwise (`blender -b` cannot run modal
operators, so test_addon.py covers execute() and this script invoke()).
"""
import argparse
import os
import sys
import time

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ap = argparse.ArgumentParser(prog="test_modal_ui.py")
ap.add_argument("--module-path", default=os.path.join(REPO, "build", "python"))
args = ap.parse_args(argv)

os.environ["SKYBAKE_PYTHONPATH"] = os.path.abspath(args.module_path)
sys.path.insert(0, os.path.join(REPO, "integrations", "blender"))
import skybake_bake  # noqa: E402
from skybake_bake import bake_op, job, mesh_convert, module_loader  # noqa: E402

skybake_bake.register()
bpy.context.preferences.view.show_splash = False
failures = []
state = {}


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what, flush=True)
    if not ok:
        failures.append(what)


def finish():
    print(f"test_modal_ui: {len(failures)} failure(s)", flush=True)
    for f in failures:
        print("  FAIL " + f, flush=True)
    os._exit(1 if failures else 0)  # quit_blender() would always exit 0


def window():
    return bpy.context.window_manager.windows[0]


def override():
    win = window()
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    return bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region)


def make_object(name, kind, triangles):
    sb = module_loader.get()
    m = sb.generate_mesh(kind, triangles)
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(map(float, p)) for p in m.positions], [], [tuple(map(int, t)) for t in m.indices])
    obj = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def select_only(obj):
    for o in bpy.context.scene.objects:
        o.select_set(o == obj)
    bpy.context.view_layer.objects.active = obj


def start_long_bake():
    bpy.ops.object.select_all(action="SELECT")
    bpy.ops.object.delete()
    check(module_loader.get() is not None, "skybake imports from SKYBAKE_PYTHONPATH")
    obj = make_object("city", "city", 20000)
    select_only(obj)
    with override():
        result = bpy.ops.skybake.bake_ao("INVOKE_DEFAULT", rule="lebedev:5810", backend="embree")
    check(result == {"RUNNING_MODAL"}, f"invoke() starts a modal bake ({result})")
    check(job.running is not None, "a bake job is running in a thread")
    state["t0"] = time.perf_counter()
    bpy.app.timers.register(press_escape, first_interval=1.5)


def press_escape():
    bake = job.running
    check(bake is not None and not bake.done.is_set(), "the bake is still running after 1.5 s (Blender stays responsive)")
    state["fraction_before_esc"] = bake.fraction if bake else None
    win = window()
    win.event_simulate(type="MOUSEMOVE", value="NOTHING", x=400, y=400)
    win.event_simulate(type="ESC", value="PRESS")
    win.event_simulate(type="ESC", value="RELEASE")
    state["esc"] = time.perf_counter()
    bpy.app.timers.register(wait_cancelled, first_interval=0.2)


def wait_cancelled():
    if job.running is not None:
        if time.perf_counter() - state["esc"] > 30.0:
            check(False, "Esc ends the bake within 30 s")
            finish()
        return 0.2
    job_seconds = time.perf_counter() - state["esc"]
    obj = bpy.data.objects["city"]
    check(not [a for a in obj.data.attributes if a.name.startswith("skybake_")],
          f"Esc cancelled the bake in {job_seconds:.2f} s (progress was {state['fraction_before_esc']:.2f}); nothing written")
    bpy.app.timers.register(start_short_bake, first_interval=0.5)
    return None


def start_short_bake():
    obj = make_object("bowl", "bowl", 2000)
    select_only(obj)
    with override():
        space = bpy.context.area.spaces.active
        space.shading.color_type = "MATERIAL"
        result = bpy.ops.skybake.bake_ao("INVOKE_DEFAULT", rule="lebedev:590", backend="embree")
    check(result == {"RUNNING_MODAL"}, "a second bake starts")
    state["t1"] = time.perf_counter()
    bpy.app.timers.register(wait_done, first_interval=0.2)


def wait_done():
    if job.running is not None:
        if time.perf_counter() - state["t1"] > 60.0:
            check(False, "the second bake ends within 60 s")
            finish()
        return 0.2
    obj = bpy.data.objects["bowl"]
    names = {a.name: a.domain for a in obj.data.attributes}
    check(all(n in names for n in mesh_convert.ATTRIBUTES), f"the modal bake wrote the attributes ({sorted(names)})")
    with override():
        space = bpy.context.area.spaces.active
        check(space.shading.color_type == "VERTEX", "the viewport shows the colour attribute (Attribute)")
    check(obj.data.color_attributes.active_color.name == mesh_convert.AO_COLOR, "skybake_ao_color is active")
    with override():
        check(bpy.ops.ed.undo.poll(), "undo is available after the modal bake")
        bpy.ops.ed.undo()
    obj = bpy.data.objects.get("bowl")
    check(obj is None or not [a for a in obj.data.attributes if a.name.startswith("skybake_")],
          "undo removes the modal bake's attributes")
    bpy.app.timers.register(start_sky, first_interval=0.2)


def start_sky():
    """The Sky World button at a width that takes seconds: a thread too, so Blender keeps drawing."""
    with override():
        result = bpy.ops.skybake.sky_world("INVOKE_DEFAULT", width=4096, sun_elevation_deg=12.0)
    check(result == {"RUNNING_MODAL"}, f"Sky World at 4096 wide starts a modal job ({result})")
    state["t2"] = time.perf_counter()
    state["ticks"] = 0
    bpy.app.timers.register(wait_sky, first_interval=0.1)


def wait_sky():
    if job.running is not None:
        state["ticks"] += 1  # the main thread runs while the sky renders
        if time.perf_counter() - state["t2"] > 120.0:
            check(False, "Sky World at 4096 wide ends within 120 s")
            finish()
        return 0.1
    seconds = time.perf_counter() - state["t2"]
    world = bpy.context.scene.world
    image = bpy.data.images.get("skybake_sky")
    check(world is not None and world.get("skybake_sun_elevation_deg") == 12.0, "the world was set")
    check(image is not None and tuple(image.size) == (4096, 2048), f"the panorama is 4096x2048 "
          f"({tuple(image.size) if image else None})")
    check(state["ticks"] >= 3, f"Blender ran {state['ticks']} timer ticks during the {seconds:.1f} s render")
    finish()


bpy.app.timers.register(start_long_bake, first_interval=1.0)
