#!/bin/sh
# suite-teach.sh: what a student reads. No line of the tour's or a
# lesson's output is wider than 80 columns, nor prints a number with more
# than 6 significant digits (their `:set digits 6`); :set digits N rounds what the
# REPL prints (piped, so no terminal is needed); every lesson runs and
# writes the pictures it names. Prints "ok NAME" or "FAIL NAME: why".
QCS=${QCS:-./qcs}
top=$(pwd)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

width() { # width NAME FILE: run FILE in $tmp, every line <= 80 columns
  (cd "$tmp" && timeout 120 "$top/$QCS" "$top/$2" > out 2> err < /dev/null)
  st=$?
  wide=$(awk 'length($0) > 80 { print NR ": " length($0) }' "$tmp/out" "$tmp/err" | head -3 | tr '\n' ' ')
  # rounding noise: a number printed with more than 6 significant digits
  noise=$(grep -oE '[0-9]+(\.[0-9]+)?' "$tmp/out" | awk '{ m = $0; sub(/\./, "", m);
    sub(/^0+/, "", m); sub(/0+$/, "", m); if (length(m) > 6) print }' | head -3 | tr '\n' ' ')
  if [ $st -ne 0 ]; then
    echo "FAIL $1: status $st: $(head -c 300 "$tmp/err" | tr '\n' ' ')"
  elif [ -n "$wide" ]; then
    echo "FAIL $1: lines wider than 80 columns (line: width) $wide"
  elif [ -n "$noise" ]; then
    echo "FAIL $1: numbers with more than 6 significant digits: $noise"
  else
    echo "ok $1"
  fi
}

