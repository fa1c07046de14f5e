#!/usr/bin/env bash
# Builds every C/C++ program of examples_c/ with -fsanitize=address,undefined and runs it
# against the shared library, then builds examples_c/threads.c with -fsanitize=thread and
# runs it (4 host threads calling pleat at once).
#
# What this covers: the C side and the boundary. The programs are instrumented, so every
# out-of-bounds or use-after-free access by the caller's code, every undefined behaviour in
# it, and every misuse of memory that crosses the boundary is caught: pleat writing past a
# caller buffer whose size it was told, a caller reading past an array pleat returned, double
# destroys, leaks of handles (LeakSanitizer), data races between the host threads (TSan).
# ASan intercepts malloc/free process-wide, so heap blocks Rust allocates are also guarded by
# redzones. What it does not cover: accesses made inside libpleat's own (uninstrumented) Rust
# code to its own memory, and races between pleat's internal worker threads; Rust's safe code
# and the Miri run of the FFI helpers (see README "Security and robustness") stand for those.
#
#   bash .ci/asan.sh            # uses ${CARGO_TARGET_DIR:-target}/debug/libpleat.so, built if absent
#   PLEAT_LIB_DIR=target/release bash .ci/asan.sh
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
libdir=${PLEAT_LIB_DIR:-${CARGO_TARGET_DIR:-$root/target}/debug}
if [ ! -e "$libdir/libpleat.so" ]; then
  # the same build as tests/c_harness.rs, so after `cargo test` this only copies the library
  cargo build --lib --tests --profile test
fi
ln -sf libpleat.so "$libdir/libpleat.so.0"
out=${TMPDIR:-/tmp}/pleat-asan-$$
mkdir -p "$out"
trap 'rm -rf "$out"' EXIT
flags=(-g -O1 -fno-omit-frame-pointer -Wall -Wextra -Werror -pedantic
       -I"$root/include" -I"$root/bindings/cpp" -L"$libdir" -Wl,-rpath,"$libdir")
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:halt_on_error=1:detect_stack_use_after_return=1}
# xatlas (vendored C++) leaks inside its packer; see examples_c/lsan.supp.
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/examples_c/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}
assimp=$(pkg-config --cflags --libs assimp 2>/dev/null || true)
ran=0
for src in examples_c/*.c examples_c/*.cpp; do
  name=$(basename "${src%.*}")
  extra=()
  case "$name" in
    assimp_*) if [ -z "$assimp" ]; then echo "SKIPPED $name (no assimp)"; continue; fi
              read -r -a extra <<<"$assimp" ;;
    threads|lod_chain) extra=(-pthread) ;;
  esac
  if [[ $src == *.cpp ]]; then cc=(c++ -std=c++17); else cc=(cc -std=c99); fi
  "${cc[@]}" "${flags[@]}" -fsanitize=address,undefined -fno-sanitize-recover=undefined \
    "$src" -o "$out/$name" -lpleat -lm "${extra[@]}"
  echo "=== asan+ubsan: $name"
  "$out/$name" >"$out/$name.log" 2>&1 || { cat "$out/$name.log"; echo "FAILED: $name"; exit 1; }
  tail -1 "$out/$name.log"
  ran=$((ran + 1))
done
echo "=== tsan: threads"
# libpleat is not instrumented: the hand-off of a call to pleat's pool threads (rayon's latches,
# plain atomics in uninstrumented code) is invisible to TSan, which then reports the pool
# thread's memcpy of the caller's parameter struct as a race. Ignore interceptor accesses made
# from libpleat itself; every access by the C program is still checked.
printf 'called_from_lib:libpleat.so.0\ncalled_from_lib:libpleat.so\n' >"$out/tsan.supp"
export TSAN_OPTIONS="$TSAN_OPTIONS:suppressions=$out/tsan.supp"
cc -std=c99 "${flags[@]}" -fsanitize=thread -pthread examples_c/threads.c -o "$out/threads_tsan" -lpleat -lm
"$out/threads_tsan" >"$out/threads_tsan.log" 2>&1 || { cat "$out/threads_tsan.log"; echo "FAILED: threads under TSan"; exit 1; }
tail -1 "$out/threads_tsan.log"
echo "sanitizers: $ran programs under ASan+UBSan, threads.c under TSan: all passed"
