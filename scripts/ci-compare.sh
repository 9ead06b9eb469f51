#!/usr/bin/env bash
# Runs the CI sweep (configs/ci.json), ranks every sync method against `atomic` measured in the
# same run, and, when a baseline results directory or results.json is given, compares the run
# with it and fails (exit 1) on a regression whose whole confidence interval clears THRESHOLD %.
#
#   scripts/ci-compare.sh [BASELINE]     env: THRESHOLD (default 10), OUT (results directory)
set -euo pipefail
cd "$(dirname "$0")/.."
baseline="${1:-}"
threshold="${THRESHOLD:-10}"
out="${OUT:-results/ci-$(date -u +%Y%m%dT%H%M%SZ)}"

cargo build --release --quiet
bin=target/release/oceanbench

"$bin" sweep configs/ci.json --out "$out" --quiet --no-charts > "$out.log"
echo "CI sweep: $out"

# Within one run, slower methods are findings, not failures (spin on one core is meant to lose).
set +e
"$bin" compare "$out" --by sync --baseline atomic --threshold "$threshold" --format markdown \
  > "$out/compare-sync.md"
status=$?
set -e
[ "$status" -le 1 ] || exit "$status"
cat "$out/compare-sync.md"

if [ -n "$baseline" ]; then
  set +e
  "$bin" compare "$baseline" "$out" --threshold "$threshold" --format markdown \
    > "$out/compare-baseline.md"
  status=$?
  set -e
  cat "$out/compare-baseline.md"
  exit "$status"
fi
