# The real-time half: a model's radiance transfer (PRT, seed 002) baked once
# and relit by the sky at noon, sunset and twilight; the model in the viewer
# (headless); the planet from sea level to space (seed 000) with the network
# of 40-neural.sh. All on OpenGL through headless EGL (Mesa's llvmpipe is enough).
set -euo pipefail
models=/usr/share/assimp/models

"$SKYBAKE" mesh generate --kind city --triangles 20000 --seed 4 -o "$OUT/rt_city.glb"
"$SKYBAKE" prt bake "$OUT/rt_city.glb" -o "$OUT/rt_city_prt.glb" --order 3 --rule lebedev:590 --bounces 1
for sun in noon:60 sunset:3 twilight:-4; do
  name=${sun%%:*} elevation=${sun#*:}
  "$SKYBAKE" prt relight "$OUT/rt_city_prt.glb" --light sky --sun-elevation-deg "$elevation" --sun-azimuth-deg 40 \
    --view 20,25 --size 480x360 -o "$OUT/rt_city_$name.png"
done

# The viewer's first frame, headless, under the trained network.
"$SKYBAKE" prt bake "$models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb" -o "$OUT/rt_engine.glb" \
  --order 3 --rule lebedev:302
"$SKYBAKE" view "$OUT/rt_engine.glb" --screenshot "$OUT/rt_engine_view.png" --model "$OUT/sky_net.json" \
  --size 640x360 --sun-elevation-deg 12 --sun-azimuth-deg 60 --set view=20,8

# From 2 m above the sea to 10,000 km, as a strip of frames.
"$SKYBAKE" fly --model "$OUT/sky_net.json" --frames 8 --size 240x180 --shading pixel -o "$OUT/fly" \
  --strip "$OUT/fly_strip.png"
