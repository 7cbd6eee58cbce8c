#!/usr/bin/env python3
"""Checks that the modules of src/ include one another in one direction only.

Each module's allowed dependencies are its DEPENDS in src/CMakeLists.txt or
src/*/*.cmake (and theirs, transitively). A file of src/MODULE/ - sources, headers and tests alike -
may include "OTHER/..." or the public header of OTHER only when MODULE depends
on OTHER, and never OTHER's internal headers (internal.h, NAME_internal.h):
what a module shares with others is a header named for its concept (e.g.
sky/device.h). Prints each violation and exits 1 if there is any.

    tools/check_layering.py [REPO_ROOT]
"""
import os
import re
import sys

root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
import glob

cmake = open(os.path.join(root, "src", "CMakeLists.txt")).read()
for extra in sorted(glob.glob(os.path.join(root, "src", "*", "*.cmake"))):
    cmake += "\n" + open(extra).read()
direct = {}
for m in re.finditer(r"skybake_add_module\((\w+)([^)]*)\)", cmake):
    name, args = m.group(1), m.group(2)
    d = re.search(r"DEPENDS((?:\s+\w+)*?)(?:\s+(?:LIBS|PUBLIC_LIBS)\b|$)", args.replace("\n", " "))
    direct[name] = set(d.group(1).split()) if d else set()


def closure(name, seen=None):
    seen = set() if seen is None else seen
    for d in direct.get(name, ()):
        if d not in seen:
            seen.add(d)
            closure(d, seen)
    return seen


allowed = {m: closure(m) | {m} for m in direct}
# The public header each module owns (include/skybake/NAME.h).
owner = {"bake.h": "bake", "bake_job.h": "job", "visibility.h": "visibility", "sky.h": "sky", "neural.h": "neural",
         "sphere.h": "sphere", "mesh.h": "io", "image.h": "core", "image_io.h": "io", "gltf_asset.h": "io", "sh.h": "sphere", "texture_bake.h": "bake", "distributed.h": "distributed",
         "sky_source.h": "neural", "planet.h": "planet", "render.h": "render", "prt.h": "prt",
         "viewer.h": "render", "sky_path_tracer.h": "sky",
         # core: every module may include these
         "core.h": "core", "error.h": "core", "files.h": "core", "interrupt.h": "core", "names.h": "core",
         "progress.h": "core", "version.h": "core"}
# Every public header has an owner: a new header must be added above.
for h in sorted(os.listdir(os.path.join(root, "include", "skybake"))):
    if h.endswith(".h") and h not in owner:
        print(f"include/skybake/{h}: no owning module in tools/check_layering.py")
        sys.exit(1)
include = re.compile(r'#\s*include\s+"(\w+)/([^"]+)"')
violations = 0
for module in direct:
    folder = os.path.join(root, "src", module)
    for base, _, files in os.walk(folder):
        for f in files:
            path = os.path.join(base, f)
            with open(path, errors="replace") as text:
                for number, line in enumerate(text, 1):
                    m = include.match(line.strip())
                    if not m:
                        continue
                    top, rest = m.groups()
                    target = owner.get(rest) if top == "skybake" else (top if top in direct else None)
                    base_name = os.path.basename(rest)
                    if target and target != module and (base_name == "internal.h" or base_name.endswith("_internal.h")):
                        rel = os.path.relpath(path, root)
                        print(f"{rel}:{number}: {module} includes {top}/{rest}, an internal header of {target}")
                        violations += 1
                        continue
                    if target and target not in allowed[module]:
                        rel = os.path.relpath(path, root)
                        print(f"{rel}:{number}: {module} includes {top}/{rest}, a header of {target}, "
                              f"which {module} does not depend on")
                        violations += 1
if violations:
    sys.exit(1)
print(f"layering: {len(direct)} modules, no upward includes, no other module's internal headers")
