#!/bin/sh
# lesson-pictures.sh: the README's gallery of lesson pictures. Runs every
# lesson (examples/lessons/*.qcs) in a scratch folder, draws each SVG it
# writes through headless Chromium at the SVG's own size (a plotSlice's
# SVG holds its PNG inside axes, so the PNG itself is not copied), and
# writes doc/images/lessons/NAME.png, 560 pixels wide with a 256-colour
# palette (ImageMagick's convert).
#   sh tools/lesson-pictures.sh      (make lesson-pictures)
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}
top=$(pwd)
browser=$(command -v chromium || command -v chromium-browser)
[ -n "$browser" ] || { echo "lesson-pictures: chromium is needed" >&2; exit 1; }
command -v convert > /dev/null || { echo "lesson-pictures: ImageMagick's convert is needed" >&2; exit 1; }
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
out=doc/images/lessons
mkdir -p "$out"
for f in examples/lessons/*.qcs; do
  (cd "$tmp" && "$top/$QCS" "$top/$f" > /dev/null) || { echo "lesson-pictures: $f failed" >&2; exit 1; }
done
for svg in "$tmp"/*.svg; do
  n=$(basename "$svg" .svg)
  size=$(sed -n 's/.*<svg [^>]* width="\([0-9]*\)" height="\([0-9]*\)".*/\1,\2/p' "$svg" | head -1)
  rm -rf "$tmp/profile"
  mkdir "$tmp/profile"
  timeout 90 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
    --no-first-run --disable-background-networking --disable-component-update \
    --disable-sync --user-data-dir="$tmp/profile" --screenshot="$tmp/$n.shot.png" \
    --window-size="$size" "file://$svg" > /dev/null 2>&1
  [ -s "$tmp/$n.shot.png" ] || { echo "lesson-pictures: no screenshot of $n.svg" >&2; exit 1; }
  convert "$tmp/$n.shot.png" -resize 560x +dither -colors 256 "PNG8:$out/$n.png"
  echo "$out/$n.png"
done
