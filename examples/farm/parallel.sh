#!/bin/sh
# parallel.sh: 16 tiles over several machines with GNU parallel and ssh,
# then the merge here. Each machine has qcs in the same folder as here
# (a shared file system, or the same checkout); PARALLEL_SEQ (1..16) picks
# the tile (qcs --index-env).
#
#   sh examples/farm/parallel.sh host1,host2,host3      (or : for this one)
HOSTS=${1:-:}
SCENE=${SCENE:-examples/figure12.qcs}
SIZE=${SIZE:-1920x1080}
mkdir -p tiles
seq 16 | parallel -S "$HOSTS" --workdir "$PWD" --retries 2 \
  ./qcs --size "$SIZE" --tiles 16 --index-env --skip-existing \
  -o tiles/tile-{}.exr "$SCENE" &&
./qcs merge figure12.exr tiles/tile-*.exr
