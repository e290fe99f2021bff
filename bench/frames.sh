#!/bin/sh
# frames.sh: an animation in one process against one process a frame
# (issue 17): examples/lid.qcs at 160x100, frames 1-100, rendered by one
# `qcs --frames 1-100` and by 100 runs of `qcs --frames k-k --animation
# 1-100` (what a farm without --frames ranges does), all on the same
# number of threads; prints frames per second both ways, their ratio, the
# fixed cost per process, and checks that the files are the same.
#   sh bench/frames.sh [THREADS]   (default 2; SIZE, SCENE, N override)
QCS=${QCS:-./qcs}
T=${1:-2}
SCENE=${SCENE:-examples/lid.qcs}
SIZE=${SIZE:-160x100}
N=${N:-100}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/one" "$tmp/each"
now() { date +%s.%N; }
t0=$(now)
"$QCS" -o "$tmp/one/f####.png" --size "$SIZE" --threads "$T" --frames "1-$N" \
  "$SCENE" >/dev/null 2>&1 || { echo "frames.sh: qcs failed" >&2; exit 1; }
t1=$(now)
k=1
while [ $k -le "$N" ]; do
  "$QCS" -o "$tmp/each/f####.png" --size "$SIZE" --threads "$T" \
    --frames "$k-$k" --animation "1-$N" "$SCENE" >/dev/null 2>&1 ||
    { echo "frames.sh: qcs failed on frame $k" >&2; exit 1; }
  k=$((k + 1))
done
t2=$(now)
diff=0
for f in "$tmp"/one/*.png; do
  cmp -s "$f" "$tmp/each/${f##*/}" || diff=$((diff + 1))
done
n=$(ls "$tmp/each" | wc -l)
[ "$n" -eq "$N" ] || diff=$((diff + N - n))
same=$([ $diff = 0 ] && echo "identical" || echo "DIFFERENT ($diff of $N)")
awk -v a="$t0" -v b="$t1" -v c="$t2" -v n="$N" -v th="$T" -v sz="$SIZE" \
    -v sc="${SCENE##*/}" -v s="$same" 'BEGIN {
  o = b - a; e = c - b;
  printf "%s %s, %d frames, %d threads: one process %.2f s (%.1f frames/s); %d processes %.2f s (%.1f frames/s)\n", sc, sz, n, th, o, n / o, n, e, n / e
  printf "one process is %.2fx the frame rate; per process %.3f s more than per frame in one (start-up, prelude, script, compile)\n", e / o, (e - o) / n
  printf "the %d files of the two ways: %s\n", n, s }'
