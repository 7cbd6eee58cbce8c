"""End-to-end test of the Blender add-on (integrations/blender/skybake_bake).

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_addon.py -- \
        --zip build/skybake_bake.zip [--module-path build/python] [--cli build/bin/skybake]

It installs the add-on from the zip (into a temporary user scripts folder,
never the user's own), and checks:

- without the module: a one-line problem in the panel, an error report from
  the operator (no traceback);
- with the module-path preference set: a bowl (skybake's procedural open
  hemisphere, turned Z-up, moved and scaled) bakes AO 1/2 at the centre of
  its bottom (closed form: cosine-weighted visibility of a cap of half-angle
  45°, sin²45° = 1/2) with lebedev:5810; the attributes equal the CLI's
  (`skybake ao`) on the same world-space mesh, max |Δ| ≤ 1e-6;
- the same with an Edge Split modifier (corner domain) and a Subdivision
  Surface modifier (nearest-vertex fallback, a warning);
- 2CylinderEngine.glb (Assimp's glTF sample; skipped when missing), all
  its meshes baked together, against the CLI;
- undo removes the attributes; a vertices-only mesh gives a clear error;
- a cancel flag stops a bake; the sky operator builds the World node tree
  and a Cycles render finds the sun where sky_op.sun_direction() says.

Exits non-zero (via --python-exit-code) on any failure.
"""

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
import traceback

import bpy
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ENGINE = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"
TOLERANCE = 1e-6

failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what, flush=True)
    if not ok:
        failures.append(what)
    return ok


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    env_path = os.environ.get("SKYBAKE_PYTHONPATH") or (os.environ.get("PYTHONPATH", "").split(os.pathsep)[0])
    ap = argparse.ArgumentParser(prog="test_addon.py")
    ap.add_argument("--zip", required=True, help="the add-on zip (make_zip.py)")
    ap.add_argument("--module-path", default=env_path or os.path.join(REPO, "build", "python"),
                    help="folder holding the compiled skybake package")
    ap.add_argument("--cli", default=os.environ.get("SKYBAKE_CLI") or os.path.join(REPO, "build", "bin", "skybake"))
    ap.add_argument("--engine", default=ENGINE)
    return ap.parse_args(argv)


# -- helpers ----------------------------------------------------------------------------------


def clear_scene():
    bpy.ops.object.select_all(action="SELECT")
    bpy.ops.object.delete()
    for mesh in list(bpy.data.meshes):
        bpy.data.meshes.remove(mesh)


def select_only(objects):
    bpy.ops.object.select_all(action="DESELECT")
    for o in objects:
        o.select_set(True)
    bpy.context.view_layer.objects.active = objects[0]


def mesh_object(name, positions, triangles):
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(map(float, p)) for p in positions], [], [tuple(map(int, t)) for t in triangles])
    me.update()
    obj = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def expect_error(call, words, what):
    try:
        call()
    except RuntimeError as e:
        text = str(e)
        return check(all(w in text for w in words) and "Traceback" not in text, f"{what}: error report '{text.strip()}'")
    return check(False, f"{what}: expected an error report")


def cli_values(sb, cli, scene, rule, backend, tmp, tag):
    """ao, shading of `skybake ao` on the exact world-space mesh the add-on baked."""
    src = os.path.join(tmp, f"{tag}.ply")
    out = os.path.join(tmp, f"{tag}_ao.ply")
    mesh = scene.to_skybake(sb)
    sb.save_mesh(src, mesh)
    back = sb.load_mesh(src)
    # The reader drops zero-area triangles (they occlude nothing); everything else must be bit-identical.
    p = scene.positions.astype(np.float64)
    t = scene.indices
    area = np.linalg.norm(np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]]), axis=1)
    kept = t[area > 0.0]
    check(back.vertex_count == scene.vertex_count and np.array_equal(back.positions, scene.positions)
          and np.array_equal(back.normals, scene.normals) and np.array_equal(back.indices, kept),
          f"{tag}: the PLY holds exactly the baked mesh ({scene.vertex_count} vertices, {scene.triangle_count} "
          f"triangles, {len(t) - len(kept)} of zero area dropped by the reader)")
    cmd = [cli, "ao", src, "-o", out, "--rule", rule, "--backend", backend]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if not check(run.returncode == 0, f"{tag}: {' '.join(cmd[1:2])} CLI exit 0 ({run.stderr.strip()[-300:]})"):
        return None, None
    baked = sb.load_mesh(out)
    return baked.attribute("ao"), baked.attribute("shading")


