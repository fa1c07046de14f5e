#!/usr/bin/env bash
# Headless test of the Blender add-on (bindings/blender/pleat_lod), docs/guide/getting-started.md, "Blender add-on".
#
#   bash .ci/blender.sh          # a Blender binary: installs blender + python3-numpy with apt
#                                # when missing (root); then the headless and the window test
#   bash .ci/blender.sh --bpy    # Blender as a Python module: `pip install bpy numpy` into a
#                                # fresh venv (the bpy wheel of Blender 4.5 LTS wants Python
#                                # 3.11); the headless test only. .ci/run uses this form; it
#                                # prints SKIPPED and exits 0 when the venv or pip fails.
#
# Uses the library cargo built (target/release, else target/debug; builds it when neither
# exists) through the Python package in bindings/python, and runs
# bindings/blender/test_addon.py in `blender -b` (or the bpy module), then (a binary, when
# xvfb-run is there) bindings/blender/test_modal.py in a Blender window on Xvfb: the
# interactive path (modal operator, worker thread, Esc).
set -euo pipefail
cd "$(dirname "$0")/.."
bpy_module=0
if [ "${1:-}" = "--bpy" ]; then
  bpy_module=1
  BPY_VERSION=${PLEAT_BPY_VERSION:-4.5.4}
  venv=$(mktemp -d)/bpy
  trap 'rm -rf "$(dirname "$venv")"' EXIT
  if ! python3 -m venv "$venv" >/dev/null 2>&1 ||
     ! "$venv/bin/pip" install -q "bpy==$BPY_VERSION" numpy >/dev/null 2>&1; then
    echo "SKIPPED: could not pip-install bpy==$BPY_VERSION (it needs Python 3.11 and PyPI): the Blender add-on was not tested"
    exit 0
  fi
elif ! command -v blender >/dev/null || ! blender -b --factory-startup --python-expr 'import numpy' \
     >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq blender python3-numpy xvfb xauth >/dev/null
  else
    echo "blender (with numpy in its Python) is not installed: apt-get install blender python3-numpy, or run with --bpy" >&2
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
if [ "$bpy_module" = 1 ]; then
  "$venv/bin/python" bindings/blender/test_addon.py
  echo "SKIPPED: the window test (test_modal.py) needs a Blender binary"
  exit 0
fi
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
