#!/usr/bin/env sh
# The dissertation's example edits (ch. 3.6) on the coarse corpus meshes with the pleat CLI:
# design from sources, local rotation, coupled frequency scaling, two regions at once, then
# edit -> interpolate -> evaluate end to end. Prints each solve's seconds and residual (the
# figures in docs/guide/wrinkle-design.md).
#
#   examples_c/wrinkle_edit_demo.sh [MESH_DIR [OUT_DIR]]
#
# MESH_DIR holds coarse_spot_1k.obj, coarse_fertility_1500.obj, coarse_torus.obj
# (default ../shared/meshes). Environment: PLEAT (default `cargo run --quiet --release --`).
# Wave vectors give ~10 edges per wavelength (|k| ≈ 0.6 / mean edge length).
set -eu

PLEAT=${PLEAT:-"cargo run --quiet --release --"}
M=${1:-../shared/meshes}
O=${2:-$(mktemp -d "${TMPDIR:-/tmp}/pleat-wrinkle-edit.XXXXXX")}
run() { echo "== pleat $*"; $PLEAT "$@"; }

spot=$M/coarse_spot_1k.obj
fert=$M/coarse_fertility_1500.obj
torus=$M/coarse_torus.obj

# Spot: local 90° rotation (Figs. 3.7, 3.19); body x2.5 (coupled) + head 90° at once (Fig. 3.19)
run wrinkle plane-wave "$spot" --k 7,0,0 -o "$O/spot_a.cwf"
run wrinkle edit "$spot" --cwf "$O/spot_a.cwf" \
    --region 'vertex=500,rings=5,interface=3,rotate=90' -o "$O/spot_rot.cwf"
run wrinkle edit "$spot" --cwf "$O/spot_a.cwf" \
    --region 'vertex=500,rings=4,interface=2,scale=2.5,couple' \
    --region 'vertex=100,rings=4,interface=2,rotate=90' -o "$O/spot_two.cwf"
# Fertility: local x3 frequency, amplitude / 3 (Fig. 3.6)
run wrinkle plane-wave "$fert" --k 0.06,0,0 -o "$O/fert_a.cwf"
run wrinkle edit "$fert" --cwf "$O/fert_a.cwf" \
    --region 'vertex=700,rings=5,interface=3,scale=3,couple' -o "$O/fert_x3.cwf"
# Torus: local 90° with the reference implementation's weights
run wrinkle plane-wave "$torus" --k 4,0,0 -o "$O/torus_a.cwf"
run wrinkle edit "$torus" --cwf "$O/torus_a.cwf" \
    --region 'vertex=200,rings=5,interface=3,rotate=90' --reference -o "$O/torus_rot.cwf"
# Design (Fig. 3.17): two sources with perpendicular wave vectors
run wrinkle design "$spot" --source 500,7,0,0,0.01,6 --source 100,0,7,0,0.01,6 \
    -o "$O/spot_design.cwf"
# Animate an edit: interpolate, evaluate every frame
run wrinkle interp "$O/spot_a.cwf" "$O/spot_rot.cwf" --base "$spot" --frames 20 --substeps 1 \
    -o "$O/spot_rot.cwfa"
run wrinkle eval-anim "$spot" "$O/spot_rot.cwfa" --levels 2 -o "$O/spot_rot_{i}.obj"
echo "outputs in $O"
