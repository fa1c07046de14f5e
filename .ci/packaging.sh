#!/usr/bin/env bash
# Packaging checks (docs/guide/getting-started.md, "C and C++" and "Python"): installs pleat into a temporary prefix with
# packaging/install.sh, builds the separate C consumer (examples_c/consumer) against it three
# ways — CMake find_package(pleat) with pleat::pleat, the same with pleat::pleat_static, and
# pkg-config through its Makefile — and runs each; compiles the C++ RAII test against the
# installed headers; moves the prefix and builds again (the CMake config is relocatable);
# builds the Python wheel with the library bundled, installs it into a fresh virtual
# environment and runs the pytest suite there with no PLEAT_LIBRARY set.
#
#   bash .ci/packaging.sh                          # installs cargo's release build
#   PLEAT_PACKAGING_PROFILE=test bash .ci/packaging.sh
#       # reuses the library `cargo test` built (target/debug; what .ci/run does, so CI
#       # compiles nothing twice)
#
# A missing tool (cmake, pkg-config, a C/C++ compiler, python3 with venv, PyPI for numpy and
# pytest) skips its part with a "SKIPPED:" line; a failure of a part that ran fails the script.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
start=$(date +%s)
step() { echo; echo "=== packaging [$(( $(date +%s) - start ))s] $*"; }
skip() { echo "SKIPPED: $*"; }
have() { command -v "$1" >/dev/null 2>&1; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/pleat-packaging.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
target=${CARGO_TARGET_DIR:-$root/target}
profile=${PLEAT_PACKAGING_PROFILE:-release}
version=$(sed -n '/^\[package\]/,/^\[/s/^version *= *"\([^"]*\)".*/\1/p' Cargo.toml | head -n 1)
passed=0
failed=0
ok() { echo "ok: $*"; passed=$((passed + 1)); }

step "install into a temporary prefix (profile $profile)"
case $profile in
  test)
    # The same command tests/c_harness.rs runs: after `cargo test` it only copies the library.
    cargo build --lib --tests --profile test
    sh packaging/install.sh --prefix "$prefix" --profile debug --no-build ;;
  release) sh packaging/install.sh --prefix "$prefix" ;;
  *) echo "PLEAT_PACKAGING_PROFILE must be release or test" >&2; exit 2 ;;
esac
lib=$prefix/lib
test "$(readlink "$lib/libpleat.so")" = libpleat.so.0
test "$(readlink "$lib/libpleat.so.0")" = "libpleat.so.$version"
if have readelf; then
  readelf -d "$lib/libpleat.so.$version" | grep -q 'SONAME.*\[libpleat.so.0\]'
fi
ok "installed files, symlinks and SONAME"

expect_run() { # expect_run EXE: runs the consumer, checks its line and that it used the prefix
  local out
  out=$("$1")
  echo "$out"
  case $out in "pleat $version: LOD with "*" triangles") ;; *) echo "unexpected output" >&2; return 1 ;; esac
}

step "one version everywhere: Cargo.toml, pleat --version, pkg-config, CMake (Python below)"
if [ -x "$target/$([ "$profile" = test ] && echo debug || echo release)/pleat" ]; then
  cli=$target/$([ "$profile" = test ] && echo debug || echo release)/pleat
  test "$("$cli" --version)" = "pleat $version"
  ok "pleat --version is $version"
else
  skip "no pleat binary built for profile $profile: pleat --version not compared"
fi
if have cmake; then
  mkdir -p "$tmp/version"
  printf '%s\n' 'cmake_minimum_required(VERSION 3.16)' 'project(pleat_version NONE)' \
    'find_package(pleat ${EXPECT} EXACT REQUIRED)' 'message(STATUS "pleat_VERSION=${pleat_VERSION}")' \
    > "$tmp/version/CMakeLists.txt"
  cmake -S "$tmp/version" -B "$tmp/version/build" -DCMAKE_PREFIX_PATH="$prefix" \
    -DEXPECT="$version" | grep -x -- "-- pleat_VERSION=$version"
  ok "CMake find_package(pleat $version EXACT)"
fi

step "README's C example is examples_c/consumer/consumer.c"
awk '/^<!-- examples_c\/consumer\/consumer.c/ { on = 1; next }
     on && /^```c$/ { copy = 1; next }
     copy && /^```$/ { exit }
     copy { print }' README.md | diff - examples_c/consumer/consumer.c
ok "README C example is the tested consumer"

