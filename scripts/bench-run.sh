#!/usr/bin/env bash
# Runs one criterion bench and keeps what it measured as a benchmark run: the machine, the
# commit and each benchmark's median with its confidence interval in
# results/bench-BENCH-<UTC>/bench.json. Prints the folder (criterion's own output goes to stderr).
#
#   scripts/bench-run.sh BENCH [--] [FILTER] [CRITERION FLAGS...]
#   scripts/bench-run.sh fft -- fft-512 --warm-up-time 1 --measurement-time 3
#
# What follows BENCH goes to the bench as after `cargo bench --bench BENCH --`.
# env: OUT (the folder; default results/bench-BENCH-<UTC of the stamp>), CARGO_TARGET_DIR.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ]; then
  echo "usage: scripts/bench-run.sh BENCH [--] [FILTER] [CRITERION FLAGS...]" >&2
  exit 2
fi
command=(scripts/bench-run.sh "$@")
bench="$1"
shift
[ "${1:-}" != "--" ] || shift
target="${CARGO_TARGET_DIR:-target}"

# Built first, so a build failure does not waste the bench.
cargo build --release --quiet
mkdir -p "$target"
# Beside criterion's files, so both times come from the same file system's clock.
stamp="$(mktemp "$target/.bench-run-stamp.XXXXXX")"
trap 'rm -f "$stamp"' EXIT
touch "$stamp"
# Named by the stamp's time, which bench.json records as the run's start.
out="${OUT:-results/bench-$bench-$(date -u -r "$stamp" +%Y%m%dT%H%M%SZ)}"
cargo bench --quiet --bench "$bench" -- "$@" >&2
"$target/release/oceanbench" bench-record "$bench" --criterion-dir "$target/criterion" \
  --since "$stamp" --out "$out" -- "${command[@]}"