width "teach: tour within 80 columns" examples/tour.qcs
for f in examples/lessons/*.qcs; do
  [ -f "$f" ] || continue
  rm -f "$tmp"/*.svg "$tmp"/*.png
  width "teach: lesson $(basename "$f" .qcs) within 80 columns" "$f"
  n=$(ls "$tmp" | grep -c -E '\.(svg|png)$')
  if [ "$n" -gt 0 ]; then echo "ok teach: lesson $(basename "$f" .qcs) draws ($n files)"
  else echo "FAIL teach: lesson $(basename "$f" .qcs) wrote no picture"; fi
  # the README's gallery shows every picture (each SVG; a slice's PNG is
  # inside its SVG)
  missing=""
  for svg in "$tmp"/*.svg; do
    [ -f "$svg" ] || continue
    pic=doc/images/lessons/$(basename "$svg" .svg).png
    { [ -s "$pic" ] && grep -qF "($pic)" README.md; } || missing="$missing $pic"
  done
  if [ -z "$missing" ]; then echo "ok teach: lesson $(basename "$f" .qcs) pictures in the README"
  else echo "FAIL teach: lesson $(basename "$f" .qcs): not in the README's gallery:$missing"; fi
done

# :set digits at the prompt: numbers, a gradient's rounding-noise
# coordinate, Trace's table, and back to the shortest form.
out=$(printf '%s\n' ':set digits 6' '1/3' '1.000000000000001' \
  'Gradient 0.1 (0.5, 0.5, 0.95) UnitCube' ':set digits 0' '1/3' \
  ':set digits 18' | "$QCS" 2>&1)
want='0.333333
1
(0, 0, -5.625)
0.3333333333333333
error: :set digits needs 0 (shortest that reads back) to 17, not '"'18'"
if [ "$out" = "$want" ]; then echo "ok teach: :set digits"
else echo "FAIL teach: :set digits: got $(printf '%s' "$out" | tr '\n' '|')"; fi

# --digits N on the command line: for -e, and over a script's :set digits
printf '1 / 3\n:set digits 3\n2 / 3\n' > "$tmp/d.qcs"
out=$("$QCS" --digits 4 "$tmp/d.qcs" -e '1 / 7' 2>&1 | tr '\n' ' ')
out0=$("$QCS" --digits 0 "$tmp/d.qcs" 2>&1 | tr '\n' ' ')
if [ "$out" = "0.3333 0.6667 0.1429 " ] &&
   [ "$out0" = "0.3333333333333333 0.6666666666666666 " ]
then echo "ok teach: --digits N, over a script's :set digits"
else echo "FAIL teach: --digits: got '$out' and '$out0'"; fi
# an animation's later frames print as the first did, setting by setting
printf ':set digits 3\nframe / 3\n:set digits 0\nframe / 3\n' > "$tmp/an.qcs"
out=$("$QCS" --frames 1-2 "$tmp/an.qcs" 2>&1 | tr '\n' ' ')
if [ "$out" = "0.333 0.3333333333333333 0.667 0.6666666666666666 " ]; then
  echo "ok teach: :set digits replayed in order for every frame"
else echo "FAIL teach: :set digits over frames: got '$out'"; fi
# a file :load-ed at the prompt sets the prompt's digits, unless --digits
printf ':set digits 3\nx = 1\n' > "$tmp/ld.qcs"
a=$(printf ':load %s\n1/3\n' "$tmp/ld.qcs" | "$QCS" 2>&1)
b=$(printf ':load %s\n1/3\n' "$tmp/ld.qcs" | "$QCS" --digits 5 2>&1)
if [ "$a" = "0.333" ] && [ "$b" = "0.33333" ]; then
  echo "ok teach: :load of a file with :set digits, and --digits over it"
else echo "FAIL teach: :load and digits: got '$a' and '$b'"; fi
if "$QCS" --digits 18 -e 1 > /dev/null 2> "$tmp/err"; then
  echo "FAIL teach: --digits 18 accepted"
elif grep -q "qcs: error: --digits needs 0 (shortest that reads back) to 17, not '18'" "$tmp/err"
then echo "ok teach: --digits 18 refused"
else echo "FAIL teach: --digits 18: $(cat "$tmp/err")"; fi

# A soft object's Trace: within 80 columns, a steps column with the
# Laguerre iterations of each solved interval (at least 12: the sextic's 6
# roots found and 6 polished), the same numbers plotRay writes per interval.
soft='SoftObject 0.5 [Key (0, 0, 0) 1 1, Key (0.8, 0, 0) 1 1]'
(cd "$tmp" && "$top/$QCS" --digits 6 -e "Trace ($soft) (-2, 0.1, 0) (1, 0, 0)" \
  -e "plotRay \"soft.svg\" ($soft) (-2, 0.1, 0) (1, 0, 0)" > trace 2> err)
wide=$(awk 'length($0) > 80' "$tmp/trace" | head -1)
steps=$(awk '/solve: Laguerre/ { for (i = 1; i <= NF; i++) if ($i == "Laguerre") print $(i + 1) }' "$tmp/trace" | tr '\n' ' ')
few=$(printf '%s\n' $steps | awk '$1 !~ /^[0-9]+$/ || $1 < 12' | head -1)
plotted=$(grep -o 'data-decision="4" data-laguerre="[0-9]*"' "$tmp/soft.svg" | sed 's/.*="//; s/"//' | tr '\n' ' ')
if [ -n "$wide" ]; then echo "FAIL teach: soft Trace: a line over 80 columns: $wide"
elif ! grep -q '^t0 .* steps roots$' "$tmp/trace"; then
  echo "FAIL teach: soft Trace: no steps column: $(head -c 300 "$tmp/trace")"
elif [ -z "$steps" ] || [ -n "$few" ]; then
  echo "FAIL teach: soft Trace: Laguerre steps '$steps'"
elif [ "$steps" != "$plotted" ]; then
  echo "FAIL teach: soft Trace steps '$steps', plotRay's '$plotted'"
else echo "ok teach: soft Trace shows the Laguerre steps per interval ($steps)"; fi

# plotRay's curve is Density (or Field) at the plotted t, and its roots
# are Roots: read the data-* attributes back and check them in qcs.
curve_check() { # curve_check NAME OBJ O D CLASS PROBE
  name=$1 obj=$2 o=$3 d=$4 cls=$5 probe=$6
  (cd "$tmp" && "$top/$QCS" -e "plotRay \"ray.svg\" ($obj) $o $d" > /dev/null 2> err) ||
    { echo "FAIL teach: $name: plotRay failed: $(head -c 200 "$tmp/err")"; return; }
  line=$(grep "class=\"$cls\"" "$tmp/ray.svg")
  xs=$(printf '%s' "$line" | sed 's/.*data-x="\([^"]*\)".*/\1/' | tr ' ' ',')
  ys=$(printf '%s' "$line" | sed 's/.*data-y="\([^"]*\)".*/\1/' | tr ' ' ',')
  rs=$(grep -o 'class="root"[^>]*data-t="[^"]*"' "$tmp/ray.svg" | sed 's/.*data-t="\([^"]*\)"/\1/' | tr '\n' ',' | sed 's/,$//')
  cat > "$tmp/check.qcs" <<QCS
