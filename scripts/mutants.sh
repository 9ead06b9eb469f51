#!/usr/bin/env bash
# Mutation testing of the modules that decide what users are told or guard their data: runs
# cargo-mutants on each named source file (or folder) against the tests that cover it, and keeps
# what it found as a small results folder, results/mutants-<UTC>/:
#   summary.json  per module its commit and tree, the counts (caught, missed, timeout,
#                 unviable) with every survivor, explained or not;
#   summary.md    the same as a table;
#   <module>/     cargo-mutants' own outcomes (caught.txt, missed.txt, timeout.txt, unviable.txt).
# A survivor is explained when scripts/mutants-equivalent.txt names it (file, then the mutant as
# cargo-mutants words it without line and column, then ` -- ` and why it changes nothing).
#
#   scripts/mutants.sh src/lock.rs src/slow_trials.rs
#   OUT=results/mutants-x scripts/mutants.sh src/balance/   # adds a module to an earlier folder
#   scripts/mutants.sh 'src/sweep.rs:Sweep::resume'         # a file's mutants matching a regex
#   RETEST=1 OUT=results/mutants-x scripts/mutants.sh src/slow_trials.rs
#       # only the module's survivors in that folder, against today's tests: a survivor a new
#       # test kills is then counted caught, with the commit of the test (<module>-retest/);
#       # a FILE:REGEX module is retested under the same argument
#   NAME=compare-rest scripts/mutants.sh 'src/report/analysis/compare.rs:in (partners|mismatches)$'
#       # the module's folder under a short name instead of one spelt from the file and regex
#       # (one module only; a retest then needs the same NAME)
#
# The covering tests are found by the module paths they name; tests that drive the binary name
# none, so scripts/mutants-tests.txt lists them per module.
#
# Slow (a build and the covering tests per mutant): run it on a schedule, not on every push
# (docs/ci.md). Exit status: 0 when every survivor is explained, 1 when one is not, 2 on bad
# input.
set -euo pipefail
cd "$(dirname "$0")/.."

usage="usage: scripts/mutants.sh MODULE... (source files or folders under src/, or FILE:REGEX for a file's mutants whose names match REGEX)"
if [ $# -lt 1 ]; then
  echo "$usage" >&2
  exit 2
fi
if ! cargo mutants --version >/dev/null 2>&1; then
  echo "scripts/mutants.sh: cargo-mutants is missing: install it with 'cargo install cargo-mutants --locked'" >&2
  exit 2
fi
if [ -n "${NAME:-}" ] && [ $# -ne 1 ]; then
  echo "scripts/mutants.sh: NAME names one module's folder, and $# modules were given" >&2
  exit 2
fi
case "${NAME:-}" in
  *[!A-Za-z0-9_-]*) echo "scripts/mutants.sh: NAME=${NAME} may hold only letters, digits, '-' and '_'" >&2; exit 2 ;;
esac
for m in "$@"; do
  case "$m" in
    src/*.rs:?*) [ -f "${m%%:*}" ] || { echo "scripts/mutants.sh: ${m%%:*} is no source file ($usage)" >&2; exit 2; } ;;
    src/*.rs) [ -f "$m" ] || { echo "scripts/mutants.sh: $m is no source file ($usage)" >&2; exit 2; } ;;
    src/*/) [ -d "$m" ] || { echo "scripts/mutants.sh: $m is no folder of src/ ($usage)" >&2; exit 2; } ;;
    *) echo "scripts/mutants.sh: $m is no source file or folder under src/ ($usage)" >&2; exit 2 ;;
  esac
done

