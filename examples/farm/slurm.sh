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
#SBATCH --job-name=qcs-tiles
#SBATCH --array=1-16
#SBATCH --cpus-per-task=4
SCENE=${SCENE:-examples/figure12.qcs}
SIZE=${SIZE:-1920x1080}
OUT=${OUT:-tiles}
mkdir -p "$OUT"
if [ "$1" = merge ]; then
  exec ./qcs merge "$OUT/figure12.exr" "$OUT"/tile-*.exr
fi
exec ./qcs --size "$SIZE" ${SLURM_CPUS_PER_TASK:+--threads $SLURM_CPUS_PER_TASK} \
  --tiles 16 --index-env --skip-existing \
  -o "$OUT/tile-$SLURM_ARRAY_TASK_ID.exr" "$SCENE"
