#!/usr/bin/env bash
# Runs the Figure 5-1 sweep (configs/figure-5-1.json, the built-in default) with its charts and
# prints where they are. Extra arguments go to `oceanbench sweep` (e.g. --out DIR).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
log=$(mktemp)
target/release/oceanbench sweep configs/figure-5-1.json "$@" | tee "$log"
dir=$(sed -n "s/^Results: //p" "$log" | tail -n 1)
echo
echo "Figure 5-1 charts: $dir/figure-5-1-sync-{atomic,mutex,condvar}.{png,svg} (one per method)"
echo "Other charts:      $dir/relative-sync-*.{png,svg}, $dir/{sync,frame-times,breakdown}.{png,svg}"
echo "Tables:            $dir/results.md, $dir/results.csv, $dir/results.json"
