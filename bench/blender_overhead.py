"""The cost of baking from Blender.

On a 200k-triangle procedural city turned into a Blender mesh object, with
the same rule and backend, it times the add-on's blocking bake
(bpy.ops.skybake.bake_ao(): the evaluated mesh to world-space arrays, the
bake, the attributes written back) against the C++ bake as the CLI measures
it on the same world-space mesh in the same run (`skybake ao --json`,
"seconds": the bake_ambient_occlusion() call alone), interleaved so that
both see the same machine load, after one warm-up of each. Prints JSON; the
target ratio is ≤ 1.3.

    blender -b --factory-startup --python bench/blender_overhead.py -- \
        --module-path build/python --cli build/bin/skybake

The add-on is taken from integrations/blender of this checkout.
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import bpy
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser(prog="blender_overhead.py", description=__doc__.splitlines()[0])
    ap.add_argument("--module-path", default=os.environ.get("SKYBAKE_PYTHONPATH", os.path.join(REPO, "build", "python")))
    ap.add_argument("--cli", default=os.environ.get("SKYBAKE_CLI", os.path.join(REPO, "build", "bin", "skybake")))
    ap.add_argument("--kind", default="city")
    ap.add_argument("--triangles", type=int, default=200_000)
    ap.add_argument("--rule", default="lebedev:590")
    ap.add_argument("--backend", default="embree")
    ap.add_argument("--repeats", type=int, default=3)
    return ap.parse_args(argv)


def blender_object(name, positions, triangles):
    """A mesh object from (N, 3) float32 positions and (M, 3) triangles, through foreach_set."""
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(positions))
    me.vertices.foreach_set("co", positions.ravel())
    me.loops.add(triangles.size)
    me.loops.foreach_set("vertex_index", triangles.astype(np.int32).ravel())
    me.polygons.add(len(triangles))
    me.polygons.foreach_set("loop_start", np.arange(0, triangles.size, 3, dtype=np.int32))
    me.polygons.foreach_set("loop_total", np.full(len(triangles), 3, dtype=np.int32))
    me.update(calc_edges=True)
    me.validate()
    obj = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def main():
    a = parse_args()
    sys.path.insert(0, os.path.join(REPO, "integrations", "blender"))
    sys.path.insert(0, os.path.abspath(a.module_path))
    import skybake
    import skybake_bake
    from skybake_bake import mesh_convert

    skybake_bake.register()
    skybake.set_quiet(True)

    bpy.ops.object.select_all(action="SELECT")
    bpy.ops.object.delete()
    source = skybake.generate_mesh(a.kind, a.triangles, seed=1)
    obj = blender_object(a.kind, source.positions, source.indices)
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj

    with tempfile.TemporaryDirectory(prefix="skybake_blender_bench_") as tmp:
        scene = mesh_convert.gather([obj], bpy.context.evaluated_depsgraph_get())
        src = os.path.join(tmp, "scene.ply")
        skybake.save_mesh(src, scene.to_skybake(skybake))  # exactly what the add-on bakes
        cli = [a.cli, "ao", src, "-o", os.path.join(tmp, "out.ply"), "--rule", a.rule, "--backend", a.backend,
               "--json", "--quiet"]

        def run_cli():
            t0 = time.perf_counter()
            out = subprocess.run(cli, check=True, capture_output=True, text=True).stdout
            return json.loads(out)["seconds"], time.perf_counter() - t0

        def run_addon():
            t0 = time.perf_counter()
            result = bpy.ops.skybake.bake_ao(rule=a.rule, backend=a.backend)
            wall = time.perf_counter() - t0
            assert result == {"FINISHED"}, result
            return wall

        run_cli()  # warm-up: page cache, Embree's first BVH
        run_addon()
        addon_wall, cli_cpp, cli_wall = [], [], []
        for _ in range(a.repeats):
            addon_wall.append(run_addon())
            inner, wall = run_cli()
            cli_cpp.append(inner)
            cli_wall.append(wall)

    report = {
        "machine": f"{cpu_model()}, {os.cpu_count()} threads",
        "blender": bpy.app.version_string,
        "mesh": {"kind": a.kind, "vertices": scene.vertex_count, "triangles": scene.triangle_count},
        "rule": a.rule,
        "backend": a.backend,
        "repeats": a.repeats,
        "addon_seconds_median": statistics.median(addon_wall),
        "cli_cpp_seconds_median": statistics.median(cli_cpp),
        "cli_process_seconds_median": statistics.median(cli_wall),
        "ratio_addon_over_cpp": statistics.median(addon_wall) / statistics.median(cli_cpp),
        "ratio_addon_over_cli_process": statistics.median(addon_wall) / statistics.median(cli_wall),
        "addon_overhead_seconds": statistics.median(w - c for w, c in zip(addon_wall, cli_cpp)),
        "target_ratio": 1.3,
    }
    print(json.dumps(report, indent=2), flush=True)


if __name__ == "__main__":
    main()
