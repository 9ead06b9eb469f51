#!/usr/bin/env bash
# Provenance end to end: a run says whether the source it was built from was committed. In a
# fresh clone of this repository's HEAD (so the caller's own uncommitted changes do not matter),
# a plain `cargo build` after each step must give a run whose results.json records:
#   as cloned: git_dirty false, no diff hash;
#   a line appended to README.md: git_dirty true and the FNV-1a 64 of `git diff HEAD --binary`;
#   a second line appended: another hash;
#   README.md checked out again: git_dirty false.
# Exits 1 with a line saying which step failed. Debug build; dependencies are kept in
# target/provenance-check, so a second run only rebuilds oceanbench.
set -euo pipefail
root=$(git rev-parse --show-toplevel)
export CARGO_TARGET_DIR="$root/target/provenance-check"
# A fixed checkout path rather than a fresh temporary one: Cargo names the crate's artifacts and
# incremental cache after its path, so each new path would compile it from scratch and leave the
# old ones behind.
src="$CARGO_TARGET_DIR/checkout"
runs=$(mktemp -d)
trap 'rm -rf "$runs" "$src"' EXIT
start=$SECONDS

fail() {
    echo "provenance-check: FAIL: $*" >&2
    exit 1
}

rm -rf "$src"
git clone -q "$root" "$src"
cd "$src"

# Builds as a developer would, runs one short cell into $runs/$1, and writes to $runs/$1.state the
# run's `git_dirty git_diff_hash` (None where absent) and the hash of the checkout's diff now.
measure() {
    cargo build --quiet --locked || fail "$1: cargo build failed"
    "$CARGO_TARGET_DIR/debug/oceanbench" run --size 16 --workload 0 --mode serial --trials 1 \
        --frames 10 --seconds 0.01 --calibrate once --out "$runs/$1" >"$runs/$1.log" 2>&1 \
        || fail "$1: oceanbench run failed; its output: $(tail -3 "$runs/$1.log")"
    git diff HEAD --binary | python3 -c '
import json, sys
machine = json.load(open(sys.argv[1]))["machine"]
h = 0xCBF29CE484222325
for b in sys.stdin.buffer.read():
    h = ((h ^ b) * 0x100000001B3) % 2**64
print(machine.get("git_dirty"), machine.get("git_diff_hash"), f"{h:016x}")
' "$runs/$1/results.json" >"$runs/$1.state" || fail "$1: cannot read $runs/$1/results.json"
}

measure clean
read -r dirty hash _ <"$runs/clean.state"
[[ $dirty == False && $hash == None ]] || fail "as cloned: git_dirty $dirty, diff hash $hash; want False, None"

echo "provenance-check: an uncommitted line" >>README.md
measure edited
read -r dirty first expected <"$runs/edited.state"
[[ $dirty == True ]] || fail "after editing README.md: git_dirty $dirty; want True"
[[ $first == "$expected" ]] || fail "after editing README.md: diff hash $first; want $expected, the FNV-1a of git diff HEAD --binary"

echo "provenance-check: a second uncommitted line" >>README.md
measure edited-again
read -r dirty second _ <"$runs/edited-again.state"
[[ $dirty == True && $second != "$first" && $second != None ]] \
    || fail "after editing README.md again: git_dirty $dirty, diff hash $second; want True and a hash other than $first"

git checkout -q -- README.md
measure reverted
read -r dirty hash _ <"$runs/reverted.state"
[[ $dirty == False && $hash == None ]] || fail "after reverting README.md: git_dirty $dirty, diff hash $hash; want False, None"

echo "provenance-check: ok (clean, dirty $first, dirty $second, clean again) in $((SECONDS - start)) s"
