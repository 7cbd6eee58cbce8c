# Neural sky: train the seed's 324-weight network (a short run), measure it,
# render with it and export it as a GLSL function.
set -euo pipefail
"$SKYBAKE" sky train --preset earth --samples 200000 --epochs 30 -o "$OUT/sky_net.json" \
  --curve "$OUT/sky_net_curve.csv" --chart "$OUT/sky_net_curve.png"
"$SKYBAKE" sky error --model "$OUT/sky_net.json" --samples 20000
"$SKYBAKE" sky render --model "$OUT/sky_net.json" --altitude-km 0 --sun-elevation-deg 20 --view panorama \
  --size 512x256 -o "$OUT/sky_net_panorama.png"
"$SKYBAKE" sky export "$OUT/sky_net.json" --format glsl -o "$OUT/sky_net.glsl"
