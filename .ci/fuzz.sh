#!/usr/bin/env bash
# Runs every fuzz target (fuzz/, cargo-fuzz + libFuzzer, AddressSanitizer) for a short bounded
# time from the committed seeds. Total time ≈ 11 targets × PLEAT_FUZZ_SECONDS (default 15 s)
# plus the build (a full nightly ASan build from a cold cache: ~10 min on 2 cores, so not yet
# part of .ci/run's budget; see README "Security and robustness").
#
#   bash .ci/fuzz.sh                      # all targets, 15 s each
#   PLEAT_FUZZ_SECONDS=1800 bash .ci/fuzz.sh obj ply    # long run of some targets
#
# Skips (exit 0, with a message) when the nightly toolchain or cargo-fuzz is missing.
# New corpus entries go to $PLEAT_FUZZ_CORPUS (default fuzz-target/corpus/<target>), never
# into the committed fuzz/seeds/. A crash leaves its input in fuzz/artifacts/<target>/ and fails.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${PLEAT_FUZZ_SECONDS:-15}
if ! rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
  echo "SKIPPED fuzzing: no nightly toolchain (rustup toolchain install nightly)"; exit 0
fi
if ! cargo +nightly fuzz --version >/dev/null 2>&1; then
  echo "SKIPPED fuzzing: cargo-fuzz not installed (cargo install cargo-fuzz)"; exit 0
fi
export CARGO_TARGET_DIR=${PLEAT_FUZZ_TARGET_DIR:-$PWD/fuzz-target}
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  mapfile -t targets < <(cargo +nightly fuzz list)
fi
cargo +nightly fuzz build
corpus_root=${PLEAT_FUZZ_CORPUS:-$CARGO_TARGET_DIR/corpus}
for t in "${targets[@]}"; do
  mkdir -p "$corpus_root/$t"
  echo "=== fuzz $t for ${secs}s"
  # -timeout: one input taking > 10 s is a hang; -rss_limit_mb: > 2 GiB is an OOM finding.
  log=$CARGO_TARGET_DIR/fuzz-$t.log
  status=0
  cargo +nightly fuzz run "$t" "$corpus_root/$t" "fuzz/seeds/$t" -- \
    -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
    -print_final_stats=1 >"$log" 2>&1 || status=$?
  grep -E '^(#[0-9]+.*DONE|stat::number_of_executed_units|stat::peak_rss_mb)' "$log" || true
  if [ "$status" -ne 0 ]; then
    tail -60 "$log"
    echo "fuzz target $t found a failure (exit $status): input saved in fuzz/artifacts/$t/"
    exit 1
  fi
done
echo "fuzzing done: ${#targets[@]} targets × ${secs}s"
