#!/bin/sh
# suite-plotpng.sh: a reference-image test for one SVG plot. The SVG that
# plotDisplacement writes is rendered to PNG by headless Chromium and the
# picture is checked against the SVG's own geometry (tests/svg_curve_check.py):
# not blank, the curve drawn along its polyline and not mirrored, the red
# markers red. Robust to fonts and anti-aliasing: no byte comparison.
# One line per check: "ok NAME", "FAIL NAME: why" or "skip NAME: why".
#   QCS  the binary under test (default ./qcs)
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
top=$(pwd)
browser=$(command -v chromium || command -v chromium-browser)
if [ -z "$browser" ]; then
  echo "skip plot-png-displacement: chromium is not installed (make test-deps)"
  exit 0
fi
if ! command -v python3 >/dev/null; then
  echo "skip plot-png-displacement: python3 is not installed"
  exit 0
fi
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
if ! (cd "$tmp" && "$top/$QCS" -e 'plotDisplacement "d.svg"') >/dev/null 2>"$tmp/err"; then
  echo "FAIL plot-png-displacement: qcs: $(head -c 200 "$tmp/err")"
  exit 0
fi
mkdir "$tmp/profile"
timeout 90 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
  --no-first-run --disable-background-networking --disable-component-update \
  --disable-sync --user-data-dir="$tmp/profile" --screenshot="$tmp/d.png" \
  --window-size=720,470 "file://$tmp/d.svg" >"$tmp/log" 2>&1
if [ ! -s "$tmp/d.png" ]; then
  echo "FAIL plot-png-displacement: chromium wrote no screenshot ($(tail -c 200 "$tmp/log"))"
  exit 0
fi
if why=$(python3 tests/svg_curve_check.py "$tmp/d.png" "$tmp/d.svg" displacement); then
  echo "ok plot-png-displacement"
else
  echo "FAIL plot-png-displacement: $why"
fi
