# The Python module: the same bake and sky from a script, checked against
# the CLI's bake of the same mesh. Skipped when the build has no module.
set -euo pipefail
build=$(dirname "$(dirname "$SKYBAKE")")
if [ ! -d "$build/python/skybake" ]; then
  echo "  no Python module in this build (pybind11 or Python headers missing)"
  exit 0
fi
PYTHONPATH="$build/python" /usr/bin/python3 - "$OUT" "$SKYBAKE" <<'PY'
import json, subprocess, sys
import numpy as np
import skybake

out, cli = sys.argv[1], sys.argv[2]
print("  skybake", skybake.__version__, "backends:",
      ", ".join(b.name + ("" if b.available else " (unavailable)") for b in skybake.backends()))
mesh = skybake.generate_mesh("city", 20000, seed=2)
mesh.compute_normals()
skybake.save_mesh(f"{out}/py_city.ply", mesh)
events = []
r = skybake.bake_ao(mesh, rule="lebedev:590", progress=events.append)
print(f"  bake_ao: {mesh.vertex_count} vertices, {r.rays} rays in {r.seconds:.2f} s, "
      f"mean AO {r.ao.mean():.4f}, {len(events)} progress event(s)")
subprocess.run([cli, "ao", f"{out}/py_city.ply", "-o", f"{out}/py_city_cli.ply", "--rule", "lebedev:590", "--quiet"],
               check=True)
cli_ao = skybake.load_mesh(f"{out}/py_city_cli.ply").attribute("ao")
print(f"  max |AO(Python) - AO(CLI)| = {np.abs(cli_ao - r.ao).max():.2e}")
assert np.abs(cli_ao - r.ao).max() <= 1e-6
srgb_to_linear = lambda c: np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)
skybake.save_image(f"{out}/py_city_ao.png", skybake.render_preview(mesh, srgb_to_linear(r.ao), 640, 400), tone="clamp")
sky = skybake.Sky.reference(skybake.atmosphere_preset("earth"))
img = sky.render(640, 240, view="camera", fov_deg=100, pitch_deg=15, sun_elevation_deg=4)
skybake.save_image(f"{out}/py_sunset.png", img, exposure_ev=4.0)
try:
    skybake.Mesh(np.zeros((3, 3)), np.zeros((1, 3), np.uint32))
except skybake.Error as e:
    print("  refused, as expected:", e)
print(f"  wrote {out}/py_city_ao.png and {out}/py_sunset.png")
PY
