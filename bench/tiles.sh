#!/bin/sh
# tiles.sh: the cost of a farm's tile against the whole picture (issue 17):
# figure12 at 1920x1080 rendered once, then as 16 tiles (--tile I/16),
# each a process of its own, all on the same number of threads; prints
# the whole's wall time, the tiles' sum, and the overhead per tile (the
# sum less the whole, over 16: start-up, parsing, scene compile, BVH,
# and the file write each process repeats), then checks the merge.
#   sh bench/tiles.sh [THREADS]   (default 2)
QCS=${QCS:-./qcs}
T=${1:-2}
SCENE=examples/figure12.qcs
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
now() { date +%s.%N; }
t0=$(now)
"$QCS" -o "$tmp/whole.exr" --size 1920x1080 --threads "$T" "$SCENE" >/dev/null 2>&1
t1=$(now)
for i in $(seq 1 16); do
  "$QCS" -o "$tmp/t$i.exr" --size 1920x1080 --threads "$T" --tile "$i/16" \
    "$SCENE" >/dev/null 2>&1
done
t2=$(now)
"$QCS" -o "$tmp/none.exr" --size 1x1 --threads "$T" "$SCENE" >/dev/null 2>&1
t3=$(now)
"$QCS" merge "$tmp/m.exr" "$tmp"/t*.exr
t4=$(now)
same=$(cmp -s "$tmp/m.exr" "$tmp/whole.exr" && echo identical || echo DIFFERENT)
awk -v a="$t0" -v b="$t1" -v c="$t2" -v d="$t3" -v e="$t4" -v th="$T" -v s="$same" 'BEGIN {
  w = b - a; t = c - b;
  printf "figure12 1920x1080, %d threads: whole %.2f s; 16 tiles %.2f s in all\n", th, w, t
  printf "overhead per tile %.3f s (%.1f%% of the whole); a 1x1 render (the fixed cost) %.3f s\n", (t - w) / 16, 100 * (t - w) / 16 / w, d - c
  printf "merge of the 16 tiles %.2f s; merged file %s to the whole\n", e - d, s }'
