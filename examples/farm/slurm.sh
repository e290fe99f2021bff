#!/bin/sh
# slurm.sh: a 1920x1080 picture as 16 tiles, one Slurm array task each,
# then a merge job that waits for the whole array. From the qcs folder:
#
#   jid=$(sbatch --parsable examples/farm/slurm.sh)
#   sbatch --dependency=afterok:$jid examples/farm/slurm.sh merge
#
# Each task renders tile SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN + 1
# (qcs --index-env reads the index; the array may start at 0 or 1).
# --skip-existing makes a requeued task cheap and safe: the writers are
# atomic, so a tile file that exists is whole.
#
# An animation: set FRAMES (A-B[:STEP], qcs's --frames) and the array
# size to frames x tiles; task k renders frame k / TILES of the range and
# tile k % TILES + 1 (TILES=1: one whole frame a task, f####.exr, and
# no merge step). 24 frames in 16
# tiles:
#
#   n=$((24 * 16))
#   jid=$(sbatch --parsable --array=1-$n --export=ALL,FRAMES=1-24 examples/farm/slurm.sh)
#   sbatch --dependency=afterok:$jid --export=ALL,FRAMES=1-24 examples/farm/slurm.sh merge
#
# which writes $OUT/f0001.exr ... $OUT/f0024.exr.
#SBATCH --job-name=qcs-tiles
#SBATCH --array=1-16
#SBATCH --cpus-per-task=4
SCENE=${SCENE:-examples/figure12.qcs}
SIZE=${SIZE:-1920x1080}
OUT=${OUT:-tiles}
TILES=${TILES:-16}
mkdir -p "$OUT"
if [ -z "$FRAMES" ]; then
  if [ "$1" = merge ]; then
    exec ./qcs merge "$OUT/figure12.exr" "$OUT"/tile-*.exr
  fi
  exec ./qcs --size "$SIZE" ${SLURM_CPUS_PER_TASK:+--threads $SLURM_CPUS_PER_TASK} \
    --tiles "$TILES" --index-env --skip-existing \
    -o "$OUT/tile-$SLURM_ARRAY_TASK_ID.exr" "$SCENE"
fi
if [ "$1" = merge ]; then  # one merge per frame of A-B[:STEP]
  a=${FRAMES%%-*}; b=${FRAMES#*-}; b=${b%%:*}; s=1
  case $FRAMES in *:*) s=${FRAMES##*:} ;; esac
  for f in $(seq "$a" "$s" "$b"); do
    f=$(printf '%04d' "$f")
    [ "$TILES" = 1 ] || ./qcs merge "$OUT/f$f.exr" "$OUT/f$f"-tile-*.exr || exit 1
  done
  exit 0
fi
if [ "$TILES" = 1 ]; then  # whole frames: f####.exr, nothing to merge
  set -- -o "$OUT/f####.exr"
else
  tile=$(( (SLURM_ARRAY_TASK_ID - ${SLURM_ARRAY_TASK_MIN:-1}) % TILES + 1 ))
  set -- --tiles "$TILES" -o "$OUT/f####-tile-$tile.exr"
fi
exec ./qcs --size "$SIZE" ${SLURM_CPUS_PER_TASK:+--threads $SLURM_CPUS_PER_TASK} \
  --frames "$FRAMES" --index-env --skip-existing "$@" "$SCENE"
