#!/usr/bin/env bash
# Cold-build timings for docs/benchmarks/build.md: a cold `cargo build --release` (the CLI and
# the library) and a cold `cargo test --no-run`, each in a fresh target directory, with cargo's
# `--timings` report reduced to its ten longest units.
#
#   bash scripts/build_timings.sh [OUT_DIR]     # default OUT_DIR: target/build-timings
#
# Downloads are not timed (`cargo fetch` runs first). Run it on an idle machine: every unit's
# time grows with whatever else is using the cores.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-target/build-timings}
mkdir -p "$out"
cargo fetch --quiet

top10() { # top10 TIMINGS_HTML: the ten longest units of a cargo --timings report
  python3 - "$1" <<'EOF'
import json, re, sys
html = open(sys.argv[1]).read()
units = json.loads(re.search(r"const UNIT_DATA = (\[.*?\]);", html, re.S).group(1))
units.sort(key=lambda u: -u["duration"])
print("| unit | target | seconds |")
print("| --- | --- | ---: |")
for u in units[:10]:
    target = u.get("target", "").strip() or "lib"
    print(f"| {u['name']} {u['version']} | {target} | {u['duration']:.1f} |")
print(f"\n{len(units)} units, {sum(u['duration'] for u in units):.0f} s of unit time in all")
EOF
}

run() { # run NAME CARGO_ARGS...: one cold build, its wall time and top units
  local name=$1; shift
  local dir; dir=$(mktemp -d "${TMPDIR:-/tmp}/pleat-cold-XXXXXX")
  local start; start=$(date +%s)
  CARGO_TARGET_DIR=$dir cargo "$@" --timings >"$out/$name.log" 2>&1
  local wall=$(( $(date +%s) - start ))
  {
    echo "### \`cargo $*\`: ${wall} s wall"
    echo
    top10 "$(ls -t "$dir"/cargo-timings/cargo-timing-*.html | head -1)"
    echo
  } | tee "$out/$name.md"
  rm -rf "$dir"
}

echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB; load before: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "commit: $(git rev-parse --short HEAD); $(rustc --version)"
run release build --release
run test test --no-run