step "C consumer with CMake find_package(pleat) -> pleat::pleat, then pleat::pleat_static"
if have cmake && have cc; then
  cmake -S examples_c/consumer -B "$tmp/cmake" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
  cmake --build "$tmp/cmake" >/dev/null
  expect_run "$tmp/cmake/consumer"
  if have readelf; then readelf -d "$tmp/cmake/consumer" | grep -q 'NEEDED.*\[libpleat.so.0\]'; fi
  ok "CMake consumer (shared)"
  cmake -S examples_c/consumer -B "$tmp/cmake-static" -DCMAKE_PREFIX_PATH="$prefix" \
    -DPLEAT_STATIC=ON >/dev/null
  cmake --build "$tmp/cmake-static" >/dev/null
  if have readelf && readelf -d "$tmp/cmake-static/consumer" | grep -q 'libpleat'; then
    echo "the static consumer links libpleat dynamically" >&2; exit 1
  fi
  expect_run "$tmp/cmake-static/consumer"
  ok "CMake consumer (static)"
else
  skip "cmake or cc not found: the CMake consumer was not built (apt-get install cmake gcc)"
fi

step "C consumer with pkg-config (examples_c/consumer/Makefile)"
if have pkg-config && have make && have cc; then
  export PKG_CONFIG_PATH="$lib/pkgconfig"
  test "$(pkg-config --modversion pleat)" = "$version"
  echo "pkg-config --cflags --libs pleat: $(pkg-config --cflags --libs pleat)"
  make -s -C "$tmp" -f "$root/examples_c/consumer/Makefile" VPATH="$root/examples_c/consumer" consumer
  expect_run "$tmp/consumer"
  ok "pkg-config consumer"
  unset PKG_CONFIG_PATH
else
  skip "pkg-config, make or cc not found: the pkg-config consumer was not built"
fi

step "C++ RAII test (examples_c/cpp_raii.cpp) against the installed headers"
if have g++; then
  g++ -std=c++17 -Wall -Wextra -Werror -pedantic -I"$prefix/include" examples_c/cpp_raii.cpp \
    -o "$tmp/cpp_raii" -L"$lib" -Wl,-rpath,"$lib" -lpleat
  (cd "$root" && "$tmp/cpp_raii")
  ok "C++ RAII test"
else
  skip "g++ not found: the C++ test against the installed headers was not built"
fi

step "relocated prefix: the CMake package finds itself after a move"
if have cmake && have cc; then
  mv "$prefix" "$tmp/moved"
  cmake -S examples_c/consumer -B "$tmp/cmake-moved" -DCMAKE_PREFIX_PATH="$tmp/moved" >/dev/null
  cmake --build "$tmp/cmake-moved" >/dev/null
  expect_run "$tmp/cmake-moved/consumer"
  mv "$tmp/moved" "$prefix"
  ok "relocated CMake package"
else
  skip "cmake not found: relocation not checked"
fi

step "Python: wheel with the library bundled, installed into a fresh venv, pytest"
if have python3 && python3 -c "import venv, ensurepip" >/dev/null 2>&1; then
  python3 -m venv "$tmp/venv"
  py=$tmp/venv/bin/python
  if "$py" -m pip install -q numpy pytest; then
    # Bundle the library just installed (no second cargo build): what `pip install
    # ./bindings/python` does with cargo's release build when PLEAT_BUNDLE_LIBRARY is unset.
    PLEAT_BUNDLE_LIBRARY="$lib/libpleat.so.$version" \
      "$py" -m pip wheel -q --no-deps -w "$tmp/wheels" ./bindings/python
    rm -rf bindings/python/build bindings/python/*.egg-info
    wheel=$(ls "$tmp"/wheels/pleat-"$version"-py3-none-*.whl)
    echo "wheel: $(basename "$wheel")"
    "$py" -m pip install -q "$wheel"
    # Run from outside the source tree, without PLEAT_LIBRARY: the installed package must find
    # its bundled library on its own.
    (cd "$tmp" && env -u PLEAT_LIBRARY "$py" -c \
      'import pleat, sys; p = pleat.library_path(); print("pleat", pleat.version(), "loads", p); sys.exit("site-packages" not in p)')
    (cd "$tmp" && env -u PLEAT_LIBRARY "$py" -c \
      'import importlib.metadata as m, pleat, sys; v = (m.version("pleat"), pleat.__version__, pleat.version()); print("python versions", v); sys.exit(v != (sys.argv[1],) * 3)' "$version")
    (cd "$tmp" && env -u PLEAT_LIBRARY "$py" -m pytest -q -p no:cacheprovider "$root/bindings/python/tests")
    ok "Python package"
  else
    skip "pip could not install numpy and pytest (no PyPI?): the Python package was not tested"
  fi
else
  skip "python3 with venv/ensurepip not found (apt-get install python3-venv): Python package not tested"
fi

step "done in $(( $(date +%s) - start ))s"
echo "packaging: $passed passed, $failed failed"
