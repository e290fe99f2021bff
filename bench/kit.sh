#!/bin/sh
# kit.sh: the modeller's kit at scale (issue 19): bench/grid1000.qcs, a
# 10 x 10 x 10 grid of rounded cubes (Grid, UnionAll), rendered N times
# at SIZE on T threads; prints the median and best whole-process wall
# time (evaluating the 1000 copies included), the median render time as
# qcs reports it, and whether the median is under the issue's target of
# "well under a second" (0.5 s).
#   sh bench/kit.sh [THREADS]   (default 2; SIZE 600x380, N 5 override)
QCS=${QCS:-./qcs}
T=${1:-2}
SIZE=${SIZE:-600x380}
N=${N:-5}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
now() { date +%s.%N; }
median() { sort -g | awk '{ v[NR] = $1 } END { printf "%.3f\n", (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
: > "$tmp/wall"; : > "$tmp/render"
k=0
while [ $k -lt "$N" ]; do
  t0=$(now)
  "$QCS" -o "$tmp/grid.png" --size "$SIZE" --threads "$T" bench/grid1000.qcs \
    >/dev/null 2>"$tmp/err" || { echo "kit.sh: qcs failed: $(head -3 "$tmp/err")" >&2; exit 1; }
  t1=$(now)
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.4f\n", b - a }' >> "$tmp/wall"
  sed -n 's/.* sample[s]*\/pixel, \([0-9.]*\) s on.*/\1/p' "$tmp/err" | head -1 >> "$tmp/render"
  k=$((k + 1))
done
wall=$(median < "$tmp/wall"); best=$(sort -g "$tmp/wall" | head -1); render=$(median < "$tmp/render")
prims=$(sed -n 's/.*; \([0-9]*\) primitives.*/\1/p' "$tmp/err" | head -1)
verdict=$(awk -v w="$wall" 'BEGIN { print (w < 0.5) ? "met" : "NOT met" }')
echo "grid1000 ($SIZE, $T threads, $prims primitives): wall median $wall s (best $best s), render median $render s over $N runs"
echo "target: a 10x10x10 grid of rounded cubes well under a second (median wall < 0.5 s): $verdict"
