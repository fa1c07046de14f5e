#!/usr/bin/env bash
# Headless test of the Blender add-on (bindings/blender/pleat_lod), docs/guide/getting-started.md, "Blender add-on".
# Not part of .ci/run: Debian's Blender with its dependencies is too large for CI's budget.
#
#   bash .ci/blender.sh        # installs blender + python3-numpy with apt when missing (root)
#
# Uses the library cargo built (target/release, else target/debug; builds it when neither
# exists) through the Python package in bindings/python, and runs
# bindings/blender/test_addon.py in `blender -b`, then (when xvfb-run is there)
# bindings/blender/test_modal.py in a Blender window on Xvfb: the interactive path (modal
# operator, worker thread, Esc).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v blender >/dev/null || ! blender -b --factory-startup --python-expr 'import numpy' \
     >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq blender python3-numpy xvfb xauth >/dev/null
  else
    echo "blender (with numpy in its Python) is not installed: apt-get install blender python3-numpy" >&2
    exit 2
  fi
fi
target=${CARGO_TARGET_DIR:-$PWD/target}
lib=
for p in release debug; do
  if [ -e "$target/$p/libpleat.so" ]; then lib=$target/$p/libpleat.so; break; fi
done
if [ -z "$lib" ]; then
  cargo build --release --lib
  lib=$target/release/libpleat.so
fi
export PLEAT_LIBRARY=$lib PLEAT_PYTHON=$PWD/bindings/python
# A corpus mesh not in the repository (shared/ sits beside the checkout in CI; override with
# PLEAT_BLENDER_MESH=...).
for d in ../shared /work/shared; do
  if [ -z "${PLEAT_BLENDER_MESH:-}" ] && [ -e "$d/meshes/coarse_spot_1k.obj" ]; then
    export PLEAT_BLENDER_MESH=$d/meshes/coarse_spot_1k.obj
  fi
done
blender -b --factory-startup --python-exit-code 1 -P bindings/blender/test_addon.py 2>&1 |
  grep -v -e '^Blender quit$' -e '^Read prefs' -e '^$'
if command -v xvfb-run >/dev/null; then
  xvfb-run -a blender --factory-startup --enable-event-simulate --python-exit-code 1 \
    -P bindings/blender/test_modal.py 2>&1 |
    grep -v -e '^Blender quit$' -e '^Read prefs' -e '^$' -e '^Warning: ' -e 'ALSA' -e '^AL lib'
  test "${PIPESTATUS[0]}" = 0
else
  echo "SKIPPED: xvfb-run not installed (apt-get install xvfb xauth): the modal path was not run"
fi