# The test targets that cover a module, one `--test=NAME` word each: the library's unit tests, and every integration test
# that names the module's path (oceanbench::lock, oceanbench::report::json), or, for a module
# inside a folder, names it on a line under its top module (oceanbench::report::{json, ...};
# report::compare, re-exported from report::analysis); and those scripts/mutants-tests.txt
# lists for it.
tests_for() {
  local module="$1" file name path top args=(--lib) files=()
  if [ -d "$module" ]; then
    mapfile -t files < <(find "${module%/}" -name '*.rs' | sort)
  else
    files=("$module")
  fi
  for file in "${files[@]}"; do
    path="${file#src/}"
    path="${path%.rs}"
    path="${path%/mod}"
    name="${path##*/}"
    path="${path//\//::}"
    top="${path%%::*}"
    for t in tests/*.rs; do
      if grep -q "oceanbench::$path\b\|crate::$path\b" "$t" \
        || { [ "$top" != "$path" ] && grep -q "oceanbench::$top::.*\b$name\b" "$t"; }; then
        args+=("--test=$(basename "$t" .rs)")
      fi
    done
  done
  local listed
  listed="$(awk -v m="$module" '!/^#/ && $1 == m ":" { for (i = 2; i <= NF; i++) print "--test=" $i }' scripts/mutants-tests.txt)"
  [ -z "$listed" ] || mapfile -t -O "${#args[@]}" args <<<"$listed"
  printf '%s\n' "${args[@]}" | awk '!seen[$0]++'
}

# The library's ocean tests take 16 of its 17 s in a dev build and exercise only the ocean
# models: a module outside src/ocean/ is tested without them.
test_filter() {
  case "$1" in
    src/ocean*) ;;
    *) printf '%s\n' --skip ocean:: ;;
  esac
}

# No debug info in the mutants' builds: each mutant is a build, and most of a dev build's link
# time is debug info no mutant outcome needs.
export CARGO_PROFILE_DEV_DEBUG="${CARGO_PROFILE_DEV_DEBUG:-0}"
# JOBS=2 runs two mutants at once (each in its own copy of the tree).
jobs="${JOBS:-1}"

stamp="$(date -u +%Y%m%dT%H%M%SZ)"
out="${OUT:-results/mutants-$stamp}"
mkdir -p "$out"
commit="$(git rev-parse HEAD)"
dirty=false
git diff-index --quiet HEAD -- || dirty=true
status=0
for m in "$@"; do
  file="${m%%:*}"
  re=()
  name="$(echo "${file%/}" | sed 's|^src/||; s|/|-|g; s|\.rs$||')"
  if [ "$file" != "$m" ]; then
    re=(--re "${m#*:}")
    name="$name-$(echo "${m#*:}" | tr -c 'A-Za-z0-9' '-' | sed 's/--*/-/g; s/^-//; s/-$//')"
  fi
  name="${NAME:-$name}"
  if [ -n "${RETEST:-}" ]; then
    survivors="$(cat "$out/$name/missed.txt" "$out/$name/timeout.txt" 2>/dev/null || true)"
    if [ -z "$survivors" ]; then
      echo "== $m: no survivor in $out/$name to retest" >&2
      continue
    fi
    # The survivors' names (file:line:column: change) as one anchored alternation, at any line
    # and column: a test written since may have moved them.
    re=(--re "^($(printf '%s\n' "$survivors" | sed 's/[][\\.*+?(){}|^$]/\\&/g; s/^\([^:]*\):[0-9]*:[0-9]*:/\1:[0-9]+:[0-9]+:/' | paste -sd '|'))\$")
    name="$name-retest"
  fi
  mapfile -t targets < <(tests_for "$file")
  mapfile -t filter < <(test_filter "$file")
  glob="$file"
  [ -d "$file" ] && glob="${file%/}/**/*.rs"
  echo "== $m: cargo test ${targets[*]} -- ${filter[*]}" >&2
  # --copy-vcs: tests read git (a run's provenance). Each mutant builds in a copy taken when
  # the module starts, so run this from a tree nobody edits meanwhile (a `git worktree`).
  # cargo-mutants exits 2 when a mutant survives, 3 on a timeout: outcomes are what count here.
  cargo mutants --no-shuffle --copy-vcs=true -j "$jobs" -f "$glob" "${re[@]}" --output "$out/$name.tmp" \
    --minimum-test-timeout 30 -- "${targets[@]}" -- "${filter[@]}" >&2 || true
  rm -rf "${out:?}/$name"
  mv "$out/$name.tmp/mutants.out" "$out/$name"
  rm -rf "${out:?}/$name.tmp"
  # Only the small outcome lists are kept; the logs and diffs stay out of results/.
  find "$out/$name" -mindepth 1 -not -name '*.txt' -not -name outcomes.json -exec rm -rf {} +
  rm -f "$out/$name/outcomes.json"
  # A folder gathers modules run at different times (OUT= the same folder): each keeps its commit.
  printf '%s%s\n' "$commit" "$([ "$dirty" = true ] && echo ' dirty')" >"$out/$name/commit"
  # What was run, for a folder whose NAME does not spell it.
  printf '%s\n' "$m" >"$out/$name/module"
done

python3 - "$out" <<'EOF' || status=$?
import json, re, sys, pathlib
out = pathlib.Path(sys.argv[1])
# Every module run into this folder so far, this call's and earlier ones'.
modules = sorted(d.name for d in out.iterdir() if (d / "commit").exists() and not d.name.endswith("-retest"))
equivalent = {}
for line in pathlib.Path("scripts/mutants-equivalent.txt").read_text().splitlines():
    if line.strip() and not line.startswith("#"):
        mutant, why = line.split(" -- ", 1)
        equivalent[mutant.strip()] = why.strip()

def key(mutant):
    # "src/lock.rs:194:46: replace && with || in same_file" -> "src/lock.rs: replace && with || in same_file"
    return re.sub(r"^([^:]+):\d+:\d+:", r"\1:", mutant)

def lines(path):
    return [l for l in path.read_text().splitlines() if l.strip()] if path.exists() else []

summary = {"modules": []}
unexplained = 0
for name in modules:
    d = out / name
    commit, _, dirty = (d / "commit").read_text().strip().partition(" ")
    argument = (d / "module").read_text().strip() if (d / "module").exists() else None
    caught, missed = lines(d / "caught.txt"), lines(d / "missed.txt")
    timeout, unviable = lines(d / "timeout.txt"), lines(d / "unviable.txt")
    # A survivor the retest caught was killed by a test written after the module's run.
    retest = out / f"{name}-retest"
    retest_commit = (retest / "commit").read_text().split()[0] if (retest / "commit").exists() else None
    # Matched at its line and column when the retest ran it there; otherwise without them (a
    # new test may move them), and then only when every mutant of its name the retest ran was
    # caught: several mutants share a name, and one left alive keeps them all counted alive.
    caught_exact = set(lines(retest / "caught.txt"))
    killed_later = {key(s) for s in caught_exact} - {
        key(s) for s in lines(retest / "missed.txt") + lines(retest / "timeout.txt")}
    survivors = []
    for s in missed + timeout:
        if s in caught_exact or key(s) in killed_later:
            survivors.append({"mutant": s, "caught_on_retest": retest_commit, "equivalent": None})
        else:
            survivors.append({"mutant": s, "equivalent": equivalent.get(key(s))})
    unexplained += sum(1 for s in survivors if s["equivalent"] is None and "caught_on_retest" not in s)
    on_retest = sum(1 for s in survivors if "caught_on_retest" in s)
    viable = len(caught) + len(missed) + len(timeout)
    summary["modules"].append({
        "module": name, "argument": argument, "commit": commit, "dirty": dirty == "dirty", "caught": len(caught), "missed": len(missed), "timeout": len(timeout),
        "unviable": len(unviable), "caught_on_retest": on_retest, "retest_commit": retest_commit,
        "caught_percent": round(100 * (len(caught) + on_retest) / viable, 1) if viable else None,
        "survivors": survivors,
    })
(out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
md = ["# Mutants", "",
      "Missed and timeout are the module's run; a survivor a later test kills is counted caught on its retest.", "",
      "| module | commit | caught | missed | timeout | unviable | caught on retest | caught of viable |", "|---|---|---:|---:|---:|---:|---:|---:|"]
for m in summary["modules"]:
    pct = "–" if m["caught_percent"] is None else f"{m['caught_percent']} %"
    tree = m["commit"][:12] + (" (dirty tree)" if m["dirty"] else "")
    retest = f"{m['caught_on_retest']} (at {m['retest_commit'][:12]})" if m["retest_commit"] else "–"
    md.append(f"| {m['module']} | {tree} | {m['caught']} | {m['missed']} | {m['timeout']} | {m['unviable']} | {retest} | {pct} |")
named = [m for m in summary["modules"] if m["argument"] and m["argument"].partition(":")[2]]
if named:
    md += ["", "Modules run on part of a file (`FILE:REGEX`):", ""]
    md += [f"- {m['module']}: `{m['argument']}`" for m in named]
md += ["", "Survivors:", ""]
for m in summary["modules"]:
    for s in m["survivors"]:
        if "caught_on_retest" in s:
            why = f"caught on retest at {s['caught_on_retest'][:12]}"
        elif s["equivalent"]:
            why = f"equivalent: {s['equivalent']}"
        else:
            why = "**unexplained**"
        md.append(f"- {s['mutant']}: {why}")
(out / "summary.md").write_text("\n".join(md) + "\n")
print("\n".join(md))
sys.exit(1 if unexplained else 0)
EOF
echo "$out" >&2
exit "$status"
