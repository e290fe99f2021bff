#!/bin/bash
# bench/callgrind.sh -- `make bench-callgrind`: instructions executed by qcs per
# canonical scene at a small size (150x95), one thread, under
# valgrind --tool=callgrind. Instruction counts are repeatable on a noisy
# machine, so a regression shows as a larger count. Writes bench/callgrind.csv
# and prints each count against the one in the previous bench/callgrind.csv.
# Environment: QCS (./qcs), CG_SIZE (150x95), OUT (/tmp/qcs-bench).
set -u
cd "$(dirname "$0")/.." || exit 1
QCS=${QCS:-./qcs}; SIZE=${CG_SIZE:-150x95}; OUT=${OUT:-/tmp/qcs-bench}/callgrind
mkdir -p "$OUT"
command -v valgrind >/dev/null || { echo "callgrind: valgrind is not installed (Debian package valgrind): skipped"; exit 1; }
[ $# -eq 0 ] && set -- figure12 figure12-sharp figure13 figure15a figure15b \
  soft-cloud-10 soft-cloud-100 soft-cloud-1000 soft-cloud-10000 soft-cloud-100000
declare -A PREV
if [ -f bench/callgrind.csv ]; then
  while IFS=, read -r s n _; do PREV[$s]=$n; done < bench/callgrind.csv
fi
echo "scene,instructions,size,threads,commit" > bench/callgrind.csv.tmp
commit=$(git rev-parse --short HEAD 2>/dev/null)
printf '%-18s %16s %10s\n' scene "Ir (callgrind)" "vs prev"
for s in "$@"; do
  case $s in
    soft-cloud-*) f=examples/soft-cloud.qcs; args="--set n=${s#soft-cloud-}" ;;
    *) f=examples/$s.qcs; args="" ;;
  esac
  [ -f "$f" ] || { echo "missing: $s ($f)"; continue; }
  # shellcheck disable=SC2086
  valgrind --tool=callgrind --callgrind-out-file="$OUT/$s.out" "$QCS" --threads 1 \
    --size "$SIZE" -o "$OUT/$s.png" $args "$f" > "$OUT/$s.log" 2>&1
  ir=$(grep -o 'Collected : [0-9]*' "$OUT/$s.log" | awk '{ print $3 }')
  [ -n "$ir" ] || { echo "FAILED: $s (see $OUT/$s.log)"; continue; }
  prev=${PREV[$s]:-}
  rel=$(awk -v a="$ir" -v b="$prev" 'BEGIN { if (b == "" || b + 0 == 0) print "-"; else printf "%+.1f%%", (a / b - 1) * 100 }')
  printf '%-18s %16s %10s\n' "$s" "$ir" "$rel"
  echo "$s,$ir,$SIZE,1,$commit" >> bench/callgrind.csv.tmp
done
mv bench/callgrind.csv.tmp bench/callgrind.csv
echo "wrote bench/callgrind.csv"
