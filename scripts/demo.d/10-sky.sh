# Sky: the reference model from the ground and from orbit.
set -euo pipefail
"$SKYBAKE" sky preset earth -o "$OUT/earth.json"
"$SKYBAKE" sky render --atmosphere "$OUT/earth.json" --altitude-km 0 --sun-elevation-deg 35 --view fisheye \
  --size 384x384 -o "$OUT/sky_fisheye.png"
"$SKYBAKE" sky render --atmosphere "$OUT/earth.json" --altitude-km 0 --sun-elevation-deg 1 --view camera --fov 90 \
  --pitch 12 --size 480x320 -o "$OUT/sky_sunset.png"
"$SKYBAKE" sky render --atmosphere "$OUT/earth.json" --altitude-km 400 --sun-elevation-deg 25 --sun-azimuth-deg 30 \
  --view camera --fov 70 --pitch -18 --size 480x320 --exposure 3 -o "$OUT/sky_limb.png"
"$SKYBAKE" sky render --atmosphere "$OUT/earth.json" --altitude-km 0 --sun-elevation-deg 20 --view panorama \
  --size 1024x512 -o "$OUT/sky_panorama.exr"
printf 'cos_view_zenith,cos_view_sun,cos_sun_zenith,density\n1,0.8,0.8,1\n0.1,0.95,0.05,1\n0.5,-0.2,0.3,0.5\n' \
  > "$OUT/sky_in.csv"
"$SKYBAKE" sky eval --atmosphere "$OUT/earth.json" --input "$OUT/sky_in.csv" --output "$OUT/sky_out.csv"
cat "$OUT/sky_out.csv"
