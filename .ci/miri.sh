#!/usr/bin/env bash
# Runs the unit tests of the C boundary's unsafe helpers (src/ffi/boundary.rs: pointer, slice,
# string, output-slot, handle and versioned-struct conversions) under Miri, which checks every
# access they make for undefined behaviour: out-of-bounds reads and writes, use of dangling or
# misaligned pointers, invalid values, aliasing violations (Stacked Borrows) and leaks.
#
#   bash .ci/miri.sh
#
# The tests make no FFI call, start no thread and touch no file, so Miri can run them. Miri
# interprets the crate and builds every dependency for its own sysroot on first use (a
# separate cache in target/miri); see README "Security and robustness" for the measured run time.
# Skips (exit 0, with a message) when the nightly toolchain or its miri component is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! cargo +nightly miri --version >/dev/null 2>&1; then
  echo "SKIPPED Miri: no nightly miri (rustup component add --toolchain nightly miri rust-src)"
  exit 0
fi
export MIRIFLAGS=${MIRIFLAGS:--Zmiri-strict-provenance}
cargo +nightly miri test --lib ffi::boundary "$@"
