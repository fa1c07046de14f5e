#!/usr/bin/env sh
# Puts a global wave on a coarse mesh and evaluates the wrinkled surface with the pleat CLI.
#
#   examples_c/wrinkle_demo.sh [BASE_MESH [OUT_MESH]]
#
# Without BASE_MESH an icosahedron (radius ~1.9) is written and used. The base must be a coarse,
# consistently oriented manifold mesh (boundary allowed): evaluation multiplies its triangle
# count by 4 per level, so bring a few hundred to a few thousand triangles. The LOD pipeline that
# will turn a dense scan into such a base (`pleat lod`) is not on main yet; until then use a
# coarse mesh you have (or a decimated one).
#
# Environment: PLEAT (the pleat command; default `cargo run --quiet --release --`),
# K (wave vector KX,KY,KZ in radians per length unit of the mesh; default 9,4,2),
# AMPLITUDE (length unit; default 0.005 x the bounding-box diagonal), LEVELS (default 4).
set -eu

PLEAT=${PLEAT:-"cargo run --quiet --release --"}
K=${K:-9,4,2}
LEVELS=${LEVELS:-4}
work=$(mktemp -d "${TMPDIR:-/tmp}/pleat-wrinkle-demo.XXXXXX")
trap 'rm -rf "$work"' EXIT

base=${1:-}
if [ -z "$base" ]; then
  base=$work/icosahedron.obj
  cat >"$base" <<'EOF'
# icosahedron, outward counter-clockwise faces
v -1 1.618033988749895 0
v 1 1.618033988749895 0
v -1 -1.618033988749895 0
v 1 -1.618033988749895 0
v 0 -1 1.618033988749895
v 0 1 1.618033988749895
v 0 -1 -1.618033988749895
v 0 1 -1.618033988749895
v 1.618033988749895 0 -1
v 1.618033988749895 0 1
v -1.618033988749895 0 -1
v -1.618033988749895 0 1
f 1 12 6
f 1 6 2
f 1 2 8
f 1 8 11
f 1 11 12
f 2 6 10
f 6 12 5
f 12 11 3
f 11 8 7
f 8 2 9
f 4 10 5
f 4 5 3
f 4 3 7
f 4 7 9
f 4 9 10
f 5 10 6
f 3 5 12
f 7 3 11
f 9 7 8
f 10 9 2
EOF
fi
out=${2:-wrinkled.ply}

echo "== base mesh: $base"
$PLEAT check --no-self-intersections "$base"

# 1. the field: a plane wave exp(i k.x) restricted to the surface, stored next to the base
if [ -n "${AMPLITUDE:-}" ]; then
  $PLEAT wrinkle plane-wave "$base" --k="$K" --amplitude "$AMPLITUDE" -o "$work/wave.cwf"
else
  $PLEAT wrinkle plane-wave "$base" --k="$K" -o "$work/wave.cwf"
fi

# 2. the wrinkled surface: LEVELS Loop refinements, displaced along the normals
$PLEAT wrinkle eval "$base" --cwf "$work/wave.cwf" --levels "$LEVELS" -o "$out"

# 3. the output is watertight when the base is
echo "== result: $out"
$PLEAT check "$out"
