#!/usr/bin/env python3
"""Runs tools/check_layering.py on small made-up trees: it must pass a clean
one and refuse an upward include, another module's internal.h and an unknown
public header.

    tools/check_layering_test.py
"""
import os
import subprocess
import sys
import tempfile

checker = os.path.join(os.path.dirname(os.path.abspath(__file__)), "check_layering.py")


def run(files):
    with tempfile.TemporaryDirectory() as root:
        base = {
            "src/CMakeLists.txt": "skybake_add_module(core)\nskybake_add_module(sky DEPENDS core)\n"
                                  "skybake_add_module(neural DEPENDS core sky)\n",
            "include/skybake/sky.h": "",
            "src/core/a.cpp": "",
            "src/sky/internal.h": "",
            "src/sky/device.h": "",
            "src/sky/sky.cpp": '#include "sky/internal.h"\n',
        }
        base.update(files)
        for rel, text in base.items():
            path = os.path.join(root, rel)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w") as f:
                f.write(text)
        p = subprocess.run([sys.executable, checker, root], capture_output=True, text=True)
        return p.returncode, p.stdout


failures = 0


def expect(name, files, code, words):
    global failures
    rc, out = run(files)
    if rc != code or any(w not in out for w in words):
        print(f"FAIL {name}: exit {rc}, output {out!r}")
        failures += 1
    else:
        print(f"ok   {name}")


expect("a clean tree passes", {"src/neural/n.cpp": '#include "sky/device.h"\n#include "skybake/sky.h"\n'}, 0,
       ["no upward includes"])
expect("another module's internal.h is refused", {"src/neural/n.cpp": '#include "sky/internal.h"\n'}, 1,
       ["src/neural/n.cpp:1", "an internal header of sky"])
expect("a NAME_internal.h is refused too", {"src/sky/mesh_internal.h": "",
                                            "src/neural/n.cpp": '#include "sky/mesh_internal.h"\n'}, 1,
       ["an internal header of sky"])
expect("an upward include is refused", {"src/sky/s.cpp": '#include "neural/n.h"\n', "src/neural/n.h": ""}, 1,
       ["sky does not depend on"])
expect("an unknown public header is refused", {"include/skybake/new_thing.h": ""}, 1,
       ["new_thing.h: no owning module"])
print(f"{5 - failures} passed, {failures} failed")
sys.exit(1 if failures else 0)