def object_values(mc, obj, part):
    """The attributes on obj.data, as per evaluated vertex values (undoing the corner mapping)."""
    ao, domain = mc.read_back(obj.data, mc.AO)
    shading, _ = mc.read_back(obj.data, mc.SHADING)
    return ao, shading, domain


def compare_with_cli(sb, mc, cli, objects, rule, backend, tmp, tag):
    scene = mc.gather(objects, bpy.context.evaluated_depsgraph_get())
    cli_ao, cli_shading = cli_values(sb, cli, scene, rule, backend, tmp, tag)
    if cli_ao is None:
        return None
    worst_ao = worst_shading = 0.0
    domains = set()
    for obj, part in zip(objects, scene.parts):
        ao, shading, domain = object_values(mc, obj, part)
        domains.add(domain)
        ref_ao = cli_ao[part.first_vertex:part.stop]
        ref_shading = cli_shading[part.first_vertex:part.stop]
        if domain == "CORNER":
            ref_ao, ref_shading = ref_ao[part.corner_vertices], ref_shading[part.corner_vertices]
        if len(ao) != len(ref_ao):
            check(False, f"{tag}/{obj.name}: {len(ao)} values in the {domain} domain, expected {len(ref_ao)}")
            return None
        worst_ao = max(worst_ao, float(np.max(np.abs(ao - ref_ao))))
        worst_shading = max(worst_shading, float(np.max(np.abs(shading - ref_shading))))
    check(worst_ao <= TOLERANCE and worst_shading <= TOLERANCE,
          f"{tag}: add-on vs CLI max |Δao| = {worst_ao:.3g}, max |Δshading| = {worst_shading:.3g} (≤ {TOLERANCE:g})")
    return scene, cli_ao, domains


# -- the steps --------------------------------------------------------------------------------


def install(zip_path):
    scripts = tempfile.mkdtemp(prefix="skybake_blender_scripts_")
    os.environ["BLENDER_USER_SCRIPTS"] = scripts  # addon_install writes here, not to ~/.config
    bpy.ops.preferences.addon_install(filepath=os.path.abspath(zip_path), overwrite=True)
    check(os.path.isfile(os.path.join(scripts, "addons", "skybake_bake", "__init__.py")),
          f"addon_install put skybake_bake into {scripts}/addons")
    bpy.ops.preferences.addon_enable(module="skybake_bake")
    check("skybake_bake" in bpy.context.preferences.addons, "addon_enable: the add-on is enabled")
    return bpy.context.preferences.addons["skybake_bake"].preferences


class FakeLayout:
    """Records what a panel draws (background mode has no UI to draw into)."""

    def __init__(self, log):
        self.log = log
        self.use_property_split = self.use_property_decorate = False
        self.scale_y = 1.0

    def label(self, text="", icon="NONE"):
        self.log.append(("label", text, icon))

    def prop(self, data, name, text=None):
        self.log.append(("prop", name))

    def operator(self, idname, text="", icon="NONE"):
        self.log.append(("operator", idname))
        return type("Props", (), {})()

    def column(self, **kw):
        return self

    def row(self, **kw):
        return self


def draw_panel(panel_cls):
    log = []
    fake = type("FakePanel", (), {"layout": FakeLayout(log)})()
    panel_cls.draw(fake, bpy.context)
    return log


def check_missing_module(prefs, module_path):
    from skybake_bake import module_loader, panel

    saved_path = list(sys.path)
    saved_env = os.environ.pop("SKYBAKE_PYTHONPATH", None)
    real = os.path.realpath(module_path)
    sys.path[:] = [p for p in sys.path if os.path.realpath(p or ".") != real]
    for name in [n for n in sys.modules if n == "skybake" or n.startswith("skybake.")]:
        del sys.modules[name]
    prefs.module_path = ""
    module_loader.reset()
    try:
        missing = module_loader.get() is None
        if not check(missing, "without the module path, skybake does not import"):
            return
        log = draw_panel(panel.SKYBAKE_PT_bake)
        labels = [entry for entry in log if entry[0] == "label"]
        check(len(labels) == 1 and labels[0][2] == "ERROR" and "Module folder" in labels[0][1]
              and "SKYBAKE_PYTHONPATH" in labels[0][1], f"panel shows one line: '{labels[0][1] if labels else ''}'")
        clear_scene()
        bpy.ops.mesh.primitive_cube_add()
        expect_error(lambda: bpy.ops.skybake.bake_ao(), ["module not found"], "bake without the module")
        expect_error(lambda: bpy.ops.skybake.sky_world(), ["module not found"], "sky without the module")
    finally:
        sys.path[:] = saved_path
        if saved_env is not None:
            os.environ["SKYBAKE_PYTHONPATH"] = saved_env


