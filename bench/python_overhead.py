#!/usr/bin/env python3
"""The cost of calling the bake from Python.

On a 200k-triangle procedural city, with the same rule and backend, it
times skybake.bake_ao() from Python (wall clock around the call: argument
checks, the GIL, the progress hook, the result arrays) against the C++ call
as the CLI measures it in the same run (`skybake ao --json`, "seconds":
the bake_ambient_occlusion() call alone, without file I/O), interleaved so
that both see the same machine load. Prints JSON; the target ratio is ≤ 1.05.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py --cli build/bin/skybake
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import tempfile
import time

import skybake


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.machine()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cli", default=os.environ.get("SKYBAKE_CLI", "skybake"))
    ap.add_argument("--triangles", type=int, default=200_000)
    ap.add_argument("--rule", default="lebedev:590")
    ap.add_argument("--backend", default="embree")
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()

    mesh = skybake.generate_mesh("city", a.triangles, seed=1)
    mesh.compute_normals()
    with tempfile.TemporaryDirectory() as tmp:
        src = os.path.join(tmp, "city.ply")
        skybake.save_mesh(src, mesh)
        mesh = skybake.load_mesh(src)  # exactly what the CLI reads
        py_wall, py_inner, cli_seconds = [], [], []
        for _ in range(a.repeats):
            m = mesh.copy()
            t0 = time.perf_counter()
            r = skybake.bake_ao(m, rule=a.rule, backend=a.backend)
            py_wall.append(time.perf_counter() - t0)
            py_inner.append(r.seconds)
            out = subprocess.run(
                [a.cli, "ao", src, "-o", os.path.join(tmp, "out.ply"), "--rule", a.rule, "--backend", a.backend,
                 "--json", "--quiet"], check=True, capture_output=True, text=True).stdout
            cli_seconds.append(json.loads(out)["seconds"])
    report = {
        "machine": f"{cpu_model()}, {os.cpu_count()} threads",
        "mesh": {"kind": "city", "vertices": mesh.vertex_count, "triangles": mesh.triangle_count},
        "rule": a.rule,
        "backend": a.backend,
        "repeats": a.repeats,
        "python_seconds_median": statistics.median(py_wall),
        "python_library_seconds_median": statistics.median(py_inner),
        "cli_cpp_seconds_median": statistics.median(cli_seconds),
        "ratio_python_over_cpp": statistics.median(py_wall) / statistics.median(cli_seconds),
        "binding_overhead_seconds": statistics.median(w - i for w, i in zip(py_wall, py_inner)),
    }
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
