#!/bin/sh
# suite-plotpng.sh: reference-image tests of the SVG plots. Each SVG a plot
# writes is rendered to PNG by headless Chromium and the picture is checked
# against the SVG's own geometry (tests/svg_curve_check.py): not blank,
# each curve drawn in its colour along its polyline and not mirrored, the
# red markers red, the bars of the search rows in their colours, the tick
# marks drawn, and plotSlice's picture shown pixel for pixel inside its
# axes. Robust to fonts and anti-aliasing: no byte comparison.
# One line per check: "ok NAME", "FAIL NAME: why" or "skip NAME: why".
#   QCS  the binary under test (default ./qcs)
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
top=$(pwd)
browser=$(command -v chromium || command -v chromium-browser)
if [ -z "$browser" ]; then
  echo "skip plot-png: chromium is not installed (make test-deps)"
  exit 0
fi
if ! command -v python3 >/dev/null; then
  echo "skip plot-png: python3 is not installed"
  exit 0
fi
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT

# check NAME SVG 'QCS EXPRESSION' [--image] CLASS...: run qcs in $tmp,
# render SVG at its own size, check it.
check() {
  name=$1 svg=$2 expr=$3
  shift 3
  if ! (cd "$tmp" && "$top/$QCS" -e "$expr") >/dev/null 2>"$tmp/err"; then
    echo "FAIL plot-png-$name: qcs: $(head -c 200 "$tmp/err")"
    return
  fi
  size=$(sed -n 's/.*<svg [^>]* width="\([0-9]*\)" height="\([0-9]*\)".*/\1,\2/p' "$tmp/$svg" | head -1)
  rm -rf "$tmp/profile" "$tmp/shot.png"
  mkdir "$tmp/profile"
  timeout 90 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
    --no-first-run --disable-background-networking --disable-component-update \
    --disable-sync --user-data-dir="$tmp/profile" --screenshot="$tmp/shot.png" \
    --window-size="$size" "file://$tmp/$svg" >"$tmp/log" 2>&1
  if [ ! -s "$tmp/shot.png" ]; then
    echo "FAIL plot-png-$name: chromium wrote no screenshot ($(tail -c 200 "$tmp/log"))"
    return
  fi
  if why=$(python3 tests/svg_curve_check.py "$tmp/shot.png" "$tmp/$svg" "$@"); then
    echo "ok plot-png-$name"
  else
    echo "FAIL plot-png-$name: $why"
  fi
}

check displacement d.svg 'plotDisplacement "d.svg"' displacement
check ray ray.svg \
  'plotRay "ray.svg" (Rounded 0.1 UnitCube) (-1, 0.95, 0.5) (1, 0, 0)' density
check ray-soft soft.svg \
  'plotRay "soft.svg" (SoftObject 0.5 [Key (0, 0, 0) 1 1, Key (0.8, 0, 0) 1 1]) (-2, 0.1, 0) (1, 0, 0)' \
  field
check field c.svg \
  'plotField "c.svg" (SoftObject 0.5 [Key (0, 0, 0) 1 1, Key (0.9, 0, 0) 0.6 (-1)]) (-2, 0, 0) (1, 0, 0)' \
  wyvill field
check slice s.svg \
  'plotSlice "s.png" 0.1 (Difference UnitCube (Shift (0.25, 0.8, 0.25) (Scale (0.5, 0.5, 0.5) UnitCube))) ((0.5, 0.6, 0.5), (0.8, 0, 0), (0, 0.8, 0))' \
  --image
check convolution conv.svg \
  'plotConvolution "conv.svg" 0.1 UnitCube (1.3, 1.3, 1.3) (-1, -1, -1)' \
  quasi difference