def make_bowl(sb, name="bowl", triangles=4000):
    bowl = sb.generate_mesh("bowl", triangles)  # y-up, bottom at (0, -1, 0), open at y = 0
    obj = mesh_object(name, bowl.positions, bowl.indices)
    obj.rotation_euler = (math.pi / 2.0, 0.0, 0.0)  # y-up to Blender's z-up
    obj.location = (3.0, -2.0, 1.0)
    obj.scale = (2.0, 2.0, 2.0)
    bpy.context.view_layer.update()
    return obj


def bottom_centre_value(obj, mc):
    """AO at the bowl's lowest world-space vertex (the centre of its bottom)."""
    world = np.array([list(r) for r in obj.matrix_world])
    co = np.empty(len(obj.data.vertices) * 3, np.float32)
    obj.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3) @ world[:3, :3].T + world[:3, 3]
    i = int(np.argmin(co[:, 2]))
    ao, domain = mc.read_back(obj.data, mc.AO)
    return float(ao[i]), co[i], domain


def check_bowl(sb, mc, cli, tmp):
    clear_scene()
    obj = make_bowl(sb)
    select_only([obj])
    rule = "lebedev:5810"
    bpy.ops.ed.undo_push(message="before the bake")
    t = time.perf_counter()
    # undo=True: the call pushes an undo step as a click in the UI does (bl_options UNDO).
    result = bpy.ops.skybake.bake_ao("EXEC_DEFAULT", True, rule=rule, backend="embree")
    check(result == {"FINISHED"}, f"bowl: bake_ao returned {result} in {time.perf_counter() - t:.2f} s")
    me = bpy.data.objects["bowl"].data
    names = {a.name: (a.data_type, a.domain) for a in me.attributes}
    check(names.get(mc.AO) == ("FLOAT", "POINT") and names.get(mc.SHADING) == ("FLOAT", "POINT")
          and names.get(mc.BENT_NORMAL) == ("FLOAT_VECTOR", "POINT")
          and names.get(mc.AO_COLOR) == ("FLOAT_COLOR", "POINT"), f"bowl: attributes {names}")
    active = me.color_attributes.active_color
    check(active is not None and active.name == mc.AO_COLOR, "bowl: skybake_ao_color is the active colour attribute")
    check(bpy.context.scene.display.shading.color_type == "VERTEX", "bowl: Workbench colour type is Attribute")
    value, where, _ = bottom_centre_value(bpy.data.objects["bowl"], mc)
    check(abs(value - 0.5) <= 0.01, f"bowl: AO at the bottom centre {where.round(3).tolist()} = {value:.4f} (1/2 ± 0.01)")
    bent, _ = mc.read_back(me, mc.BENT_NORMAL)
    lengths = np.linalg.norm(bent, axis=1)
    check(np.all(np.abs(lengths - 1.0) < 1e-3), "bowl: bent normals are unit vectors")
    compare_with_cli(sb, mc, cli, [bpy.data.objects["bowl"]], rule, "embree", tmp, "bowl")

    # Undo: one step back is the state before the operator.
    if not check(bpy.ops.ed.undo.poll(), "undo is available after the bake (the operator pushed a step)"):
        return rule
    bpy.ops.ed.undo()
    me = bpy.data.objects["bowl"].data
    left = [a.name for a in me.attributes if a.name.startswith("skybake_")]
    check(not left, f"undo removes the attributes (left: {left})")
    return rule


