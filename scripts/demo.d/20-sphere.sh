# Sphere: quadrature rules as CSV, for use in other tools.
set -euo pipefail
"$SKYBAKE" sphere export lebedev:5810 -o "$OUT/lebedev5810.csv"
"$SKYBAKE" sphere export design:t21 -o "$OUT/design_t21.csv"
"$SKYBAKE" sphere show phong:a=32,n=8 --limit 2
