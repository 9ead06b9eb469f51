#!/usr/bin/env bash
# Renders a results folder's report.html with headless Chromium to a PNG and fails when the
# picture is blank (one colour), so CI catches a page that no longer draws.
#
#   scripts/report-screenshot.sh DIR [PNG] [HEIGHT]
#
# PNG defaults to DIR/report.png; HEIGHT (default 3000) is the window's height in pixels, so
# the shot covers the page's top: what was run, Figure 5-1 and the start of the tables.
set -euo pipefail

if [[ $# -lt 1 || $# -gt 3 ]]; then
    echo "usage: $0 DIR [PNG] [HEIGHT]" >&2
    exit 2
fi
dir=$1
page="$dir/report.html"
png=${2:-$dir/report.png}
height=${3:-3000}
if [[ ! -f $page ]]; then
    echo "$0: $page: no report.html (write it with: oceanbench report $dir)" >&2
    exit 2
fi
browser=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
if [[ -z $browser ]]; then
    echo "$0: no Chromium found (Debian: apt-get install chromium)" >&2
    exit 2
fi

profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
rm -f "$png"
# The flags keep a sandboxed, offline machine quiet: no GPU, no sandbox (root in CI), and no
# background connections, which a closed network refuses many at a time.
"$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --hide-scrollbars --user-data-dir="$profile" --window-size="1280,$height" \
    --screenshot="$(realpath -m "$png")" "file://$(realpath "$page")" >/dev/null 2>&1 || true
if [[ ! -s $png ]]; then
    echo "$0: Chromium wrote no screenshot of $page" >&2
    exit 1
fi

# Decode the PNG (8-bit RGB or RGBA, as Chromium writes) and count its colours.
python3 - "$png" <<'EOF'
import struct, sys, zlib

path = sys.argv[1]
data = open(path, "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
pos, idat, header = 8, b"", None
while pos < len(data):
    length, kind = struct.unpack(">I4s", data[pos : pos + 8])
    body = data[pos + 8 : pos + 8 + length]
    if kind == b"IHDR":
        header = struct.unpack(">IIBBBBB", body)
    elif kind == b"IDAT":
        idat += body
    pos += 12 + length
width, height, depth, colour = header[:4]
if depth != 8 or colour not in (2, 6):
    sys.exit(f"{path}: unexpected PNG format (depth {depth}, colour type {colour})")
bpp = 3 if colour == 2 else 4
raw = zlib.decompress(idat)
stride = width * bpp
prev = bytearray(stride)
colours = set()
for y in range(height):
    kind = raw[y * (stride + 1)]
    line = bytearray(raw[y * (stride + 1) + 1 : (y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - bpp] if i >= bpp else 0
        b = prev[i]
        c = prev[i - bpp] if i >= bpp else 0
        if kind == 1:
            line[i] = (line[i] + a) & 255
        elif kind == 2:
            line[i] = (line[i] + b) & 255
        elif kind == 3:
            line[i] = (line[i] + (a + b) // 2) & 255
        elif kind == 4:
            p = a + b - c
            pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
    if y % 8 == 0:
        colours.update(bytes(line[i : i + 3]) for i in range(0, stride, bpp * 4))
    prev = line
if len(colours) < 2:
    sys.exit(f"{path}: the screenshot is blank (one colour)")
print(f"{path}: {width}x{height}, {len(colours)} colours sampled")
EOF