def check_modifiers(sb, mc, cli, tmp):
    clear_scene()
    obj = make_bowl(sb, "bowl_split", 2000)
    mod = obj.modifiers.new("split", "EDGE_SPLIT")
    mod.split_angle = math.radians(5.0)
    select_only([obj])
    bpy.ops.skybake.bake_ao(rule="lebedev:590", backend="embree")
    scene_domains = compare_with_cli(sb, mc, cli, [obj], "lebedev:590", "embree", tmp, "edge_split")
    if scene_domains:
        scene, _, domains = scene_domains
        check(scene.vertex_count != len(obj.data.vertices) and domains == {"CORNER"},
              f"edge split: {len(obj.data.vertices)} → {scene.vertex_count} vertices, written per corner")

    clear_scene()
    obj = make_bowl(sb, "bowl_subsurf", 1000)
    obj.modifiers.new("subsurf", "SUBSURF").levels = 1
    select_only([obj])
    result = bpy.ops.skybake.bake_ao(rule="lebedev:590", backend="embree")
    ao, domain = mc.read_back(obj.data, mc.AO)
    check(result == {"FINISHED"} and domain == "POINT" and len(ao) == len(obj.data.vertices)
          and np.all((ao >= 0.0) & (ao <= 1.0)), "subdivision: nearest-vertex values on the original vertices")


def check_engine(sb, mc, cli, tmp, path):
    if not os.path.isfile(path):
        print(f"skip  2CylinderEngine: {path} is missing (Debian package assimp-testmodels)")
        return
    clear_scene()
    # Debian 12's Blender 3.4 glTF importer still uses np.bool, which numpy 1.24 removed: alias it for
    # the import only.
    shimmed = "bool" not in np.__dict__
    if shimmed:
        np.bool = bool
    try:
        bpy.ops.import_scene.gltf(filepath=path)
    finally:
        if shimmed:
            del np.bool
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    shared = sum(1 for o in meshes if o.data.users > 1)
    select_only(meshes)
    t = time.perf_counter()
    result = bpy.ops.skybake.bake_ao(rule="lebedev:590", backend="embree")
    scene_domains = compare_with_cli(sb, mc, cli, meshes, "lebedev:590", "embree", tmp, "engine")
    if scene_domains:
        scene, cli_ao, domains = scene_domains
        check(result == {"FINISHED"}, f"engine: {len(meshes)} objects, {scene.vertex_count} vertices, "
              f"{scene.triangle_count} triangles, domains {sorted(domains)}, {time.perf_counter() - t:.2f} s")
        check(0.05 < float(np.mean(cli_ao)) < 0.95, f"engine: mean AO {float(np.mean(cli_ao)):.3f}")
        check(all(o.data.users == 1 for o in meshes), f"engine: the {shared} linked duplicates got meshes of their own")


def check_no_faces():
    clear_scene()
    obj = mesh_object("points", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [])
    select_only([obj])
    expect_error(lambda: bpy.ops.skybake.bake_ao(), ["'points'", "no faces"], "vertices-only mesh")
    check(not [a for a in obj.data.attributes if a.name.startswith("skybake_")], "vertices-only mesh: nothing written")


def check_cancel(sb):
    from skybake_bake import bake_op

    mesh = sb.generate_mesh("city", 20000)
    job = bake_op.BakeJob(sb, mesh, {"rule": "lebedev:5810", "backend": "embree"})
    job.cancel_requested = True
    t = time.perf_counter()
    job.start()
    job.thread.join(60.0)
    check(job.done.is_set() and job.cancelled and job.result is None and job.error is None,
          f"a cancel flag stops a threaded bake ({time.perf_counter() - t:.2f} s)")
    job = bake_op.BakeJob(sb, sb.generate_mesh("bowl", 500), {"rule": "lebedev:194", "backend": "embree"})
    job.start()
    job.thread.join(60.0)
    check(job.result is not None and len(job.result.ao) == job.mesh.vertex_count, "a threaded bake completes")
    job = bake_op.BakeJob(sb, sb.generate_mesh("bowl", 500), {"rule": "nonsense:1", "backend": "embree"})
    job.run()
    check(isinstance(job.error, sb.Error), f"a bad rule is an error, not a crash ({job.error})")


