# Ambient occlusion: per-vertex AO, shading coefficient A and bent normals
# (seed 002), baked with Embree (and CUDA where there is a GPU, and the depth
# buffer of OpenGL), written as glTF (any viewer shows COLOR_0 = AO)
# with PNG previews.
set -euo pipefail
models=/usr/share/assimp/models

# The seed's table case: about 5k vertices with the 5810-point Lebedev rule.
"$SKYBAKE" mesh generate --kind city --triangles 3000 --seed 1 -o "$OUT/ao_city_5k.glb"
"$SKYBAKE" ao "$OUT/ao_city_5k.glb" -o "$OUT/ao_city_5k_baked.glb" --rule lebedev:5810 --json

# A larger city and a terrain, with previews.
"$SKYBAKE" mesh generate --kind city --triangles 60000 --seed 1 -o "$OUT/ao_city.glb"
"$SKYBAKE" ao "$OUT/ao_city.glb" -o "$OUT/ao_city_baked.glb" --rule lebedev:590 \
  --preview "$OUT/ao_city.png" --preview-size 640x480 --preview-elevation 35
"$SKYBAKE" ao "$OUT/terrain.ply" -o "$OUT/ao_terrain_baked.ply" --rule lebedev:302 \
  --preview "$OUT/ao_terrain.png" --preview-size 640x480 --preview-elevation 40

# A real model, and its visibility bits in the seed's bit-packed form.
"$SKYBAKE" ao "$models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb" -o "$OUT/ao_engine_baked.glb" \
  --rule lebedev:590+rotate --preview "$OUT/ao_engine.png" --preview-size 640x480 --bits "$OUT/ao_engine_bits.bin"

# Closed form: inside the hemispherical bowl AO is exactly 1/2.
"$SKYBAKE" ao "$OUT/bowl.glb" -o "$OUT/ao_bowl_baked.glb" --rule lebedev:1202 --json | grep -A4 '"ao"'

# The table case on the GPU, with each of the CUDA backend's methods. Without
# a GPU, asking for it is one error line, exit code 1, and no output.
if "$SKYBAKE" --version | grep -q 'device(s)'; then
  for method in bvh per-polygon per-vertex; do
    "$SKYBAKE" ao "$OUT/ao_city_5k.glb" -o "$OUT/ao_city_5k_cuda_$method.glb" --rule lebedev:5810 \
      --device cuda --method "$method"
  done
else
  expect_refusal "$SKYBAKE" ao "$OUT/bowl.glb" -o "$OUT/nothing.glb" --device cuda
fi

# The seed's depth-buffer method: a depth cube map at each vertex, on any
# OpenGL 4.3 context (Mesa's llvmpipe without a GPU), and one depth map per
# direction; both against the Embree bake of the same city.
"$SKYBAKE" mesh generate --kind city --triangles 1000 --seed 1 -o "$OUT/ao_city_small.glb"
"$SKYBAKE" ao "$OUT/ao_city_small.glb" -o "$OUT/ao_city_small_embree.glb" --rule lebedev:590
"$SKYBAKE" ao "$OUT/ao_city_small.glb" -o "$OUT/ao_city_small_cube.glb" --rule lebedev:590 --backend raster
"$SKYBAKE" ao "$OUT/ao_city_small.glb" -o "$OUT/ao_city_small_directional.glb" --rule lebedev:590 \
  --backend raster --method directional --preview "$OUT/ao_city_small_directional.png" --preview-size 640x480