obj = $obj;
at t = (ox + t * dx, oy + t * dy, oz + t * dz)
  where (ox, oy, oz) = $o;
        (dx, dy, dz) = $d;
ts = [$xs];
ys = [$ys];
bad = [t \\\\ (t, y) <- zip ts ys, abs ($probe (at t) - y) > 1e-12];
(length ts, length bad)
[$rs] == Roots obj $o $d
QCS
  got=$("$top/$QCS" "$tmp/check.qcs" 2>&1 | tr '\n' ' ')
  if [ "$got" = "(401, 0) True " ]; then echo "ok teach: $name"
  else echo "FAIL teach: $name: got $got"; fi
}
curve_check "plotRay curve is Density, its roots are Roots" \
  "Rounded 0.1 UnitCube" "(-1, 0.95, 0.5)" "(1, 0, 0)" density \
  "(\\p -> Density 0.1 p UnitCube)"
curve_check "plotRay curve of a soft object is Field, its roots are Roots" \
  "SoftObject 0.5 [Key (0, 0, 0) 1 1, Key (0.8, 0, 0) 1 1]" "(-2, 0.1, 0)" \
  "(1, 0, 0)" field "(\\p -> Field p obj)"

# plotConvolution's curves are Density and TrueDensity at the plotted t,
# and its crossings are where each is 0.5 (the quasi one to 1e-9, the true
# one to 1e-6: TrueDensity is good to 1e-7, its slope there about 6).
(cd "$tmp" && "$top/$QCS" -e 'plotConvolution "conv.svg" 0.1 UnitCube (1.3, 1.3, 1.3) (-1, -1, -1)' \
  > /dev/null 2> err) || echo "FAIL teach: plotConvolution: $(head -c 200 "$tmp/err")"
attr() { grep "class=\"$1\"" "$tmp/conv.svg" | sed "s/.*$2=\"\([^\"]*\)\".*/\1/" | tr ' ' ','; }
cat > "$tmp/conv.qcs" <<QCS
at t = (1.3 - t, 1.3 - t, 1.3 - t);
check f ts ys = (length ts, length [t \\\\ (t, y) <- zip ts ys, abs (f (at t) - y) > 1e-12]);
check (\\p -> Density 0.1 p UnitCube) [$(attr quasi data-x)] [$(attr quasi data-y)]
check (\\p -> TrueDensity 0.1 p UnitCube) [$(attr true data-x)] [$(attr true data-y)]
abs (Density 0.1 (at $(attr cross-quasi data-t)) UnitCube - 0.5) < 1e-9
abs (TrueDensity 0.1 (at $(attr cross-true data-t)) UnitCube - 0.5) < 1e-6
QCS
got=$("$QCS" "$tmp/conv.qcs" 2>&1 | tr '\n' ' ')
if [ "$got" = "(201, 0) (33, 0) True True " ]; then
  echo "ok teach: plotConvolution's curves are Density and TrueDensity, its crossings 0.5"
else echo "FAIL teach: plotConvolution data: got $got"; fi

# Every plot writes its file, and a failed write leaves nothing behind.
(cd "$tmp" && "$top/$QCS" -e 'plotDisplacement "d.svg"' \
  -e 'plotField "c.svg" (SoftObject 0.5 [Key (0, 0, 0) 1 1]) (-2, 0, 0) (1, 0, 0)' \
  -e 'plotSlice "s.png" 0.1 UnitCube ((0.5, 0.5, 0.5), (0.8, 0, 0), (0, 0.8, 0))' \
  > out 2> err)
if [ -s "$tmp/d.svg" ] && [ -s "$tmp/c.svg" ] && [ -s "$tmp/s.png" ] && [ -s "$tmp/s.svg" ] &&
   grep -q '</svg>' "$tmp/d.svg" && grep -q '</svg>' "$tmp/c.svg" && grep -q '</svg>' "$tmp/s.svg"
then echo "ok teach: plotDisplacement, plotField, plotSlice write their files"
else echo "FAIL teach: plots: $(ls "$tmp" | tr '\n' ' ') $(head -c 200 "$tmp/err")"; fi
if "$QCS" -e 'plotDisplacement "/nonexistent-dir/d.svg"' > /dev/null 2> "$tmp/err"; then
  echo "FAIL teach: plot into a missing folder succeeded"
elif grep -q 'cannot write /nonexistent-dir/d.svg' "$tmp/err"; then
  echo "ok teach: plot into a missing folder is an error naming the file"
else echo "FAIL teach: plot error: $(head -c 200 "$tmp/err")"; fi