def render_mean(direction, path):
    """Mean radiance a narrow Cycles camera sees looking along a world direction."""
    from mathutils import Vector

    scene = bpy.context.scene
    cam = bpy.data.objects.get("probe_cam")
    if cam is None:
        cam = bpy.data.objects.new("probe_cam", bpy.data.cameras.new("probe_cam"))
        scene.collection.objects.link(cam)
    cam.data.angle = math.radians(6.0)
    cam.location = (0.0, 0.0, 0.0)
    cam.rotation_euler = Vector(direction).to_track_quat("-Z", "Y").to_euler()
    scene.camera = cam
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 4
    scene.cycles.device = "CPU"
    scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
    scene.render.resolution_x = scene.render.resolution_y = 12
    scene.render.resolution_percentage = 100
    scene.world.cycles.sampling_method = "NONE"  # camera rays see the background; skip the importance map
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = path
    scene.view_settings.view_transform = "Standard"
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path, check_existing=False)
    px = np.empty(len(img.pixels), np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    return float(px.reshape(-1, 4)[:, :3].mean())


def check_sky(tmp):
    from skybake_bake import sky_op

    clear_scene()
    bpy.context.scene.world = None
    elevation, azimuth = 25.0, 60.0
    result = bpy.ops.skybake.sky_world(sun_elevation_deg=elevation, sun_azimuth_deg=azimuth, strength=1.5,
                                       width=1024, filepath=os.path.join(tmp, "sky.exr"))
    world = bpy.context.scene.world
    check(result == {"FINISHED"} and world is not None and os.path.isfile(os.path.join(tmp, "sky.exr")),
          "sky: operator wrote sky.exr and set a World")
    nodes = world.node_tree.nodes
    env = next((n for n in nodes if n.bl_idname == "ShaderNodeTexEnvironment"), None)
    bg = next((n for n in nodes if n.bl_idname == "ShaderNodeBackground"), None)
    out = next((n for n in nodes if n.bl_idname == "ShaderNodeOutputWorld"), None)
    linked = (env is not None and bg is not None and out is not None and env.outputs["Color"].links
              and env.outputs["Color"].links[0].to_node == bg and bg.outputs[0].links
              and bg.outputs[0].links[0].to_node == out)
    check(bool(linked) and tuple(env.image.size) == (1024, 512) and abs(bg.inputs["Strength"].default_value - 1.5) < 1e-6,
          "sky: Environment Texture (1024x512) → Background (strength 1.5) → World Output")
    sun = sky_op.sun_direction(elevation, azimuth)
    toward = render_mean(sun, os.path.join(tmp, "probe_sun.exr"))
    others = {
        "opposite": (-sun[0], -sun[1], sun[2]),
        "mirrored x": (-sun[0], sun[1], sun[2]),
        "mirrored y": (sun[0], -sun[1], sun[2]),
        "swapped x/y": (sun[1], sun[0], sun[2]),
    }
    worst = max((render_mean(d, os.path.join(tmp, f"probe_{k.replace(' ', '_').replace('/', '')}.exr")), k)
                for k, d in others.items())
    check(toward > 20.0 * worst[0], f"sky: Cycles sees the sun where sun_direction() points: mean {toward:.3g} "
          f"vs ≤ {worst[0]:.3g} ({worst[1]})")


def main():
    args = parse_args()
    print(f"test_addon: zip {args.zip}, module path {args.module_path}, CLI {args.cli}", flush=True)
    prefs = install(args.zip)
    check_missing_module(prefs, args.module_path)

    prefs.module_path = args.module_path
    from skybake_bake import mesh_convert as mc, module_loader

    sb = module_loader.get()
    if not check(sb is not None, f"with the preference set, skybake imports ({module_loader.problem_details()})"):
        return
    check(os.path.realpath(os.path.dirname(os.path.dirname(sb.__file__))) == os.path.realpath(args.module_path),
          f"skybake comes from the preference path ({sb.__file__})")
    if not os.path.isfile(args.cli):
        check(False, f"the CLI {args.cli} exists (pass --cli or set SKYBAKE_CLI)")
        return
    with tempfile.TemporaryDirectory(prefix="skybake_blender_test_") as tmp:
        check_bowl(sb, mc, args.cli, tmp)
        check_modifiers(sb, mc, args.cli, tmp)
        check_engine(sb, mc, args.cli, tmp, args.engine)
        check_no_faces()
        check_cancel(sb)
        check_sky(tmp)


if __name__ == "__main__":
    start = time.perf_counter()
    try:
        main()
    except Exception:
        traceback.print_exc()
        failures.append("an exception escaped the test")
    print(f"test_addon: {len(failures)} failure(s) in {time.perf_counter() - start:.1f} s", flush=True)
    if failures:
        for f in failures:
            print("  FAIL " + f)
        sys.exit(1)
