#!/usr/bin/env bash
# The Ray recipe (examples/ray/bake_lods.py, docs/guide/remote.md): one Ray task per
# asset on a local Ray cluster, through the pleat Python package. Not part of .ci/run: Ray is
# a ~70 MB wheel with many dependencies, too much for CI's budget.
#
#   bash .ci/ray.sh        # venv with ray + numpy from PyPI (kept in $PLEAT_RAY_VENV)
#
# Bakes four corpus meshes (../shared, or the repo's asset when absent) and one corrupt file,
# checks that the corrupt one is a failed row while the others bake, and that every output of
# the Ray tasks is byte-identical to a bake in the driver process (--verify-local).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
venv=${PLEAT_RAY_VENV:-${TMPDIR:-/tmp}/pleat-ray-venv}
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c 'import ray, numpy' 2>/dev/null; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q ray numpy
fi
target=${CARGO_TARGET_DIR:-$root/target}
lib=
for p in release debug; do
  if [ -e "$target/$p/libpleat.so" ]; then lib=$target/$p/libpleat.so; break; fi
done
if [ -z "$lib" ]; then cargo build --release --lib; lib=$target/release/libpleat.so; fi
export PLEAT_LIBRARY=$lib PYTHONPATH=$root/bindings/python

tmp=$(mktemp -d "${TMPDIR:-/tmp}/pleat-ray.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/assets"
shared=../shared/meshes
[ -d "$shared" ] || shared=/work/shared/meshes
for m in coarse_spot_1k.obj coarse_torus.obj dirty_suzanne.obj coarse_fertility_1500.obj; do
  [ -e "$shared/$m" ] && cp "$shared/$m" "$tmp/assets/"
done
cp assets/dirty_two_boxes.obj "$tmp/assets/"
printf 'v 0 0 0\nv 1 0\nf 1 2 zz\n' > "$tmp/assets/broken.obj"
"$venv/bin/python" -c 'import ray; print("ray", ray.__version__)'
set +e
"$venv/bin/python" examples/ray/bake_lods.py "$tmp/assets" --screen-sizes 50,25 \
  --max-rounds 20 --out "$tmp/out" --num-cpus 2 --verify-local --report "$tmp/report.json" \
  | tee "$tmp/log"
rc=${PIPESTATUS[0]}
set -e
[ "$rc" = 1 ] || { echo "expected exit 1 (one corrupt asset), got $rc" >&2; exit 1; }
grep -q '^broken.obj: FAILED: ' "$tmp/log"
grep -q ' 1 failed, ' "$tmp/log"
grep -q '^determinism: ' "$tmp/log"
echo "ray recipe: ok"
