#!/usr/bin/env python3
"""Zips the skybake Blender add-on for Preferences > Add-ons > Install.

    python3 integrations/blender/make_zip.py build/skybake_bake.zip

The archive holds one top-level folder, skybake_bake/, with the add-on's
.py files (no __pycache__). Deterministic: sorted entries, fixed times.
"""
import os
import sys
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
PACKAGE = "skybake_bake"


def main(argv):
    if len(argv) != 2:
        sys.stderr.write("usage: make_zip.py OUT.zip\n")
        return 2
    out = os.path.abspath(argv[1])
    src = os.path.join(HERE, PACKAGE)
    files = sorted(f for f in os.listdir(src) if f.endswith(".py"))
    if "__init__.py" not in files:
        sys.stderr.write(f"make_zip.py: no {PACKAGE}/__init__.py in {HERE}\n")
        return 1
    os.makedirs(os.path.dirname(out), exist_ok=True)
    tmp = out + ".tmp"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for name in files:
            info = zipfile.ZipInfo(f"{PACKAGE}/{name}", date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = 0o644 << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            with open(os.path.join(src, name), "rb") as f:
                z.writestr(info, f.read())
    os.replace(tmp, out)
    print(f"wrote {out} ({len(files)} files)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
