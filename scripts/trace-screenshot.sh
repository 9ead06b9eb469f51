#!/usr/bin/env bash
# Screenshots a trace as speedscope draws it, under headless Chromium: the check that a trace
# from `run --trace` opens in a viewer users already have, not just that it parses.
#
#   scripts/trace-screenshot.sh TRACE.json [PNG] [WIDTHxHEIGHT]
#
# Needs node/npm (speedscope comes from the npm registry into a temporary folder) and Chromium;
# speedscope draws with WebGL, which headless Chromium gives it through SwiftShader.
set -euo pipefail

if [[ $# -lt 1 || $# -gt 3 ]]; then
    echo "usage: $0 TRACE.json [PNG] [WIDTHxHEIGHT]" >&2
    exit 2
fi
trace=$1
png=${2:-${trace%.json}.speedscope.png}
size=${3:-1280x800}
if [[ ! -f $trace ]]; then
    echo "$0: $trace: no such trace (write one with: oceanbench run --trace $trace)" >&2
    exit 2
fi
browser=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
if [[ -z $browser ]]; then
    echo "$0: no Chromium found (Debian: apt-get install chromium)" >&2
    exit 2
fi
if ! command -v npm >/dev/null || ! command -v node >/dev/null; then
    echo "$0: node and npm are needed to fetch speedscope (Debian: apt-get install nodejs npm)" >&2
    exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
npm install --silent --no-audit --no-fund --prefix "$work" speedscope@1.25.0 >/dev/null
# speedscope's own CLI loads a profile this way: a script that hands it the file in base64.
node -e '
const fs = require("fs");
const [trace, out] = process.argv.slice(1);
const name = require("path").basename(trace);
const b64 = fs.readFileSync(trace).toString("base64");
fs.writeFileSync(out, `speedscope.loadFileFromBase64(${JSON.stringify(name)}, ${JSON.stringify(b64)})`);
' "$trace" "$work/profile.js"
"$browser" --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader --hide-scrollbars \
    --allow-file-access-from-files \
    --window-size="${size/x/,}" --virtual-time-budget=8000 --screenshot="$png" \
    "file://$work/node_modules/speedscope/dist/release/index.html#localProfilePath=$work/profile.js" \
    2>/dev/null
echo "$png"
