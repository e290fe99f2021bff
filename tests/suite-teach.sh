#!/bin/sh
# suite-teach.sh: what a student reads. No line of the tour's or a
# lesson's output is wider than 80 columns; :set digits N rounds what the
# REPL prints (piped, so no terminal is needed); every lesson runs and
# writes the pictures it names. Prints "ok NAME" or "FAIL NAME: why".
QCS=${QCS:-./qcs}
top=$(pwd)
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

width() { # width NAME FILE: run FILE in $tmp, every line <= 80 columns
  (cd "$tmp" && timeout 120 "$top/$QCS" "$top/$2" > out 2> err < /dev/null)
  st=$?
  wide=$(awk 'length($0) > 80 { print NR ": " length($0) }' "$tmp/out" "$tmp/err" | head -3 | tr '\n' ' ')
  if [ $st -ne 0 ]; then
    echo "FAIL $1: status $st: $(head -c 300 "$tmp/err" | tr '\n' ' ')"
  elif [ -n "$wide" ]; then
    echo "FAIL $1: lines wider than 80 columns (line: width) $wide"
  else
    echo "ok $1"
  fi
}

width "teach: tour within 80 columns" examples/tour.qcs
for f in examples/lessons/*.qcs; do
  [ -f "$f" ] || continue
  width "teach: lesson $(basename "$f" .qcs) within 80 columns" "$f"
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
