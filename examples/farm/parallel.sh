#!/bin/sh
# parallel.sh: 16 tiles over several machines with GNU parallel and ssh,
# then the merge here. Each machine has qcs in the same folder as here
# (a shared file system, or the same checkout); PARALLEL_SEQ (1..16) picks
# the tile (qcs --index-env).
#
#   sh examples/farm/parallel.sh host1,host2,host3      (or : for this one)
#
# An animation: FRAMES=A-B[:STEP] (qcs's --frames) runs frames x 16 jobs,
# job k (from 0) rendering frame k / 16 of the range and tile k % 16 + 1
# (qcs --frames --tiles --index-env), then merges each frame into
# frames/f0001.exr ...:
#
#   FRAMES=1-24 sh examples/farm/parallel.sh host1,host2,host3
HOSTS=${1:-:}
SCENE=${SCENE:-examples/figure12.qcs}
SIZE=${SIZE:-1920x1080}
if [ -z "$FRAMES" ]; then
  mkdir -p tiles
  seq 16 | parallel -S "$HOSTS" --workdir "$PWD" --retries 2 \
    ./qcs --size "$SIZE" --tiles 16 --index-env --skip-existing \
    -o tiles/tile-{}.exr "$SCENE" &&
  ./qcs merge figure12.exr tiles/tile-*.exr
  exit
fi
a=${FRAMES%%-*}; b=${FRAMES#*-}; b=${b%%:*}; s=1
case $FRAMES in *:*) s=${FRAMES##*:} ;; esac
mkdir -p frames
seq $(( ((b - a) / s + 1) * 16 )) | parallel -S "$HOSTS" --workdir "$PWD" \
  --retries 2 ./qcs --size "$SIZE" --frames "$FRAMES" --tiles 16 \
  --index-env --skip-existing \
  -o "frames/f####-tile-{= \$_ = (\$_ - 1) % 16 + 1 =}.exr" "$SCENE" || exit 1
for f in $(seq "$a" "$s" "$b"); do
  f=$(printf '%04d' "$f")
  ./qcs merge "frames/f$f.exr" "frames/f$f"-tile-*.exr || exit 1
done
